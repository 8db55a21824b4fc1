// ExecContext, StageProgress, parallel_chunks, per-index RNG, memory budget.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <thread>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"

using namespace exsynth;

TEST(ExecContext, CancelIsSeenFromAnotherThread) {
  ExecContext ctx;
  EXPECT_FALSE(ctx.cancelled());
  std::thread t([&] { ctx.cancel(); });
  t.join();
  EXPECT_TRUE(ctx.cancelled());
  EXPECT_THROW(ctx.check(), Cancelled);
}

TEST(ExecContext, StageProgressMapsOntoItsRange) {
  ExecContext ctx;
  StageProgress p(&ctx, "stage two", 0.5, 0.75, 4);
  EXPECT_EQ(ctx.stage(), "stage two");
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.5);
  p.advance(2);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.625);
  p.advance(2);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.75);
  ctx.set_progress(7);
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);  // clamped
}

// Chunks finishing together may report their counts out of order; the bar
// never goes back within a stage (raise_progress), and a new stage still
// sets its start.
TEST(ExecContext, ProgressNeverGoesBackWithinAStage) {
  ExecContext ctx;
  ctx.set_span(0.2, 0.6);
  ctx.raise_progress(0.5);
  ctx.raise_progress(0.25);  // a late, smaller count
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.4);
  ctx.set_progress(0.0);  // set_progress may lower it: a stage's start
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.2);
  // Many threads advancing one stage while another samples the bar.
  ctx.set_span(0.0, 1.0);
  StageProgress stage(&ctx, "stress", 0.0, 1.0, 8 * 20000);
  std::atomic<bool> running{true};
  int backwards = 0;
  std::thread watch([&] {
    double last = 0.0;
    while (running.load()) {
      const double p = ctx.progress();
      backwards += p < last;
      last = p;
    }
  });
  std::vector<std::thread> workers;
  for (int t = 0; t < 8; ++t)
    workers.emplace_back([&] {
      for (int i = 0; i < 20000; ++i) stage.advance();
    });
  for (std::thread& w : workers) w.join();
  running = false;
  watch.join();
  EXPECT_EQ(backwards, 0);
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);
}

TEST(ExecContext, ASpanGivesOneCallItsShareOfTheBar) {
  ExecContext ctx;
  ctx.set_span(0.2, 0.6);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.2);
  StageProgress p(&ctx, "inside", 0.0, 1.0, 2);  // a call that knows nothing of the span
  p.advance(1);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.4);
  ctx.set_progress(1.0);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.6);
  ctx.set_span(0.9, 0.1);  // hi < lo: an empty span at lo
  ctx.set_progress(0.5);
  EXPECT_DOUBLE_EQ(ctx.progress(), 0.9);
}

TEST(ParallelChunks, CoversEveryIndexOnceAndStopsWhenCancelled) {
  ExecContext ctx;
  StageProgress p(&ctx, "loop", 0, 1, 1000);
  std::vector<int> hits(1000, 0);
  parallel_chunks(1000, 7, p, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) ++hits[i];
  });
  for (int h : hits) EXPECT_EQ(h, 1);
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);

  ExecContext cancelled;
  StageProgress q(&cancelled, "loop", 0, 1, 1000);
  cancelled.cancel();
  EXPECT_THROW(parallel_chunks(1000, 7, q, [](std::size_t, std::size_t) {}), Cancelled);
}

TEST(IndexRng, DependsOnlyOnSeedIndexAndStream) {
  auto draw = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::vector<double> out(5000);
    StageProgress p(nullptr, "rng", 0, 1, out.size());
    parallel_chunks(out.size(), 13, p, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out[i] = IndexRng(42, i).uniform();
    });
    return out;
  };
  const auto one = draw(1), two = draw(2);
  EXPECT_EQ(one, two);
  EXPECT_NE(IndexRng(42, 0).next(), IndexRng(43, 0).next());
  EXPECT_NE(IndexRng(42, 0, 0).next(), IndexRng(42, 0, 1).next());
  double mean = 0;
  for (double x : one) {
    EXPECT_GE(x, 0.0);
    EXPECT_LT(x, 1.0);
    mean += x / one.size();
  }
  EXPECT_NEAR(mean, 0.5, 0.02);
}

TEST(MemoryBudget, RefusesWithSizesAndAdvice) {
  EXPECT_NO_THROW(check_memory_budget(1000, 2000, "job", "advice"));
  try {
    check_memory_budget(3.0 * (1 << 30), std::size_t(1) << 30, "voxelizing at 2048^3", "lower the resolution");
    FAIL();
  } catch (const OverBudget& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("3.00 GiB"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("1.00 GiB"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("lower the resolution"));
  }
  EXPECT_EQ(format_bytes(512), "512 B");
}
