#include "search/pca.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>

#include "exsynth/rng.hpp"

namespace exsynth::search {

RowMatrixXf Pca::project(const RowMatrixXf& x) const {
  return (x.rowwise() - mean) * basis;
}

namespace {

constexpr Eigen::Index kExactMaxDims = 512;

// Leading eigenpairs (decreasing) of cov = A^T A / (rows - 1) for a wide A
// (D > kExactMaxDims): randomized subspace iteration (Halko, Martinsson &
// Tropp 2011) with a fixed-seed test matrix, 8 oversampling columns and 4
// power iterations, then the exact eigen-decomposition of the small
// projected matrix.
void leading_eigenpairs(const Eigen::MatrixXd& a, int wanted, Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                        const StageProgress* progress) {
  const Eigen::Index D = a.cols(), l = std::min<Eigen::Index>(wanted + 8, std::min(a.rows(), D));
  Eigen::MatrixXd q(D, l);
  for (Eigen::Index j = 0; j < l; ++j)
    for (Eigen::Index i = 0; i < D; ++i) q(i, j) = IndexRng(0x9CA, std::uint64_t(i), std::uint64_t(j)).uniform() - 0.5;
  for (int it = 0; it < 5; ++it) {
    if (progress) progress->check();
    const Eigen::MatrixXd y = a.transpose() * (a * q);
    q = Eigen::HouseholderQR<Eigen::MatrixXd>(y).householderQ() * Eigen::MatrixXd::Identity(D, l);
  }
  const Eigen::MatrixXd aq = a * q;
  const Eigen::MatrixXd small = (aq.transpose() * aq) / double(std::max<Eigen::Index>(1, a.rows() - 1));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(small);
  values = eig.eigenvalues().reverse().cwiseMax(0.0);
  vectors = q * eig.eigenvectors().rowwise().reverse();
}

}  // namespace

Pca fit_pca(const RowMatrixXf& samples, double variance, int max_dims, const StageProgress* progress) {
  Pca pca;
  const Eigen::Index n = samples.rows(), D = samples.cols();
  pca.mean = samples.colwise().mean();
  // Covariance in double (the eigen-decomposition of a near-singular float
  // covariance loses the small components' order) from at most kMaxRows
  // evenly strided rows: the leading components of a few thousand
  // neighbourhoods are those of all of them, at a fraction of the cost.
  // Wide samples keep the strided copy under ~4 M values.
  const Eigen::Index kMaxRows = std::max<Eigen::Index>(512, std::min<Eigen::Index>(4096, (Eigen::Index(1) << 22) / std::max<Eigen::Index>(D, 1)));
  const Eigen::Index step = (n + kMaxRows - 1) / kMaxRows, rows = (n + step - 1) / step;
  Eigen::MatrixXd centred(rows, D);
  for (Eigen::Index r = 0; r < rows; ++r) centred.row(r) = (samples.row(r * step) - pca.mean).cast<double>();
  if (progress) progress->check();
  const int cap = std::max(1, std::min<int>(max_dims, int(D)));
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  double total = 0.0;
  if (D <= kExactMaxDims) {
    const Eigen::MatrixXd cov = (centred.transpose() * centred) / double(std::max<Eigen::Index>(1, rows - 1));
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
    values = eig.eigenvalues().reverse().cwiseMax(0.0);  // decreasing
    vectors = eig.eigenvectors().rowwise().reverse();
    total = values.sum();
  } else {
    leading_eigenpairs(centred, cap, values, vectors, progress);
    total = centred.squaredNorm() / double(std::max<Eigen::Index>(1, rows - 1));  // trace of the covariance
  }
  int d = 0;
  double kept = 0.0;
  const int avail = std::min<int>(cap, int(values.size()));
  while (d < avail && (d == 0 || total <= 0 || kept < variance * total)) kept += values[d++];
  pca.kept_variance = total > 0 ? std::min(1.0, kept / total) : 1.0;
  pca.basis = vectors.leftCols(d).cast<float>();
  return pca;
}

}  // namespace exsynth::search
