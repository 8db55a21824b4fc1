// Oriented points -> level set -> mesh (OpenVDB), see points_to_mesh.
#include <cstdio>
#include <cmath>
#include <mutex>

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "exsynth/errors.hpp"
#include "exsynth/points.hpp"
#include "search/point_index.hpp"
#include "points/point_surface.hpp"

namespace exsynth {
namespace {

// The particle list ParticlesToLevelSet reads: centres moved inward by r.
struct InsetSpheres {
  using PosType = openvdb::Vec3R;
  const OrientedPoints* pts;
  double r;
  std::size_t size() const { return pts->size(); }
  void getPos(std::size_t i, openvdb::Vec3R& p) const {
    const Eigen::Vector3f c = pts->positions[i] - float(r) * pts->normals[i];
    p = openvdb::Vec3R(c.x(), c.y(), c.z());
  }
  void getPosRad(std::size_t i, openvdb::Vec3R& p, openvdb::Real& rad) const {
    getPos(i, p);
    rad = r;
  }
};

// Cancel checks for OpenVDB's tools (their interrupter concept).
struct Interrupter {
  ExecContext* ctx;
  void start(const char* = nullptr) {}
  void end() {}
  bool wasInterrupted(int = -1) const { return ctx && ctx->cancelled(); }
};

// The union of inset spheres is a shell: its outer side is the surface, its
// inner side a second surface facing inward (negative enclosed volume).
// Keep the components that enclose positive volume.
TriangleMesh drop_inner_shells(const TriangleMesh& m) {
  std::vector<int> parent(m.vertices.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = int(i);
  auto find = [&](int x) {
    while (parent[std::size_t(x)] != x) x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  };
  for (const auto& f : m.faces) {
    const int a = find(f[0]), b = find(f[1]), c = find(f[2]);
    parent[std::size_t(b)] = a;
    parent[std::size_t(find(c))] = a;
  }
  std::vector<double> volume(m.vertices.size(), 0.0);
  for (const auto& f : m.faces) {
    const Eigen::Vector3d a = m.vertices[f[0]].cast<double>(), b = m.vertices[f[1]].cast<double>(),
                          c = m.vertices[f[2]].cast<double>();
    volume[std::size_t(find(f[0]))] += a.dot(b.cross(c)) / 6.0;
  }
  TriangleMesh out;
  std::vector<int> remap(m.vertices.size(), -1);
  for (const auto& f : m.faces) {
    if (volume[std::size_t(find(f[0]))] <= 0) continue;
    Eigen::Vector3i g;
    for (int k = 0; k < 3; ++k) {
      int& r = remap[std::size_t(f[k])];
      if (r < 0) {
        r = int(out.vertices.size());
        out.vertices.push_back(m.vertices[std::size_t(f[k])]);
      }
      g[k] = r;
    }
    out.faces.push_back(g);
  }
  return out;
}

}  // namespace

// OpenVDB's index coordinates are 32-bit; keep well inside them.
constexpr double kMaxIndexSpan = double(1 << 24);

TriangleMesh points_to_mesh(const OrientedPoints& pts, double spacing, const PointMeshOptions& opt, ExecContext* ctx) {
  if (pts.positions.empty()) throw InvalidInput("points_to_mesh: no points to make a surface from");
  if (pts.normals.size() != pts.positions.size())
    throw InvalidInput("points_to_mesh: give one unit normal per point (an oriented point set)");
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (!pts.positions[i].allFinite() || !pts.normals[i].allFinite())
      throw InvalidInput("points_to_mesh: point " + std::to_string(i) + " has a NaN or infinite position or normal");
  if (!(opt.radius > 0) || !(opt.voxel > 0) || opt.smoothing < 0)
    throw InvalidInput("points_to_mesh: radius and voxel must be positive, smoothing >= 0");
  StageProgress progress(ctx, "surface from points", 0.0, 1.0, 4);
  if (!(spacing > 0)) {
    const search::PointIndex index(pts.positions);
    spacing = points::mean_spacing(pts.positions, index);
    if (!(spacing > 0)) throw InvalidInput("points_to_mesh: the points all coincide");
  }
  const double h = opt.voxel * spacing, r = opt.radius * spacing;
  Eigen::AlignedBox3f box;
  for (const auto& p : pts.positions) box.extend(p);
  const double extent = double(box.sizes().maxCoeff()) + 2 * r;
  if (!(extent / h < kMaxIndexSpan)) {  // also a spacing too small for OpenVDB's transform
    char msg[200];
    std::snprintf(msg, sizeof msg, "points_to_mesh: a spacing of %.3g makes voxels of %.3g, so the points' extent "
                  "%.3g spans more than %.0f voxels; give a spacing of at least %.3g (or 0 to measure it)",
                  spacing, h, extent, kMaxIndexSpan, extent / kMaxIndexSpan / opt.voxel);
    throw InvalidInput(msg);
  }
  // Every sphere touches about (2 r / h)^2 surface voxels, with the band a few more.
  const double voxels = double(pts.size()) * std::pow(2 * r / h + 3.0, 2.0) * 3.0;
  check_memory_budget(voxels * 8.0, opt.memory_budget, "a surface of " + std::to_string(pts.size()) + " points",
                      "raise the voxel size or lower the point count");
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  auto grid = openvdb::createLevelSet<openvdb::FloatGrid>(h, 3.0);
  Interrupter interrupt{ctx};
  {
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid, void, Interrupter> raster(*grid, &interrupt);
    raster.setRmin(0.5);  // spheres under half a voxel would be dropped; ours are > 1 voxel
    raster.rasterizeSpheres(InsetSpheres{&pts, r});
    raster.finalize(true);
  }
  progress.advance();
  progress.check();
  if (opt.smoothing > 0) {
    openvdb::tools::LevelSetFilter<openvdb::FloatGrid, openvdb::FloatGrid, Interrupter> filter(*grid, &interrupt);
    for (int i = 0; i < opt.smoothing; ++i) filter.meanCurvature();
  }
  progress.advance();
  progress.check();
  std::vector<openvdb::Vec3s> vp;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, vp, tris, quads, 0.0, 0.0);
  progress.advance();
  TriangleMesh mesh;
  mesh.vertices.reserve(vp.size());
  for (const auto& p : vp) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  // volumeToMesh orders a level set's polygons the other way round from our
  // counter-clockwise-outside convention: flip them.
  for (const auto& t : tris) mesh.faces.emplace_back(int(t[2]), int(t[1]), int(t[0]));
  for (const auto& q : quads) {
    mesh.faces.emplace_back(int(q[2]), int(q[1]), int(q[0]));
    mesh.faces.emplace_back(int(q[3]), int(q[2]), int(q[0]));
  }
  progress.advance();
  return drop_inner_shells(mesh);
}

}  // namespace exsynth
