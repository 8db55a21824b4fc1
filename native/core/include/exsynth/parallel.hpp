#pragma once
// Parallel loops over index ranges with cancel checks and progress at chunk
// granularity. Work inside a chunk must depend only on its indices (and RNG
// streams derived from them) so results do not depend on the thread count.
#include <algorithm>
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "exsynth/exec_context.hpp"

namespace exsynth {

/// Calls body(begin, end) on disjoint chunks of [0, n) in parallel. Before
/// each chunk the stage's context is checked (Cancelled propagates out of
/// the loop); after it, progress advances by the chunk's size. Chunks hold
/// at most `grain` indices (a simple partitioner: TBB's default one hands
/// each thread a share of the whole range, which made the checks of a
/// 384^3 voxelization 1-2 s apart).
template <class Body>
void parallel_chunks(std::size_t n, std::size_t grain, StageProgress& progress, Body&& body) {
  grain = std::max<std::size_t>(grain, 1);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, grain),
      [&](const tbb::blocked_range<std::size_t>& r) {
        progress.check();
        body(r.begin(), r.end());
        progress.advance(r.size());
      },
      tbb::simple_partitioner());
}

}  // namespace exsynth
