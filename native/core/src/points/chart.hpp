#pragma once
// Per-patch chart between world space and the exemplar's frame (u, v, h):
// u, v in the reference plane (patch centre at 0), h the height above it.
// A plane is a translation; a curved target maps (u, v) to the foot point
// of c + s (u T + v B) on the target and h along its normal there (s: target
// units per exemplar unit), with the tangent frame carried from the centre.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "points/point_surface.hpp"

namespace exsynth::points {

struct LocalPoint {
  Eigen::Vector3f p, n;
};

class Chart {
 public:
  virtual ~Chart() = default;
  /// False when the point does not belong to this chart (the far side of a thin part).
  virtual bool to_local(const Eigen::Vector3f& p, const Eigen::Vector3f& n, LocalPoint& out) const = 0;
  virtual LocalPoint to_world(const LocalPoint& local) const = 0;
  /// World centre and a world radius that holds the chart's patch.
  virtual Eigen::Vector3f centre() const = 0;
  /// World units per exemplar unit.
  virtual float scale() const = 0;
};

class PlaneChart final : public Chart {
 public:
  PlaneChart(float cx, float cy) : c_(cx, cy, 0.0f) {}
  bool to_local(const Eigen::Vector3f& p, const Eigen::Vector3f& n, LocalPoint& out) const override {
    out = {p - c_, n};
    return true;
  }
  LocalPoint to_world(const LocalPoint& l) const override { return {l.p + c_, l.n}; }
  Eigen::Vector3f centre() const override { return c_; }
  float scale() const override { return 1.0f; }

 private:
  Eigen::Vector3f c_;
};

/// The target surface a curved synthesis follows: its samples (a point-set
/// surface) and the direction field at each sample.
struct TargetSurface {
  std::vector<Eigen::Vector3f> positions, normals, field;
  std::unique_ptr<PointSurface> surface;
  /// Foot point and unit normal of p on the target (nearest sample's tangent
  /// plane when p is beyond the surface's reach).
  void foot(const Eigen::Vector3f& p, Eigen::Vector3f& base, Eigen::Vector3f& normal) const;
};

class SurfaceChart final : public Chart {
 public:
  /// Centre c on the target, frame from the field at c; scale: target units per exemplar unit.
  SurfaceChart(const TargetSurface& target, const Eigen::Vector3f& c, float scale, float max_height);
  bool to_local(const Eigen::Vector3f& p, const Eigen::Vector3f& n, LocalPoint& out) const override;
  LocalPoint to_world(const LocalPoint& l) const override;
  Eigen::Vector3f centre() const override { return c_; }
  float scale() const override { return scale_; }

 private:
  void frame_at(const Eigen::Vector3f& normal, Eigen::Vector3f& t, Eigen::Vector3f& b) const;
  const TargetSurface& target_;
  Eigen::Vector3f c_, t_, b_, n_;
  float scale_, max_height_;
};

}  // namespace exsynth::points
