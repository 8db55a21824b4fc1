#pragma once
// Approximate nearest neighbour in PCA space for the analogy: the shared
// nanoflann k-d tree of search/.
#include "search/kd_tree.hpp"

namespace exsynth::analogy {

using AnnIndex = search::KdTree;

}  // namespace exsynth::analogy
