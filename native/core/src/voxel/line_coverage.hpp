#pragma once
// Turning the crossings of one axis-aligned line into per-voxel values.
// Voxel k's centre is at coordinate k; it spans [k - 0.5, k + 0.5].
// Inside is decided by parity: the intervals [x0, x1], [x2, x3], ... are
// inside; with an odd count (an open mesh) the last one runs to +infinity,
// as plain parity says — the vote across axes is what repairs that.
#include <cstdint>
#include <vector>

#include "voxel/axis_rays.hpp"

namespace exsynth::voxel {

/// cov[k] += weight * |inside ∩ voxel k| for k in [0, n).
void accumulate_coverage(const std::vector<Crossing>& xs, int n, float weight, float* cov);

/// inside[k] = 1 if voxel k's centre is inside (odd number of crossings below it), else 0.
void centre_parity(const std::vector<Crossing>& xs, int n, std::uint8_t* inside);

}  // namespace exsynth::voxel
