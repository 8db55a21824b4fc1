#pragma once
// Clean-up after the analogy: parts of B' that float free of B.
#include <cstddef>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::analogy {

/// Inside parts of b_prime (sdf < 0, 6-connected) that share no voxel with
/// b's inside are made empty, and empty pockets that share no voxel with
/// b's outside are filled: a copied spike tip that grew no spike under it,
/// a bubble no pit opened. Parts under 0.2 % of the largest part on their
/// side (and under 27 voxels) go too. Returns the number of voxels changed.
/// Checks `progress` for a cancel every 65536 voxels.
std::size_t remove_debris(Volume& b_prime, const Volume& b, StageProgress& progress);

}  // namespace exsynth::analogy
