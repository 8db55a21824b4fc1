#pragma once
// A nanoflann k-d tree over the rows of a (PCA coefficient) matrix: the one
// wrapper the solid and analogy searches share. The matrix must outlive the
// tree. Queries are const and thread-safe; results are deterministic (the
// tree is built the same way every time).
#include <functional>

#include "search/nanoflann_compat.hpp"

#include "search/pca.hpp"

namespace exsynth::search {

class KdTree {
 public:
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<RowMatrixXf, -1, nanoflann::metric_L2_Simple>;
  explicit KdTree(const RowMatrixXf& points, int leaf_size = 16) : tree_(int(points.cols()), std::cref(points), leaf_size) {
    nf::ensure_built(nf::index(tree_));
  }

  /// Row of the (1 + eps)-approximate nearest neighbour of q (eps = 0: exact).
  Eigen::Index nearest(const float* q, float eps = 0.0f) const {
    Eigen::Index idx = 0;
    float d2 = 0;
    knn(q, 1, &idx, &d2, eps);
    return idx;
  }

  /// The k nearest rows of q, closest first (eps = 0: exact); returns how
  /// many were found (fewer than k only when the matrix has fewer rows).
  std::size_t knn(const float* q, std::size_t k, Eigen::Index* idx, float* d2, float eps = 0.0f) const {
    nanoflann::KNNResultSet<float, Eigen::Index> result(k);
    result.init(idx, d2);
    nf::index(tree_).findNeighbors(result, q, nf::params(eps));
    return result.size();
  }

 private:
  Tree tree_;
};

}  // namespace exsynth::search
