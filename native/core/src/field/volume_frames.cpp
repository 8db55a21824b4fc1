#include "exsynth/frames.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include "search/nanoflann_compat.hpp"

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "grid/gradient.hpp"
#include "search/pca.hpp"
#include "voxel/distance_transform.hpp"

namespace exsynth {
namespace {

using search::RowMatrixXf;
using Tree = nanoflann::KDTreeEigenMatrixAdaptor<RowMatrixXf, 3, nanoflann::metric_L2_Simple>;

// A unit vector perpendicular to n: v projected, or if v is (nearly) along
// n, the coordinate axis least aligned with n, projected.
Eigen::Vector3f tangent_of(const Eigen::Vector3f& v, const Eigen::Vector3f& n) {
  Eigen::Vector3f t = v - v.dot(n) * n;
  if (t.norm() > 1e-4f) return t.normalized();
  Eigen::Index axis;
  n.cwiseAbs().minCoeff(&axis);
  Eigen::Vector3f e = Eigen::Vector3f::Zero();
  e[axis] = 1.0f;
  return (e - e.dot(n) * n).normalized();
}

Eigen::Vector3f get3(const Volume& v, std::size_t i) {
  const float* p = v.data() + i * 3;
  return {p[0], p[1], p[2]};
}
void set3(Volume& v, std::size_t i, const Eigen::Vector3f& x) {
  float* p = v.data() + i * 3;
  p[0] = x.x(), p[1] = x.y(), p[2] = x.z();
}

}  // namespace

VolumeFrames volume_frames(const Volume& sdf, const std::vector<Eigen::Vector3f>& points,
                           const std::vector<Eigen::Vector3f>& vectors, const FrameOptions& opt, ExecContext* ctx) {
  if (sdf.empty() || sdf.channels() != 1) throw InvalidInput("the signed distance volume must have 1 channel and at least one voxel");
  if (points.empty() || points.size() != vectors.size())
    throw InvalidInput("the field needs one direction per point and at least one point (got " +
                       std::to_string(points.size()) + " points and " + std::to_string(vectors.size()) + " vectors)");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite() || !vectors[i].allFinite())
      throw InvalidInput("field point " + std::to_string(i) + " is not finite; fix the field first");
  if (!(opt.band > 0) || !std::isfinite(opt.band) || opt.smoothing_steps < 0 || opt.smoothing_steps > kMaxSmoothingSteps)
    throw InvalidInput("band must be a finite number > 0 (voxels) and smoothing_steps between 0 and " +
                       std::to_string(kMaxSmoothingSteps));

  const int nx = sdf.nx(), ny = sdf.ny(), nz = sdf.nz();
  const std::size_t voxels = sdf.voxel_count();
  const GridTransform& xf = sdf.transform();
  const float h = float(xf.voxel_size);
  VolumeFrames f{Volume(nx, ny, nz, 3, 0.0f, xf), Volume(nx, ny, nz, 3, 0.0f, xf), Volume(nx, ny, nz, 3, 0.0f, xf)};
  auto index = [&](int x, int y, int z) { return (std::size_t(z) * ny + y) * nx + x; };

  // N: the normalised central-difference gradient (one-sided on the border).
  StageProgress normals(ctx, "frames: normals", 0.0, 0.2, std::size_t(nz));
  parallel_chunks(std::size_t(nz), 1, normals, [&](std::size_t z0, std::size_t z1) {
    for (int z = int(z0); z < int(z1); ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) set3(f.n, index(x, y, z), grid::unit_normal(sdf, x, y, z));
  });

  // Surface voxels take the field of their nearest field point.
  RowMatrixXf cloud(Eigen::Index(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) cloud.row(Eigen::Index(i)) = points[i].transpose();
  StageProgress field_index(ctx, "frames: field index", 0.2, 0.2, 1);
  Tree tree(3, std::cref(cloud), 16);
  search::nf::ensure_built(search::nf::index(tree));
  field_index.check();
  std::vector<float> dist2(voxels, voxel::kFarAway);
  std::vector<std::int32_t> label(voxels, -1);
  StageProgress surface(ctx, "frames: surface field", 0.2, 0.5, voxels);
  parallel_chunks(voxels, 4096, surface, [&](std::size_t v0, std::size_t v1) {
    for (std::size_t v = v0; v < v1; ++v) {
      if (std::abs(sdf.values()[v]) > opt.band * h) continue;
      const int x = int(v % nx), y = int((v / nx) % ny), z = int(v / (std::size_t(nx) * ny));
      const auto w = xf.index_to_world(x, y, z);
      const float q[3] = {float(w[0]), float(w[1]), float(w[2])};
      Eigen::Index nearest = 0;
      float d2 = 0;
      nanoflann::KNNResultSet<float, Eigen::Index> result(1);
      result.init(&nearest, &d2);
      search::nf::index(tree).findNeighbors(result, q, search::nf::params());
      set3(f.t, v, tangent_of(vectors[std::size_t(nearest)], get3(f.n, v)));
      dist2[v] = 0.0f;
      label[v] = std::int32_t(v);  // the voxel itself: the transform carries surface voxels
    }
  });
  bool any = false;
  for (float d : dist2) any = any || d == 0.0f;
  if (!any) throw InvalidInput("the volume has no voxels within " + std::to_string(opt.band) +
                               " voxels of its surface; is it a signed distance field in world units?");

  // Every other voxel: the field of its nearest surface voxel (exact
  // Euclidean feature transform), then fix-and-diffuse: average the six
  // neighbours, re-fix the surface, a few times.
  StageProgress spread(ctx, "frames: propagate", 0.5, 0.8, std::size_t(ny) * nz + std::size_t(nx) * nz + std::size_t(nx) * ny);
  voxel::distance_transform(nx, ny, nz, dist2, label, spread);
  std::vector<std::uint8_t> fixed(voxels);
  for (std::size_t v = 0; v < voxels; ++v) {
    spread.check_every(v);
    fixed[v] = label[v] == std::int32_t(v);
    if (!fixed[v]) set3(f.t, v, get3(f.t, std::size_t(label[v])));
  }
  StageProgress smooth(ctx, "frames: smooth", 0.8, 1.0, std::size_t(opt.smoothing_steps + 1) * nz);
  for (int step = 0; step < opt.smoothing_steps; ++step) {
    const Volume prev = f.t;
    parallel_chunks(std::size_t(nz), 1, smooth, [&](std::size_t z0, std::size_t z1) {
      for (int z = int(z0); z < int(z1); ++z)
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            const std::size_t v = index(x, y, z);
            if (fixed[v]) continue;
            Eigen::Vector3f sum = get3(prev, v);
            const int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
            for (const auto& p : nb)
              if (p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] < nx && p[1] < ny && p[2] < nz)
                sum += get3(prev, index(p[0], p[1], p[2]));
            set3(f.t, v, sum);  // normalised with the projection below
          }
    });
  }
  // Project T perpendicular to N, normalise, B = T x N.
  parallel_chunks(std::size_t(nz), 1, smooth, [&](std::size_t z0, std::size_t z1) {
    for (std::size_t v = z0 * nx * ny; v < z1 * nx * ny; ++v) {
      const Eigen::Vector3f n = get3(f.n, v);
      const Eigen::Vector3f t = tangent_of(get3(f.t, v), n);
      set3(f.t, v, t);
      set3(f.b, v, t.cross(n));
    }
  });
  if (ctx) ctx->set_progress(1.0);
  return f;
}

}  // namespace exsynth
