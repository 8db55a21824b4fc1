#include <Eigen/Geometry>

#include "points/tps.hpp"

#include <cmath>

#include <Eigen/LU>

#include "exsynth/errors.hpp"

namespace exsynth::points {

ThinPlateSpline::ThinPlateSpline(const std::vector<Eigen::Vector3d>& sources,
                                 const std::vector<Eigen::Vector3d>& targets, double regularization) {
  const int n = int(sources.size());
  if (n < 4 || targets.size() != sources.size())
    throw InvalidInput("a thin-plate spline needs at least 4 source/target pairs of equal count");
  // [K + lambda I, P; P^T, 0] [w; a] = [y; 0], P = [x 1].
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 4, n + 4);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + 4, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) m(i, j) = (sources[i] - sources[j]).norm();
    m(i, i) += regularization;
    for (int d = 0; d < 3; ++d) m(i, n + d) = m(n + d, i) = sources[i][d];
    m(i, n + 3) = m(n + 3, i) = 1.0;
    rhs.row(i) = targets[i].transpose();
  }
  // Partial pivoting is enough for this saddle-point system when the
  // sources are not degenerate; a degenerate set shows as a bad residual.
  const Eigen::MatrixXd sol = Eigen::PartialPivLU<Eigen::MatrixXd>(m).solve(rhs);
  if (!sol.allFinite() || (m * sol - rhs).norm() > 1e-6 * (1.0 + rhs.norm()))
    throw InvalidInput("thin-plate spline: the source points are degenerate (all on one plane or repeated)");
  centres_ = sources;
  weights_.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) weights_[std::size_t(i)] = sol.row(i).transpose();
  centre_columns_.resize(n, 3);
  weight_columns_ = sol.topRows(n).cast<float>();
  for (int i = 0; i < n; ++i) centre_columns_.row(i) = sources[std::size_t(i)].transpose().cast<float>();
  linear_ = sol.block(n, 0, 3, 3).transpose();
  offset_ = sol.row(n + 3).transpose();
}

Eigen::Vector3d ThinPlateSpline::apply(const Eigen::Vector3d& x) const {
  Eigen::Vector3d y = linear_ * x + offset_;
  for (std::size_t i = 0; i < centres_.size(); ++i) y += weights_[i] * (x - centres_[i]).norm();
  return y;
}

Eigen::Matrix3d ThinPlateSpline::jacobian(const Eigen::Vector3d& x) const {
  Eigen::Matrix3d j = linear_;
  for (std::size_t i = 0; i < centres_.size(); ++i) {
    const Eigen::Vector3d d = x - centres_[i];
    const double r = d.norm();
    if (r > 1e-12) j += weights_[i] * (d / r).transpose();
  }
  return j;
}

namespace {

// J^-T n normalised; n itself where J is singular.
Eigen::Vector3d normal_through(const Eigen::Matrix3d& j, const Eigen::Vector3d& n) {
  const double det = j.determinant();
  if (!(std::abs(det) > 1e-12)) return n;
  const Eigen::Vector3d m = j.inverse().transpose() * n;
  const double len = m.norm();
  return len > 0 ? Eigen::Vector3d(m / len) : n;
}

}  // namespace

Eigen::Vector3d ThinPlateSpline::transform_normal(const Eigen::Vector3d& x, const Eigen::Vector3d& n) const {
  return normal_through(jacobian(x), n);
}

Eigen::Vector3d ThinPlateSpline::apply(const Eigen::Vector3d& x, const Eigen::Vector3d& n, Eigen::Vector3d& n_out) const {
  // The radial sums in float: four centres per SSE op instead of two, and
  // the float sqrt (the TPS was 12 % of a synthesis' CPU in double). Patch
  // coordinates are O(1) and the sums of ~170 terms lose ~1e-6 relative,
  // far below a point spacing (tested against the double reference).
  thread_local Eigen::ArrayXf d[3], r, inv, w_inv;  // no allocation per point
  const Eigen::Vector3f xf = x.cast<float>();
  for (int a = 0; a < 3; ++a) d[a] = xf[a] - centre_columns_.col(a).array();
  r = (d[0].square() + d[1].square() + d[2].square()).sqrt();
  inv = (r > 1e-12f).select(r.inverse(), 0.0f);  // a centre at x adds nothing to J (as in jacobian())
  Eigen::Vector3d y = linear_ * x + offset_;
  Eigen::Matrix3d j = linear_;
  for (int a = 0; a < 3; ++a) {
    const auto w = weight_columns_.col(a).array();
    y[a] += double((w * r).sum());
    w_inv = w * inv;
    for (int b = 0; b < 3; ++b) j(a, b) += double((w_inv * d[b]).sum());
  }
  n_out = normal_through(j, n);
  return y;
}

}  // namespace exsynth::points
