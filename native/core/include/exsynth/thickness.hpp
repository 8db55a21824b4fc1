#pragma once
// How thick a model is where its surface is: for each surface sample, the
// largest ball inside the model that touches the surface there (its centre
// walked inward along the normal while the signed distance at the centre
// still covers the radius); the model's thickness is a robust percentile of
// those diameters over the surface. Thin parts weigh by their area, so a
// model with thin limbs measures thinner than its bounding box suggests:
// the add-on and the CLI size Geometric Texture's pattern from it.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth {

/// Option limits, checked by model_thickness (exported for the bindings).
constexpr int kMinThicknessResolution = 16, kMaxThicknessResolution = 1024;

struct ThicknessOptions {
  int resolution = 96;       ///< voxels along the longest bounding-box side (16..1024)
  double percentile = 50.0;  ///< of the surface samples' diameters, in [0, 100]
  /// The pattern (a built-in pair's cube) spans this many thicknesses:
  /// chosen by looking at Geometric Texture on the armadillo, bunny and cow
  /// (docs/analogy.md); 2 gives the bunny about the old half of its side.
  double pattern_per_thickness = 2.0;
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;    ///< unused: the measure is deterministic
};

struct ThicknessResult {
  double thickness = 0.0;    ///< the percentile, in mesh units
  double voxel_size = 0.0;   ///< of the signed-distance grid it was measured on
  std::size_t samples = 0;   ///< surface samples (voxels just inside the surface)
  double median = 0.0, low = 0.0, high = 0.0;  ///< 50th, 10th, 90th percentiles
  double pattern_size = 0.0;  ///< thickness * pattern_per_thickness: the default pattern size
};

/// Measures `mesh` (closed, as voxelize wants it). Throws InvalidInput for
/// options out of range or a mesh with no inside at this resolution.
ThicknessResult model_thickness(const TriangleMesh& mesh, const ThicknessOptions& opt = {},
                                ExecContext* ctx = nullptr);

/// The per-sample diameters on a given signed distance (positive outside),
/// in sample order (voxel order); model_thickness takes their percentile.
/// Exposed for the tests' brute-force reference.
struct ThicknessSample {
  Eigen::Vector3f surface;   ///< the sample's surface point (world)
  Eigen::Vector3f inward;    ///< unit inward normal there
  float diameter = 0.0f;     ///< of the largest inscribed ball touching there
};
std::vector<ThicknessSample> thickness_samples(const Volume& sdf, ExecContext* ctx = nullptr);
/// The same, its stage reporting progress lo..hi of the context's bar.
std::vector<ThicknessSample> thickness_samples(const Volume& sdf, ExecContext* ctx, double lo, double hi);

/// Nearest-rank percentile q in [0, 100] of `values` (copied, not sorted in place).
double percentile_of(std::vector<float> values, double q);

}  // namespace exsynth
