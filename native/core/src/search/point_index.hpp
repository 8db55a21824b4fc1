#pragma once
// A nanoflann k-d tree over 3-D points (float), for radius and k-nearest
// queries. The points are referenced, not copied: keep them alive.
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "search/nanoflann_compat.hpp"

namespace exsynth::search {

class PointIndex {
 public:
  explicit PointIndex(const std::vector<Eigen::Vector3f>& points)
      : adaptor_{&points}, tree_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(12)) {
    if (!points.empty()) nf::ensure_built(tree_);
  }
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  std::size_t size() const { return adaptor_.points->size(); }

  /// Indices and squared distances of the points within `radius` of q, in the
  /// tree's order (deterministic, not sorted: sorting cost 10 % of a synthesis).
  void radius(const Eigen::Vector3f& q, float radius, std::vector<std::pair<std::size_t, float>>& out) const {
    out.clear();
    if (size() == 0) return;
    nf::RadiusCollector<std::size_t, float> collect(radius * radius, out);
    tree_.findNeighbors(collect, q.data(), nf::params(0.0f, false));
  }

  /// Up to k nearest: fills idx / d2 and returns how many were found.
  std::size_t knn(const Eigen::Vector3f& q, std::size_t k, std::size_t* idx, float* d2) const {
    if (size() == 0) return 0;
    nanoflann::KNNResultSet<float, std::size_t> result(k);
    result.init(idx, d2);
    tree_.findNeighbors(result, q.data(), nf::params());
    return result.size();
  }

 private:
  struct Adaptor {
    const std::vector<Eigen::Vector3f>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t i, std::size_t d) const { return (*points)[i][int(d)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>, Adaptor, 3, std::size_t>;
  Adaptor adaptor_;
  Tree tree_;
};

}  // namespace exsynth::search
