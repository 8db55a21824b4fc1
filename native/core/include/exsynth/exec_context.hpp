#pragma once
// Progress, stage name and cancel flag shared between a running job and the
// thread that watches it (the Blender UI). Every member is thread-safe.
#include <atomic>
#include <cstddef>
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
    if (cancelled()) throw Cancelled("cancelled by the user");
  }

  void set_progress(double p) {
    progress_.store(p < 0 ? 0 : (p > 1 ? 1 : p), std::memory_order_relaxed);
  }
  double progress() const { return progress_.load(std::memory_order_relaxed); }

  void set_stage(std::string stage) {
    std::lock_guard<std::mutex> lock(mutex_);
    stage_ = std::move(stage);
  }
  std::string stage() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stage_;
  }

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<double> progress_{0.0};
  mutable std::mutex mutex_;
  std::string stage_;
};

/// One stage of a job: maps `total` units of work onto the progress range
/// [lo, hi] of an (optional) ExecContext. advance() is thread-safe, so
/// parallel chunks can report as they finish.
class StageProgress {
 public:
  StageProgress(ExecContext* ctx, std::string stage, double lo, double hi, std::size_t total)
      : ctx_(ctx), lo_(lo), hi_(hi), total_(total ? total : 1) {
    if (ctx_) {
      ctx_->check();
      ctx_->set_stage(std::move(stage));
      ctx_->set_progress(lo_);
    }
  }
  /// Throws Cancelled when the context was cancelled.
  void check() const {
    if (ctx_) ctx_->check();
  }
  void advance(std::size_t units = 1) {
    std::size_t done = done_.fetch_add(units, std::memory_order_relaxed) + units;
    if (ctx_) ctx_->set_progress(lo_ + (hi_ - lo_) * double(done) / double(total_));
  }
  ExecContext* context() const { return ctx_; }

 private:
  ExecContext* ctx_;
  double lo_, hi_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
};

}  // namespace exsynth
