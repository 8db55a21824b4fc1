#pragma once
// The band of voxels a level searches: visiting orders and what carries
// over from the coarser level. Private to the analogy.
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::analogy {

// Band positions in breadth-first order over 26-neighbours within the band,
// each piece started from its first position in `order`. (Each of these
// checks `progress` for a cancel at chunk granularity.)
std::vector<std::uint32_t> breadth_first(const Volume& grid, const std::vector<std::uint32_t>& band,
                                         const std::vector<std::int32_t>& band_of,
                                         const std::vector<std::uint32_t>& order, const StageProgress& progress);

// The coarser level's volume on this level's grid (coarse index = index / 2).
Volume upsample(const Volume& coarse, const Volume& like, StageProgress& progress);

// The coarser level's sweep distance at this level's voxels (x2: voxel
// units halve), averaged over the coarse corners that have one; empty when
// there is no coarser level.
std::vector<float> upsample_phi(const Volume& phi_coarse, const Volume& has_coarse, const Volume& level,
                                const std::vector<std::uint32_t>& voxels, StageProgress& progress);

// The band's positions (0..n-1) in increasing `key`, ties by position: a
// stable sort, on (key, position) pairs in parallel and checking for a
// cancel (std::stable_sort of 10^6 indices took ~0.2 s without one).
std::vector<std::uint32_t> sorted_by(const std::vector<float>& key, const StageProgress& progress);

}  // namespace exsynth::analogy
