#pragma once
// Progress, stage name and cancel flag shared between a running job and the
// thread that watches it (the Blender UI). Every member is thread-safe.
#include <atomic>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>

#include "exsynth/errors.hpp"

namespace exsynth {

class ExecContext {
 public:
  /// Ask the running job to stop; it throws Cancelled at its next chunk.
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  /// Throws Cancelled if cancel() was called.
  void check() const {
    if (on_check_) on_check_();
    if (cancelled()) throw Cancelled("cancelled by the user");
  }

  /// Progress p in [0, 1] of the current call, shown as lo + p (hi - lo)
  /// of the whole job (see set_span).
  void set_progress(double p) { progress_.store(in_span(p), std::memory_order_relaxed); }
  /// As set_progress, but never lowers the progress shown: parallel chunks
  /// report through it (StageProgress::advance), and two that finish
  /// together may store their counts out of order (a bar going back from
  /// 0.185 to 0.1846 failed a Blender test in CI).
  void raise_progress(double p) {
    const double value = in_span(p);
    double shown = progress_.load(std::memory_order_relaxed);
    while (value > shown && !progress_.compare_exchange_weak(shown, value, std::memory_order_relaxed)) {
    }
  }
  /// A job made of several calls gives each its share of one progress bar:
  /// set_span(0.2, 0.9) before a call makes that call's 0..1 read 0.2..0.9.
  /// Set it between calls, not while one runs. Default: [0, 1].
  void set_span(double lo, double hi) {
    lo = lo < 0 ? 0 : (lo > 1 ? 1 : lo);
    hi = hi < lo ? lo : (hi > 1 ? 1 : hi);
    span_lo_.store(lo, std::memory_order_relaxed);
    span_hi_.store(hi, std::memory_order_relaxed);
    progress_.store(lo, std::memory_order_relaxed);
  }
  double progress() const { return progress_.load(std::memory_order_relaxed); }

  void set_stage(std::string stage) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stage_ = std::move(stage);
    }
    if (on_stage_) on_stage_();
  }
  std::string stage() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stage_;
  }

  /// Hooks for logs and tests (tests/cpp/support/cancel.hpp cancels inside
  /// a chosen stage with them); set them before the job starts. on_stage:
  /// on the job's thread whenever a stage starts, after its name is set.
  /// on_check: at every cancel check, before the flag is read, from any of
  /// the job's threads (so it must be thread-safe).
  void on_stage(std::function<void()> hook) { on_stage_ = std::move(hook); }
  void on_check(std::function<void()> hook) { on_check_ = std::move(hook); }

 private:
  // p clamped to [0, 1], mapped into the span.
  double in_span(double p) const {
    p = p < 0 ? 0 : (p > 1 ? 1 : p);
    const double lo = span_lo_.load(std::memory_order_relaxed), hi = span_hi_.load(std::memory_order_relaxed);
    return lo + p * (hi - lo);
  }

  std::atomic<bool> cancelled_{false};
  std::atomic<double> progress_{0.0};
  std::atomic<double> span_lo_{0.0}, span_hi_{1.0};
  mutable std::mutex mutex_;
  std::string stage_;
  std::function<void()> on_stage_, on_check_;
};

/// One stage of a job: maps `total` units of work onto the progress range
/// [lo, hi] of an (optional) ExecContext. advance() is thread-safe, so
/// parallel chunks can report as they finish.
class StageProgress {
 public:
  StageProgress(ExecContext* ctx, std::string stage, double lo, double hi, std::size_t total)
      : ctx_(ctx), lo_(lo), hi_(hi), total_(total ? total : 1) {
    // Named before the check, so a cancel that arrives between two stages
    // is reported at the stage that starts (and seen as such by the hooks).
    if (ctx_) {
      ctx_->set_progress(lo_);
      ctx_->set_stage(std::move(stage));
      ctx_->check();
    }
  }
  /// Throws Cancelled when the context was cancelled.
  void check() const {
    if (ctx_) ctx_->check();
  }
  /// For serial loops: checks on every 65536th iteration i (i = 0 included),
  /// cheap enough to call on each.
  void check_every(std::size_t i) const {
    if ((i & 0xFFFF) == 0) check();
  }
  void advance(std::size_t units = 1) {
    std::size_t done = done_.fetch_add(units, std::memory_order_relaxed) + units;
    if (ctx_) ctx_->raise_progress(lo_ + (hi_ - lo_) * double(done) / double(total_));
  }
  ExecContext* context() const { return ctx_; }

 private:
  ExecContext* ctx_;
  double lo_, hi_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
};

}  // namespace exsynth
