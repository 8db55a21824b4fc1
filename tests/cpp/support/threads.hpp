#pragma once
// Running a computation on exactly n TBB threads, more than the machine's
// cores if asked: determinism tests compare 1, 2 and 8 threads on 2 cores.
// max_allowed_parallelism alone only caps the default arena (one thread per
// core); an arena of n slots under a cap of n gets n threads.
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <utility>

namespace exsynth::testing {

template <class F>
auto on_threads(int n, F&& f) {
  tbb::global_control cap(tbb::global_control::max_allowed_parallelism, std::size_t(n));
  tbb::task_arena arena(n);
  return arena.execute(std::forward<F>(f));
}

}  // namespace exsynth::testing
