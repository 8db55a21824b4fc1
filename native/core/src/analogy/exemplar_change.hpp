#pragma once
// What the pair A -> A' changes, and where. Private to the analogy.
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::analogy {

// How far the pair moves A's surface: outward (A' has material where A is
// empty: spikes) and inward (A' is empty where A had material: pits,
// grooves), measured at the voxels on either surface.
struct Reach {
  double outward = 0, inward = 0;
};
Reach pair_reach(const Volume& a, const Volume& ap);

// 1 where |A' - A| > tol, dilated by r voxels (a cube). Checks `progress`
// for a cancel once per slice.
std::vector<unsigned char> change_mask(const Volume& a, const Volume& ap, float tol, int r,
                                       const StageProgress& progress);

}  // namespace exsynth::analogy
