#pragma once
// Principal component analysis of neighbourhood vectors: the search compares
// candidates in the space of the leading components, which keeps most of the
// variance in a fraction of the dimensions (Kopf et al. keep 95 %).
#include <Eigen/Core>

#include "exsynth/exec_context.hpp"

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
/// Up to 512 dimensions the covariance is decomposed exactly; above (many
/// channels: 100 channels x 8 x 8 = 6400), a seeded randomized subspace
/// iteration finds the leading `max_dims` components in O(n D max_dims)
/// instead of O(D^3). `progress` (optional) is checked for cancellation.
Pca fit_pca(const RowMatrixXf& samples, double variance, int max_dims, const StageProgress* progress = nullptr);

}  // namespace exsynth::search
