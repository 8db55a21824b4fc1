#include "points/chart.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace exsynth::points {

void TargetSurface::foot(const Eigen::Vector3f& p, Eigen::Vector3f& base, Eigen::Vector3f& normal) const {
  const Projection pr = surface->project(p, 6, 1e-6f);
  if (pr.converged) {
    base = pr.point;
    normal = pr.normal;
    return;
  }
  const std::size_t i = surface->nearest(p);
  normal = normals[i];
  base = p - (p - positions[i]).dot(normal) * normal;
}

SurfaceChart::SurfaceChart(const TargetSurface& target, const Eigen::Vector3f& c, float scale, float max_height)
    : target_(target), scale_(scale), max_height_(max_height) {
  target.foot(c, c_, n_);
  const std::size_t i = target.surface->nearest(c_);
  Eigen::Vector3f f = target.field[i];
  f -= f.dot(n_) * n_;
  if (f.norm() < 1e-6f) {  // no usable field here: any tangent, deterministically
    f = std::abs(n_.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
    f -= f.dot(n_) * n_;
  }
  t_ = f.normalized();
  b_ = n_.cross(t_);
}

void SurfaceChart::frame_at(const Eigen::Vector3f& normal, Eigen::Vector3f& t, Eigen::Vector3f& b) const {
  Eigen::Vector3f f = t_ - t_.dot(normal) * normal;
  if (f.norm() < 1e-6f) f = b_.cross(normal);
  t = f.normalized();
  b = normal.cross(t);
}

bool SurfaceChart::to_local(const Eigen::Vector3f& p, const Eigen::Vector3f& n, LocalPoint& out) const {
  Eigen::Vector3f base, normal;
  target_.foot(p, base, normal);
  if (normal.dot(n_) < 0.3f) return false;  // the other side of a thin part, or folded too far
  const float h = (p - base).dot(normal) / scale_;
  if (std::abs(h) > max_height_) return false;
  Eigen::Vector3f t, b;
  frame_at(normal, t, b);
  const Eigen::Vector3f d = base - c_;
  out.p = Eigen::Vector3f(d.dot(t_) / scale_, d.dot(b_) / scale_, h);
  out.n = Eigen::Vector3f(n.dot(t), n.dot(b), n.dot(normal)).normalized();
  return true;
}

LocalPoint SurfaceChart::to_world(const LocalPoint& l) const {
  Eigen::Vector3f base, normal;
  target_.foot(c_ + scale_ * (l.p.x() * t_ + l.p.y() * b_), base, normal);
  Eigen::Vector3f t, b;
  frame_at(normal, t, b);
  return {base + scale_ * l.p.z() * normal, (l.n.x() * t + l.n.y() * b + l.n.z() * normal).normalized()};
}

}  // namespace exsynth::points
