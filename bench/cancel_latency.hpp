#pragma once
// Cancel latency per stage (issue 12: every stage cancellable within 0.2 s),
// shared by the benchmarks of each job. One run records the time of every
// stage start and every cancel check (the context's hooks); a cancel arriving
// at any moment is seen at the next check, so the longest gap between
// consecutive checks inside a stage bounds its latency. Then one run per
// stage is cancelled from another thread halfway through that stage, and the
// time from cancel() to the Cancelled exception is measured. On a shared
// machine wall-clock gaps grow with the load, so the gaps are also given in
// process CPU time, which does not: for a serial stage that is the unloaded
// wall-clock gap, for a stage running on both cores twice it (an upper bound
// either way). Counters: the worst stage's gaps and measured latency (ms);
// the per-stage table is printed to stderr.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include "exsynth/errors.hpp"
#include "exsynth/exec_context.hpp"

namespace exsynth_bench {

using Clock = std::chrono::steady_clock;
using Job = std::function<void(exsynth::ExecContext*)>;

inline double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

inline double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct StageTiming {
  std::string name;
  double start_ms = 0, end_ms = 0, max_gap_ms = 0, max_cpu_gap_ms = 0, latency_ms = -1;
};

// Stages (first occurrence of each name, with the time until the next stage
// starts) and the longest gap between checks within each.
inline std::vector<StageTiming> timeline(const Job& job) {
  exsynth::ExecContext ctx;
  std::mutex m;
  struct Check {
    double wall, cpu;
    int stage;
  };
  std::vector<Check> checks;
  std::vector<StageTiming> stages;
  int current = -1;
  const auto t0 = Clock::now();
  ctx.on_stage([&] {
    std::lock_guard<std::mutex> lock(m);
    const double t = ms(Clock::now() - t0);
    const std::string s = ctx.stage();
    if (current >= 0) stages[std::size_t(current)].end_ms = t;
    auto it = std::find_if(stages.begin(), stages.end(), [&](const StageTiming& st) { return st.name == s; });
    if (it == stages.end()) {
      stages.push_back({s, t, t, 0, 0, -1});
      current = int(stages.size()) - 1;
    } else {
      current = int(it - stages.begin());
      it->start_ms = std::min(it->start_ms, t);
    }
    checks.push_back({t, cpu_ms(), current});
  });
  ctx.on_check([&] {
    std::lock_guard<std::mutex> lock(m);
    checks.push_back({ms(Clock::now() - t0), cpu_ms(), current});
  });
  job(&ctx);
  const double end = ms(Clock::now() - t0);
  if (current >= 0) stages[std::size_t(current)].end_ms = end;
  checks.push_back({end, cpu_ms(), -1});
  for (std::size_t i = 0; i + 1 < checks.size(); ++i) {
    const int s = checks[i].stage;
    if (s < 0) continue;
    StageTiming& st = stages[std::size_t(s)];
    st.max_gap_ms = std::max(st.max_gap_ms, checks[i + 1].wall - checks[i].wall);
    st.max_cpu_gap_ms = std::max(st.max_cpu_gap_ms, checks[i + 1].cpu - checks[i].cpu);
  }
  return stages;
}

// Cancels from another thread `delay_ms` after stage `name` first starts;
// returns the time from cancel() to the exception (-1: the job finished).
inline double cancel_latency(const Job& job, const std::string& name, double delay_ms) {
  exsynth::ExecContext ctx;
  std::thread canceller;
  Clock::time_point cancelled_at;
  bool started = false;
  ctx.on_stage([&] {
    if (started || ctx.stage() != name) return;
    started = true;
    canceller = std::thread([&, delay_ms] {
      std::this_thread::sleep_for(std::chrono::microseconds(long(delay_ms * 1000)));
      cancelled_at = Clock::now();
      ctx.cancel();
    });
  });
  double latency = -1;
  try {
    job(&ctx);
  } catch (const exsynth::Cancelled&) {
    if (canceller.joinable()) canceller.join();
    latency = ms(Clock::now() - cancelled_at);
  }
  if (canceller.joinable()) canceller.join();
  return latency;
}

inline void report(benchmark::State& state, const char* job_name, const Job& job) {
  std::vector<StageTiming> stages;
  for (auto _ : state) {
    stages = timeline(job);
    for (StageTiming& st : stages) {
      const double length = st.end_ms - st.start_ms;
      if (length < 1.0) continue;  // too short to cancel into
      st.latency_ms = cancel_latency(job, st.name, 0.5 * length);
    }
  }
  double worst_gap = 0, worst_cpu_gap = 0, worst_latency = 0;
  std::fprintf(stderr,
               "\n%s (ms): stage | first run length | longest gap between checks: wall, process CPU | latency of a "
               "cancel halfway\n",
               job_name);
  for (const StageTiming& st : stages) {
    worst_gap = std::max(worst_gap, st.max_gap_ms);
    worst_cpu_gap = std::max(worst_cpu_gap, st.max_cpu_gap_ms);
    worst_latency = std::max(worst_latency, st.latency_ms);
    std::fprintf(stderr, "  %-44s %9.1f %9.1f %9.1f %9.1f\n", st.name.c_str(), st.end_ms - st.start_ms, st.max_gap_ms,
                 st.max_cpu_gap_ms, st.latency_ms);
  }
  state.counters["stages"] = double(stages.size());
  state.counters["worst_gap_ms"] = worst_gap;
  state.counters["worst_cpu_gap_ms"] = worst_cpu_gap;
  state.counters["worst_latency_ms"] = worst_latency;
}

}  // namespace exsynth_bench
