#include "image/max_flow.hpp"

#include <algorithm>
#include <limits>

namespace exsynth::image {
namespace {

constexpr double kEps = 1e-12;

}  // namespace

void MaxFlow::reset(int nodes) {
  source_ = nodes;
  sink_ = nodes + 1;
  head_.assign(std::size_t(nodes) + 2, -1);
  arcs_.clear();
  max_cap_ = 0.0;
}

void MaxFlow::add_edge(int i, int j, double forward, double backward) {
  forward = std::max(forward, 0.0);
  backward = std::max(backward, 0.0);
  if (forward <= 0.0 && backward <= 0.0) return;
  arcs_.push_back({j, head_[std::size_t(i)], forward});
  head_[std::size_t(i)] = int(arcs_.size()) - 1;
  arcs_.push_back({i, head_[std::size_t(j)], backward});
  head_[std::size_t(j)] = int(arcs_.size()) - 1;
  max_cap_ = std::max({max_cap_, forward, backward});
}

void MaxFlow::add_terminal(int i, double from_source, double to_sink) {
  if (from_source > 0.0) add_edge(source_, i, from_source, 0.0);
  if (to_sink > 0.0) add_edge(i, sink_, to_sink, 0.0);
}

bool MaxFlow::levels() {
  const double eps = kEps * std::max(max_cap_, 1.0);
  level_.assign(head_.size(), -1);
  queue_.clear();
  queue_.push_back(source_);
  level_[std::size_t(source_)] = 0;
  for (std::size_t k = 0; k < queue_.size(); ++k) {
    const int v = queue_[k];
    for (int a = head_[std::size_t(v)]; a >= 0; a = arcs_[std::size_t(a)].next) {
      const Arc& arc = arcs_[std::size_t(a)];
      if (arc.cap > eps && level_[std::size_t(arc.to)] < 0) {
        level_[std::size_t(arc.to)] = level_[std::size_t(v)] + 1;
        queue_.push_back(arc.to);
      }
    }
  }
  return level_[std::size_t(sink_)] >= 0;
}

double MaxFlow::push(int v, double limit) {
  if (v == sink_) return limit;
  const double eps = kEps * std::max(max_cap_, 1.0);
  double pushed = 0.0;
  for (int& a = cursor_[std::size_t(v)]; a >= 0; a = arcs_[std::size_t(a)].next) {
    Arc& arc = arcs_[std::size_t(a)];
    if (arc.cap <= eps || level_[std::size_t(arc.to)] != level_[std::size_t(v)] + 1) continue;
    const double f = push(arc.to, std::min(limit - pushed, arc.cap));
    if (f > 0.0) {
      arc.cap -= f;
      arcs_[std::size_t(a ^ 1)].cap += f;
      pushed += f;
      if (limit - pushed <= eps) break;
    }
  }
  if (pushed <= 0.0) level_[std::size_t(v)] = -1;  // dead end for this phase
  return pushed;
}

double MaxFlow::solve() {
  double flow = 0.0;
  while (levels()) {
    cursor_ = head_;
    flow += push(source_, std::numeric_limits<double>::infinity());
  }
  // The source side: what the source still reaches (levels() left it in level_).
  seen_.resize(head_.size());
  ++visit_;
  for (std::size_t v = 0; v < head_.size(); ++v)
    if (level_[v] >= 0) seen_[v] = visit_;
  return flow;
}

}  // namespace exsynth::image
