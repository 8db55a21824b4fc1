#include <Eigen/Geometry>

#include "points/point_surface.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace exsynth::points {

PointSurface::PointSurface(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3f>& normals,
                           float h)
    : positions_(positions), normals_(normals), h_(h), grid_(positions, kCutoff * h) {}

SurfaceSample PointSurface::evaluate(const Eigen::Vector3f& x) const {
  if (positions_.empty()) return {};
  thread_local std::vector<std::pair<std::size_t, float>> near;
  grid_.radius(x, kCutoff * h_, near);  // weights beyond 2.5 h are below 0.2 %
  return weighted(x, near);
}

SurfaceSample PointSurface::weighted(const Eigen::Vector3f& x, const std::vector<std::pair<std::size_t, float>>& near) const {
  SurfaceSample s;
  if (near.empty()) return s;
  const float inv_h2 = 1.0f / (h_ * h_);
  // Sums relative to x in float: the neighbours are within 3 h, so there is
  // no cancellation to fear, and the radius query returns them in a fixed order.
  float wsum = 0;
  Eigen::Vector3f af = Eigen::Vector3f::Zero(), nf = Eigen::Vector3f::Zero();
  for (const auto& [i, d2] : near) {
    const float w = std::exp(-d2 * inv_h2);
    wsum += w;
    af += w * (positions_[i] - x);
    nf += w * normals_[i];
  }
  Eigen::Vector3d a = af.cast<double>() / double(wsum) + x.cast<double>(), n = nf.cast<double>();
  if (!(wsum > 0) || n.norm() < 1e-12) return s;
  n.normalize();
  s.mean = a.cast<float>();
  s.normal = n.cast<float>();
  s.f = float(n.dot(x.cast<double>() - a));
  s.valid = true;
  return s;
}

SurfaceSample PointSurface::evaluate(const Eigen::Vector3f& x, Cursor& c) const {
  // The points within the cut-off of x are all within cut-off + slack of the
  // centre while x stays within the slack; they are filtered exactly (the
  // same set as a fresh query). Projection steps are short, so most
  // projections query the tree once instead of 4-8 times (the queries were
  // 40 % of a synthesis).
  if (positions_.empty()) return {};
  const float slack = 0.5f * h_, cutoff2 = (kCutoff * h_) * (kCutoff * h_);
  if (!((x - c.centre).squaredNorm() <= slack * slack)) {
    c.centre = x;
    grid_.radius(c.centre, kCutoff * h_ + slack, c.wide);
  }
  c.near.clear();
  for (const auto& [i, unused] : c.wide) {
    const float d2 = (positions_[i] - x).squaredNorm();
    if (d2 < cutoff2) c.near.emplace_back(i, d2);
  }
  return weighted(x, c.near);
}

Projection PointSurface::project(const Eigen::Vector3f& x0, int iterations, float tol, Cursor* cursor) const {
  Projection p;
  if (positions_.empty()) return p;
  thread_local Cursor own;
  Cursor& c = cursor ? *cursor : own;
  if (!cursor) c.centre = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  auto sample = [&](const Eigen::Vector3f& x) { return evaluate(x, c); };
  Eigen::Vector3f x = x0;
  for (int it = 0; it < iterations; ++it) {
    const SurfaceSample s = sample(x);
    if (!s.valid) return p;
    const Eigen::Vector3f step = s.f * s.normal;
    x -= step;
    p.point = x;
    p.normal = s.normal;
    if (step.norm() < tol) {
      p.converged = true;
      break;
    }
  }
  if (!p.converged && iterations > 0) {
    // Accept a last step that is small next to the bandwidth.
    const SurfaceSample s = sample(x);
    p.converged = s.valid && std::abs(s.f) < 0.05f * h_;  // within 5 % of the bandwidth: on the surface for blending
    if (s.valid) p.normal = s.normal;
  }
  return p;
}

std::size_t PointSurface::nearest(const Eigen::Vector3f& x, float* d2) const {
  return grid_.nearest(x, d2);
}

std::vector<float> surface_variation(const std::vector<Eigen::Vector3f>& positions, const search::PointIndex& index,
                                     int k, const StageProgress* progress) {
  std::vector<float> out(positions.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 1024), [&](const auto& r) {
    if (progress) progress->check();
    std::vector<std::size_t> idx(k);
    std::vector<float> d2(k);
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const std::size_t m = index.knn(positions[i], std::size_t(k), idx.data(), d2.data());
      if (m < 3) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < m; ++j) mean += positions[idx[j]].cast<double>();
      mean /= double(m);
      Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
      for (std::size_t j = 0; j < m; ++j) {
        const Eigen::Vector3d d = positions[idx[j]].cast<double>() - mean;
        c += d * d.transpose();
      }
      const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c, Eigen::EigenvaluesOnly).eigenvalues();
      const double t = l.sum();
      out[i] = t > 0 ? float(std::max(0.0, l[0]) / t) : 0.0f;
    }
  });
  return out;
}

double mean_spacing(const std::vector<Eigen::Vector3f>& positions, const search::PointIndex& index,
                    const StageProgress* progress) {
  if (positions.size() < 2) return 0.0;
  // Per point, then summed in index order: the same value whatever the thread count.
  std::vector<double> nn(positions.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4096), [&](const auto& r) {
    if (progress) progress->check();
    std::size_t idx[2];
    float d2[2];
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      if (index.knn(positions[i], 2, idx, d2) == 2) nn[i] = std::sqrt(double(d2[1]));
  });
  double sum = 0;
  for (double d : nn) sum += d;
  return sum / double(positions.size());
}

}  // namespace exsynth::points
