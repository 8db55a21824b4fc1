#include "exsynth/isosurface.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"

namespace exsynth {
namespace {

void check_options(const Volume& vol, const IsosurfaceOptions& opt) {
  if (vol.empty()) throw InvalidInput("isosurface: the volume is empty");
  if (opt.channel < 0 || opt.channel >= vol.channels()) {
    throw InvalidInput("isosurface: channel " + std::to_string(opt.channel) +
                       " does not exist; the volume has " + std::to_string(vol.channels()) +
                       " channel(s)");
  }
  const double h = vol.transform().voxel_size;
  if (!(h > 0.0) || !std::isfinite(h)) {
    throw InvalidInput("isosurface: the volume's voxel size must be positive (got " +
                       std::to_string(h) + ")");
  }
  if (!std::isfinite(opt.isovalue)) throw InvalidInput("isosurface: the isovalue is not finite");
  if (!(opt.adaptivity >= 0.0 && opt.adaptivity <= 1.0)) {
    throw InvalidInput("isosurface: adaptivity must be in [0, 1] (got " +
                       std::to_string(opt.adaptivity) + ")");
  }
}


}  // namespace

TriangleMesh isosurface(const Volume& vol, const IsosurfaceOptions& opt, ExecContext* ctx) {
  check_options(vol, opt);
  const std::size_t slices = std::size_t(vol.nz());
  // Units: copy = 1 per slice, meshing = 2 per slice, triangulation = 1 per slice.
  StageProgress progress(ctx, "isosurface", 0.0, 1.0, 4 * slices);

  // OpenVDB meshes with "inside = below the isovalue"; invert=true (a
  // density, inside = above) is the same problem on the negated field.
  const float sign = opt.invert ? -1.0f : 1.0f;
  const float iso = float(sign * opt.isovalue);
  const int c = opt.channel, nx = vol.nx(), ny = vol.ny();
  const std::size_t slice_voxels = std::size_t(nx) * ny;
  std::vector<float> field(vol.voxel_count());
  parallel_chunks(slices, 1, progress, [&](std::size_t begin, std::size_t end) {
    const float* d = vol.data();
    const std::size_t nc = std::size_t(vol.channels());
    for (std::size_t i = begin * slice_voxels; i < end * slice_voxels; ++i) {
      field[i] = sign * d[i * nc + std::size_t(c)];
    }
  });

  float vmin = field[0], vmax = field[0];
  for (std::size_t i = 0; i < field.size(); ++i) {
    const float v = field[i];
    if (!std::isfinite(v)) {
      const std::size_t x = i % std::size_t(nx), y = (i / std::size_t(nx)) % std::size_t(ny),
                        z = i / slice_voxels;
      throw InvalidInput("isosurface: voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                         ", " + std::to_string(z) + ") of channel " + std::to_string(c) +
                         " is not finite; fix the volume first");
    }
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  if (!(vmin < iso && vmax >= iso)) {
    progress.advance(3 * slices);
    return {};
  }

  // Outside the box is "outside" so shapes touching the border come out
  // closed. This background puts the closing caps at most half a voxel
  // beyond the border voxels' centres (i.e. on the box's faces at most).
  const float background = std::max(vmax, iso) + (vmax - vmin);
  // Meshed in index space (identity transform) and placed in world space
  // below, in double: OpenVDB refuses voxel sizes below ~1.4e-5 units, and
  // the values (not the transform) decide where the surface crosses.
  auto grid = openvdb::FloatGrid::create(background);
  {
    openvdb::CoordBBox box(openvdb::Coord(0, 0, 0), openvdb::Coord(nx - 1, ny - 1, vol.nz() - 1));
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, field.data());
    // Negative tolerance: every voxel of the box stays active, none is pruned to a tile.
    openvdb::tools::copyFromDense(dense, *grid, -1.0f);
  }
  field.clear();
  field.shrink_to_fit();
  progress.check();

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, tris, quads, double(iso), opt.adaptivity);
  grid.reset();
  progress.advance(2 * slices);
  progress.check();

  TriangleMesh mesh;
  mesh.vertices.reserve(points.size());
  const GridTransform& xf = vol.transform();
  for (const openvdb::Vec3s& p : points) {
    Eigen::Vector3f w;
    for (int k = 0; k < 3; ++k) w[k] = float(xf.origin[k] + xf.voxel_size * double(p[k]));
    mesh.vertices.push_back(w);
  }
  mesh.faces.reserve(tris.size() + 2 * quads.size());
  // OpenVDB's polygons are already counter-clockwise seen from the side
  // above the isovalue (checked by the tests with enclosed_volume).
  for (const openvdb::Vec3I& t : tris) mesh.faces.emplace_back(int(t[0]), int(t[1]), int(t[2]));
  for (const openvdb::Vec4I& q : quads) {
    // Split along the shorter diagonal: better-shaped triangles.
    const float d02 = (mesh.vertices[q[0]] - mesh.vertices[q[2]]).squaredNorm();
    const float d13 = (mesh.vertices[q[1]] - mesh.vertices[q[3]]).squaredNorm();
    if (d02 <= d13) {
      mesh.faces.emplace_back(int(q[0]), int(q[1]), int(q[2]));
      mesh.faces.emplace_back(int(q[0]), int(q[2]), int(q[3]));
    } else {
      mesh.faces.emplace_back(int(q[1]), int(q[2]), int(q[3]));
      mesh.faces.emplace_back(int(q[1]), int(q[3]), int(q[0]));
    }
  }
  progress.advance(slices);
  return mesh;
}

}  // namespace exsynth
