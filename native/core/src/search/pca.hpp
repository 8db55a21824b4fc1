#pragma once
// Principal component analysis of neighbourhood vectors: the search compares
// candidates in the space of the leading components, which keeps most of the
// variance in a fraction of the dimensions (Kopf et al. keep 95 %).
#include <Eigen/Core>

namespace exsynth::search {

using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct Pca {
  Eigen::RowVectorXf mean;  ///< 1 x D
  Eigen::MatrixXf basis;    ///< D x d, columns = principal directions, by decreasing variance
  double kept_variance = 1.0;

  int dims() const { return int(basis.cols()); }
  /// Rows of X (n x D) -> coefficients (n x d).
  RowMatrixXf project(const RowMatrixXf& x) const;
};

/// Fits on the rows of `samples` (n x D): keeps the fewest leading components
/// whose variance reaches `variance` of the total, at most `max_dims`, at
/// least 1. Deterministic: large sample sets are strided, not randomly subsampled.
Pca fit_pca(const RowMatrixXf& samples, double variance, int max_dims);

}  // namespace exsynth::search
