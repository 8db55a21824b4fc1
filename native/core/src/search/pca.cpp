#include "search/pca.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace exsynth::search {

RowMatrixXf Pca::project(const RowMatrixXf& x) const {
  return (x.rowwise() - mean) * basis;
}

Pca fit_pca(const RowMatrixXf& samples, double variance, int max_dims) {
  Pca pca;
  const Eigen::Index n = samples.rows(), D = samples.cols();
  pca.mean = samples.colwise().mean();
  // Covariance in double (the eigen-decomposition of a near-singular float
  // covariance loses the small components' order) from at most kMaxRows
  // evenly strided rows: the leading components of a few thousand
  // neighbourhoods are those of all of them, at a fraction of the cost.
  constexpr Eigen::Index kMaxRows = 4096;
  const Eigen::Index step = (n + kMaxRows - 1) / kMaxRows, rows = (n + step - 1) / step;
  Eigen::MatrixXd centred(rows, D);
  for (Eigen::Index r = 0; r < rows; ++r) centred.row(r) = (samples.row(r * step) - pca.mean).cast<double>();
  const Eigen::MatrixXd cov = (centred.transpose() * centred) / double(std::max<Eigen::Index>(1, rows - 1));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  const Eigen::VectorXd values = eig.eigenvalues().reverse().cwiseMax(0.0);  // decreasing
  const double total = values.sum();
  int d = 0;
  double kept = 0.0;
  const int cap = std::max(1, std::min<int>(max_dims, int(D)));
  while (d < cap && (d == 0 || total <= 0 || kept < variance * total)) kept += values[d++];
  pca.kept_variance = total > 0 ? kept / total : 1.0;
  pca.basis = eig.eigenvectors().rowwise().reverse().leftCols(d).cast<float>();
  return pca;
}

}  // namespace exsynth::search
