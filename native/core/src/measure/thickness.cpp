#include "exsynth/thickness.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/sample.hpp"
#include "exsynth/voxelize.hpp"
#include "grid/gradient.hpp"

namespace exsynth {
namespace {

constexpr int kMinResolution = kMinThicknessResolution, kMaxResolution = kMaxThicknessResolution;

// Signed distance at a world point, trilinear between voxel centres; outside
// the grid it is clamped, which only shortens a walk that left the model.
float sdf_at(const Volume& sdf, const Eigen::Vector3f& p) {
  const auto i = sdf.transform().world_to_index(p.x(), p.y(), p.z());
  return sample_trilinear(sdf, i[0], i[1], i[2], 0);
}

// The radius of the largest ball that touches the surface at `surface` from
// inside: its centre surface + t * inward stays at least t - slack from the
// surface. The walk steps half a voxel, then bisects the last step. `slack`
// (half a voxel) absorbs the interpolation error of the distance, which is
// exact at voxel centres but cut off across the medial axis.
float inscribed_radius(const Volume& sdf, const Eigen::Vector3f& surface, const Eigen::Vector3f& inward,
                       float h) {
  const float step = 0.5f * h, slack = 0.5f * h;
  auto fits = [&](float t) { return -sdf_at(sdf, surface + t * inward) >= t - slack; };
  const float t_max = h * float(std::max({sdf.nx(), sdf.ny(), sdf.nz()}));
  float good = 0.0f, bad = -1.0f;
  for (float t = step; t <= t_max; t += step) {
    if (!fits(t)) {
      bad = t;
      break;
    }
    good = t;
  }
  if (bad < 0) return good;
  for (int k = 0; k < 6; ++k) {
    const float mid = 0.5f * (good + bad);
    (fits(mid) ? good : bad) = mid;
  }
  return good;
}

}  // namespace

double percentile_of(std::vector<float> values, double q) {
  if (values.empty()) throw InvalidInput("percentile of no values");
  std::sort(values.begin(), values.end());
  const double rank = std::clamp(q, 0.0, 100.0) / 100.0 * double(values.size() - 1);
  return values[std::size_t(std::lround(rank))];
}

std::vector<ThicknessSample> thickness_samples(const Volume& sdf, ExecContext* ctx) {
  return thickness_samples(sdf, ctx, 0.0, 1.0);
}

std::vector<ThicknessSample> thickness_samples(const Volume& sdf, ExecContext* ctx, double lo, double hi) {
  if (sdf.empty() || sdf.channels() != 1) throw InvalidInput("thickness: the signed distance must be one channel");
  const float h = float(sdf.transform().voxel_size);
  // Samples: the voxels just inside the surface (within one voxel of it).
  std::vector<std::size_t> band;
  for (int z = 0; z < sdf.nz(); ++z)
    for (int y = 0; y < sdf.ny(); ++y)
      for (int x = 0; x < sdf.nx(); ++x) {
        const float d = sdf.at(x, y, z);
        if (d < 0.0f && d > -h) band.push_back(sdf.voxel_index(x, y, z));
      }
  std::vector<ThicknessSample> out(band.size());
  StageProgress progress(ctx, "measuring thickness", lo, hi, band.size());
  parallel_chunks(band.size(), 1024, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t v = band[i];
      const int x = int(v % sdf.nx()), y = int((v / sdf.nx()) % sdf.ny()), z = int(v / (std::size_t(sdf.nx()) * sdf.ny()));
      const Eigen::Vector3f inward = -grid::unit_normal(sdf, x, y, z);
      const auto w = sdf.transform().index_to_world(x, y, z);
      // The voxel centre moved onto the surface along the normal.
      const Eigen::Vector3f surface = Eigen::Vector3f(float(w[0]), float(w[1]), float(w[2])) + sdf.at(x, y, z) * inward;
      out[i] = {surface, inward, 2.0f * inscribed_radius(sdf, surface, inward, h)};
    }
  });
  return out;
}

ThicknessResult model_thickness(const TriangleMesh& mesh, const ThicknessOptions& opt, ExecContext* ctx) {
  validate_mesh(mesh, "mesh");
  if (opt.resolution < kMinResolution || opt.resolution > kMaxResolution)
    throw InvalidInput("thickness: resolution must be " + std::to_string(kMinResolution) + ".." +
                       std::to_string(kMaxResolution) + " (got " + std::to_string(opt.resolution) + ")");
  if (!(opt.percentile >= 0.0 && opt.percentile <= 100.0))
    throw InvalidInput("thickness: percentile must be in [0, 100] (got " + std::to_string(opt.percentile) + ")");
  if (!(opt.pattern_per_thickness > 0.0 && opt.pattern_per_thickness <= 100.0))
    throw InvalidInput("thickness: pattern_per_thickness must be in (0, 100] (got " +
                       std::to_string(opt.pattern_per_thickness) + ")");
  VoxelizeOptions vopt;
  vopt.resolution = opt.resolution;
  vopt.padding = 2;
  vopt.memory_budget = opt.memory_budget;
  const VoxelizeResult grid = voxelize(mesh, vopt, ctx);
  // voxelize reports 0..1 of the bar; the walks (a tenth of its time at the
  // default resolution) run at its end rather than moving the bar back.
  const std::vector<ThicknessSample> samples = thickness_samples(grid.sdf, ctx, 1.0, 1.0);
  if (samples.empty())
    throw InvalidInput("thickness: the mesh has no inside at resolution " + std::to_string(opt.resolution) +
                       " (is it closed? a finer resolution resolves thinner models)");
  std::vector<float> d(samples.size());
  std::transform(samples.begin(), samples.end(), d.begin(), [](const ThicknessSample& s) { return s.diameter; });
  ThicknessResult r;
  r.voxel_size = grid.sdf.transform().voxel_size;
  r.samples = samples.size();
  r.thickness = percentile_of(d, opt.percentile);
  r.median = percentile_of(d, 50.0);
  r.low = percentile_of(d, 10.0);
  r.high = percentile_of(d, 90.0);
  r.pattern_size = r.thickness * opt.pattern_per_thickness;
  return r;
}

}  // namespace exsynth
