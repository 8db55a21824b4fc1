#pragma once
// A small s-t max-flow / min-cut for the graph cuts of image/seam_cut.hpp:
// graphs of one local window (about a thousand nodes, four-neighbour grid
// edges plus terminal edges), built and solved thousands of times per image.
//
// Dinic's algorithm (BFS levels, blocking flow by DFS with per-node edge
// cursors) rather than Boykov-Kolmogorov: a fraction of BK's code and, on
// these windows, fast enough. Measured (256^2 from 128^2, 8 exemplars,
// load 5-9 on 2 shared cores): the whole cut stage, graphs and pair costs
// included, adds 0.1-0.2 s CPU with cut_reach 2 (graphs of the pixels near
// each alpha) and ~2 s with cut_reach 0 (every window pixel a node); the
// flow's own share was not profiled apart. The stack has no graph library. Capacities are doubles; an edge whose
// residual falls below `kEps` times the largest capacity counts as saturated.
#include <cstddef>
#include <vector>

namespace exsynth::image {

class MaxFlow {
 public:
  explicit MaxFlow(int nodes = 0) { reset(nodes); }
  /// Empties the graph and sizes it for `nodes` nodes (storage is kept).
  void reset(int nodes);
  int nodes() const { return int(head_.size()); }
  /// Terminal capacities of node i: source -> i (cut when i ends on the sink
  /// side) and i -> sink (cut when i stays on the source side); added to
  /// what the node has.
  void add_terminal(int i, double from_source, double to_sink);
  /// Edge i -> j with capacity `forward` and j -> i with `backward`.
  void add_edge(int i, int j, double forward, double backward);
  /// The maximum flow (= the minimum cut's capacity).
  double solve();
  /// After solve(): whether node i is on the source side of a minimum cut
  /// (reachable from the source in the residual graph).
  bool source_side(int i) const { return seen_[std::size_t(i)] == visit_; }

 private:
  struct Arc {
    int to;
    int next;
    double cap;
  };
  bool levels();
  double push(int v, double limit);

  std::vector<int> head_;  ///< first arc of each node, -1 = none (nodes, then source, then sink)
  std::vector<Arc> arcs_;  ///< arcs in pairs (2k, 2k + 1 reverse)
  std::vector<int> level_, cursor_, queue_;
  std::vector<int> seen_;
  int visit_ = 0;
  int source_ = 0, sink_ = 0;
  double max_cap_ = 0.0;
};

}  // namespace exsynth::image
