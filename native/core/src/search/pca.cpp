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
  // Covariance in double: the eigen-decomposition of a near-singular float
  // covariance loses the small components' order.
  const Eigen::MatrixXd centred = (samples.rowwise() - pca.mean).cast<double>();
  const Eigen::MatrixXd cov = (centred.transpose() * centred) / double(std::max<Eigen::Index>(1, n - 1));
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
