#pragma once
// A 3-D thin-plate (biharmonic) spline f(x) = A x + b + sum_i w_i |x - c_i|
// mapping source centres c_i to targets y_i exactly (up to a small
// regularisation), with its Jacobian for transforming normals: a normal n
// becomes J^-T n (normalised), which keeps it perpendicular to the warped surface.
#include <vector>

#include <Eigen/Core>

namespace exsynth::points {

class ThinPlateSpline {
 public:
  ThinPlateSpline() = default;
  /// Throws InvalidInput when there are fewer than 4 pairs or the system is singular.
  ThinPlateSpline(const std::vector<Eigen::Vector3d>& sources, const std::vector<Eigen::Vector3d>& targets,
                  double regularization = 0.0);

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const;
  Eigen::Matrix3d jacobian(const Eigen::Vector3d& x) const;
  /// J^-T n normalised (n itself where J is singular).
  Eigen::Vector3d transform_normal(const Eigen::Vector3d& x, const Eigen::Vector3d& n) const;
  /// f(x) and the transformed normal J^-T n together, over the centres held
  /// column by column in float (Eigen's vectorised array ops; apply +
  /// jacobian one centre at a time took 18 % of a synthesis). apply and
  /// jacobian above (double) are its reference: they agree to ~1e-6.
  Eigen::Vector3d apply(const Eigen::Vector3d& x, const Eigen::Vector3d& n, Eigen::Vector3d& n_out) const;
  bool empty() const { return centres_.empty(); }

 private:
  std::vector<Eigen::Vector3d> centres_;
  std::vector<Eigen::Vector3d> weights_;  ///< one per centre
  Eigen::Matrix<float, Eigen::Dynamic, 3> centre_columns_, weight_columns_;  ///< the same, n x 3, in float
  Eigen::Matrix3d linear_ = Eigen::Matrix3d::Identity();  ///< A
  Eigen::Vector3d offset_ = Eigen::Vector3d::Zero();      ///< b
};

}  // namespace exsynth::points
