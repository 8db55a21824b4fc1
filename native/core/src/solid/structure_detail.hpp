#pragma once
// Structure from the optimiser's weighted mean, detail from the exemplar
// values (TextureOptimizationOptions::structure_sigma; docs/solid.md,
// seventeenth and eighteenth passes). The mean (Kopf et al.'s result) has
// the cells and cracks in the right places but blurred; the exemplar values
// are crisp but their outlines dissolve into the grain at 2-4 voxels. The
// split keeps the mean's low frequencies and the values' high ones:
//   out = G(mean) + (values - G(values)),  G = Gaussian of sigma voxels,
// then matches each channel's histogram to the exemplars' (the sum is no
// longer a set of exemplar texels and can leave their range).
#include <cstddef>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::solid {

/// Separable Gaussian (radius ceil(3 sigma), weights normalised) of the
/// first `channels` channels along every axis longer than one voxel;
/// Boundary::Wrap for tileable textures. Advances `progress` by one unit per
/// line of voxels along each blurred axis (blur_units).
void gaussian_blur(Volume& v, double sigma, Boundary boundary, int channels, StageProgress& progress);
std::size_t blur_units(const Volume& v);

/// Rank matching: each of the first `channels` channels of `v` takes, voxel
/// for voxel in the order of its values (ties by voxel index), the values of
/// the same quantiles of the pooled pixels of `images` (same channel). Exact
/// and deterministic; one unit of progress per channel.
void match_histograms(Volume& v, int channels, const std::vector<const Image*>& images, StageProgress& progress);

/// values <- G(mean) + values - G(values), computed as values + G(mean -
/// values), then match_histograms. `mean` is consumed. Units: split_units.
void split_structure_detail(Volume& values, Volume&& mean, double sigma, Boundary boundary, int channels,
                            const std::vector<const Image*>& images, StageProgress& progress);
std::size_t split_units(const Volume& v, int channels);

}  // namespace exsynth::solid
