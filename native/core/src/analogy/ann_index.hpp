#pragma once
// Approximate nearest neighbour in PCA space: a nanoflann k-d tree over the
// rows of a coefficient matrix. Private to the analogy.
#include <functional>

#include <nanoflann.hpp>

#include "search/pca.hpp"

namespace exsynth::analogy {

class AnnIndex {
 public:
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<search::RowMatrixXf, -1, nanoflann::metric_L2_Simple>;
  explicit AnnIndex(const search::RowMatrixXf& points) : tree_(int(points.cols()), std::cref(points), 16) {
    tree_.index->buildIndex();
  }
  /// Row of the (1 + eps)-approximate nearest neighbour of q.
  Eigen::Index nearest(const float* q, float eps) const {
    Eigen::Index idx = 0;
    float d2 = 0;
    nanoflann::KNNResultSet<float, Eigen::Index> result(1);
    result.init(&idx, &d2);
    tree_.index->findNeighbors(result, q, nanoflann::SearchParams(32, eps));
    return idx;
  }

 private:
  Tree tree_;
};

}  // namespace exsynth::analogy
