#pragma once
// Adamson & Alexa's point-set surface: at x, a(x) is the Gaussian-weighted
// mean of the points near x and n(x) the normalised weighted mean of their
// normals; the surface is f(x) = n(x) . (x - a(x)) = 0. Projection iterates
// x <- x - f(x) n(x) (their quasi-orthogonal projection). Built once over a
// point set, queried from many threads (queries are const).
#include <cstddef>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "search/point_grid.hpp"
#include "search/point_index.hpp"

namespace exsynth::points {

struct SurfaceSample {
  float f = 0;                              ///< signed distance estimate (positive along the normals)
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  ///< n(x), unit; the field's gradient direction
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();    ///< a(x)
  bool valid = false;                       ///< false: no point within the cut-off (2.5 h)
};

struct Projection {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  bool converged = false;
};

class PointSurface {
 public:
  /// h: Gaussian width (weights exp(-d^2 / h^2), cut off at 2.5 h).
  PointSurface(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3f>& normals, float h);

  SurfaceSample evaluate(const Eigen::Vector3f& x) const;
  /// The neighbours of a moving query point: one radius query of the cut-off
  /// plus a slack serves every evaluation within the slack of its centre.
  struct Cursor {
    Eigen::Vector3f centre = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
    std::vector<std::pair<std::size_t, float>> wide, near;
  };
  /// As evaluate(x), through the cursor (same neighbours, same result up to
  /// the order of the sums).
  SurfaceSample evaluate(const Eigen::Vector3f& x, Cursor& cursor) const;
  /// At most `iterations` steps; converged when a step is below tol. Pass a
  /// cursor to share its query across calls from nearby points.
  Projection project(const Eigen::Vector3f& x, int iterations = 8, float tol = 1e-5f, Cursor* cursor = nullptr) const;
  /// Nearest point's index (size() when empty) and squared distance.
  std::size_t nearest(const Eigen::Vector3f& x, float* d2 = nullptr) const;
  /// True when some point is within r of x.
  bool any_within(const Eigen::Vector3f& x, float r) const { return grid_.any_within(x, r); }
  float bandwidth() const { return h_; }
  std::size_t size() const { return positions_.size(); }

 private:
  static constexpr float kCutoff = 2.5f;  ///< neighbours within 2.5 h (weights below 0.2 % beyond)
  SurfaceSample weighted(const Eigen::Vector3f& x, const std::vector<std::pair<std::size_t, float>>& near) const;

  const std::vector<Eigen::Vector3f>& positions_;
  const std::vector<Eigen::Vector3f>& normals_;
  float h_;
  search::PointGrid grid_;  ///< cells of the cut-off radius (2.5 h)
};

/// Surface variation sigma = l0 / (l0 + l1 + l2) of the k nearest points'
/// covariance (Pauly et al.), per point; 0 on a plane, 1/3 isotropic.
std::vector<float> surface_variation(const std::vector<Eigen::Vector3f>& positions, const search::PointIndex& index,
                                     int k = 12, const StageProgress* progress = nullptr);

/// Mean distance from each point to its nearest other point.
/// `progress`, when given, is checked for a cancel per chunk of points.
double mean_spacing(const std::vector<Eigen::Vector3f>& positions, const search::PointIndex& index,
                    const StageProgress* progress = nullptr);

}  // namespace exsynth::points
