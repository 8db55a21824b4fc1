#pragma once
// Exact nearest rows for a batch of queries, by one matrix product.
//
// The solid optimiser's coarsest level compares every query with every
// exemplar window (in PCA space). Row by row that is a reduction per pair,
// memory-bound; with the exemplar's quarter turns (4x the windows) it was 14 %
// of a 128^3 solid's CPU in perf. Here |c|^2 - 2 q.c for the whole batch
// comes from one GEMM (Eigen's blocked kernel), and every row within a
// rounding bound of the batch row's minimum is re-ranked with the very
// expression the row-by-row search used, so the answer is the same index,
// ties to the lowest (bench/solid_hashes.py: byte-identical solids).
#include <vector>

#include "search/pca.hpp"

namespace exsynth::search {

class ExhaustiveNearest {
 public:
  /// `rows` (count x d) must outlive this object.
  explicit ExhaustiveNearest(const RowMatrixXf& rows);

  /// For query rows [0, count) of `queries` (q x d), the index of the row of
  /// `rows` nearest in squared Euclidean distance, as
  /// `(rows.row(j) - query).squaredNorm()` evaluates it, the lowest index on
  /// ties. `scratch` is the caller's (one per thread), resized as needed.
  void nearest(const RowMatrixXf& queries, Eigen::Index count, int* best, RowMatrixXf& scratch) const;

  /// The reference: every row, one at a time (the tests compare the two).
  static int brute_force(const RowMatrixXf& rows, const RowMatrixXf& queries, Eigen::Index k);

 private:
  const RowMatrixXf& rows_;
  Eigen::VectorXf norms_;  ///< |row|^2
  float max_norm_ = 0.0f;
};

}  // namespace exsynth::search
