#pragma once
// Cancelling a job inside each of its stages, deterministically (no timing):
// the context's hooks cancel at the first cancel check made after a chosen
// stage has started. A StageProgress names its stage before its own check,
// so that first check is the stage's own opening check; the cancel is made
// at the next one. If the stage has a check inside its work, Cancelled comes
// out of that stage; if not, the next stage starts (and is named) first, and
// the test sees the wrong stage at the throw.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "exsynth/errors.hpp"
#include "exsynth/exec_context.hpp"

namespace exsynth::testing {

using Job = std::function<void(ExecContext*)>;

/// The stages a job runs through, in order of first appearance, and the
/// progress at the end of the run.
struct StageLog {
  std::vector<std::string> names;
  std::vector<double> start_progress;  ///< progress when each stage first started
  double final_progress = 0;
};

inline StageLog stages_of(const Job& job) {
  ExecContext ctx;
  StageLog log;
  ctx.on_stage([&] {
    const std::string s = ctx.stage();
    if (std::find(log.names.begin(), log.names.end(), s) != log.names.end()) return;
    log.names.push_back(s);
    log.start_progress.push_back(ctx.progress());
  });
  job(&ctx);
  log.final_progress = ctx.progress();
  return log;
}

struct CancelOutcome {
  bool threw_cancelled = false;
  std::string stage_at_throw;  ///< the stage the context names when Cancelled came out
};

/// Runs the job with a context that cancels inside `stage` (its first start).
inline CancelOutcome cancel_in_stage(const Job& job, const std::string& stage) {
  ExecContext ctx;
  std::atomic<int> armed{0};  // 0: waiting for the stage, 1: skip its opening check, 2: cancel at the next
  ctx.on_stage([&] {
    if (armed.load() == 0 && ctx.stage() == stage) armed.store(1);
  });
  ctx.on_check([&] {
    int expected = 1;
    if (armed.compare_exchange_strong(expected, 2)) return;  // the stage's own opening check
    if (armed.load() == 2) ctx.cancel();
  });
  CancelOutcome out;
  try {
    job(&ctx);
  } catch (const Cancelled&) {
    out.threw_cancelled = true;
  }
  out.stage_at_throw = ctx.stage();
  return out;
}

/// Every stage of the job reports progress (non-decreasing starts, 1 at the
/// end) and can be cancelled from inside its work.
inline void expect_every_stage_cancels(const Job& job, std::size_t min_stages) {
  const StageLog log = stages_of(job);
  EXPECT_GE(log.names.size(), min_stages);
  EXPECT_DOUBLE_EQ(log.final_progress, 1.0);
  EXPECT_TRUE(std::is_sorted(log.start_progress.begin(), log.start_progress.end()));
  for (const std::string& name : log.names) {
    SCOPED_TRACE("cancelled in stage '" + name + "'");
    const CancelOutcome o = cancel_in_stage(job, name);
    EXPECT_TRUE(o.threw_cancelled);
    EXPECT_EQ(o.stage_at_throw, name);
  }
}

}  // namespace exsynth::testing
