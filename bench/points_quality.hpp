// How much a synthesized point texture looks like its exemplar, by four
// distributions compared over the exemplar's box and the output's inner
// region (the border strip left out): the normal jump between neighbours on
// the same sheet (a seam or a torn patch shows as a heavy tail: its 99th
// percentile, as a ratio to the exemplar's), and the Wasserstein-1 distances between the
// surface variations (shape), the heights (z, over the exemplar's height
// range) and the nearest-neighbour distances (over the spacing: holes and
// doubled sheets). 1 and 0 are "like the exemplar"; a second sampling of the
// exemplar (another seed) gives the floor.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "exsynth/points.hpp"
#include "points/point_surface.hpp"
#include "search/point_index.hpp"

namespace exsynth_bench {

struct PointQuality {
  double seam_p99 = 0;    ///< p99 of 1 - n.n' over neighbours within 1.5 spacings, n.n' > 0
  double sigma_w1 = 0;    ///< W1 of the surface variations
  double height_w1 = 0;   ///< W1 of the heights / the exemplar's height range
  double spacing_w1 = 0;  ///< W1 of the nearest-neighbour distances / the spacing
};

struct PointStats {
  std::vector<float> jump, sigma, height, nearest;
};

// The four samples over the points inside [lo, hi]^2 (x, y) of `pts`.
inline PointStats point_stats(const exsynth::OrientedPoints& pts, double lo, double hi, double spacing) {
  const exsynth::search::PointIndex index(pts.positions);
  const std::vector<float> sigma = exsynth::points::surface_variation(pts.positions, index, 12);
  PointStats s;
  std::vector<std::pair<std::size_t, float>> near;
  std::size_t idx[2];
  float d2[2];
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3f& p = pts.positions[i];
    if (p.x() < lo || p.x() > hi || p.y() < lo || p.y() > hi) continue;
    s.sigma.push_back(sigma[i]);
    s.height.push_back(p.z());
    index.knn(p, 2, idx, d2);
    s.nearest.push_back(std::sqrt(d2[1]));
    index.radius(p, float(1.5 * spacing), near);
    for (const auto& [j, dist2] : near)
      if (j != i && pts.normals[i].dot(pts.normals[j]) > 0.0f)  // the same sheet, not the next ring's
        s.jump.push_back(1.0f - pts.normals[i].dot(pts.normals[j]));
  }
  return s;
}

// Wasserstein-1 between two 1-D samples, by 1000 quantiles.
inline double w1(std::vector<float> a, std::vector<float> b) {
  if (a.empty() || b.empty()) return INFINITY;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const int q = 1000;
  double sum = 0;
  for (int k = 0; k < q; ++k) {
    const double t = (k + 0.5) / q;
    sum += std::abs(double(a[std::size_t(t * double(a.size()))]) - double(b[std::size_t(t * double(b.size()))]));
  }
  return sum / q;
}

inline double p99(std::vector<float> v) {
  if (v.empty()) return INFINITY;
  std::sort(v.begin(), v.end());
  return double(v[v.size() * 99 / 100]);
}

/// `out` grown over [0, side]^2 from `ex` (box [0, 1]^2), with the overlap
/// strip `border` left out of the output's sample.
inline PointQuality point_quality(const exsynth::PointExemplar& ex, const exsynth::OrientedPoints& out, double side,
                                  double border, double spacing) {
  const PointStats e = point_stats(ex.points, 0.0, 1.0, spacing), o = point_stats(out, border, side - border, spacing);
  const auto [zlo, zhi] = std::minmax_element(e.height.begin(), e.height.end());
  PointQuality q;
  q.seam_p99 = p99(o.jump) / std::max(1e-9, p99(e.jump));
  q.sigma_w1 = w1(e.sigma, o.sigma);
  q.height_w1 = w1(e.height, o.height) / std::max(1e-9, double(*zhi - *zlo));
  q.spacing_w1 = w1(e.nearest, o.nearest) / spacing;
  return q;
}

}  // namespace exsynth_bench
