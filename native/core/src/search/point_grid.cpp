#include "search/point_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_sort.h>

namespace exsynth::search {
namespace {

constexpr int kBits = 21;  // per axis, relative to the lowest occupied cell
constexpr int kSpan = (1 << kBits) - 1;

}  // namespace

Eigen::Vector3i PointGrid::cell_of(const Eigen::Vector3f& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    // Clamped in float first: a far-away query must not overflow the int.
    const float f = std::floor(p[a] * inv_cell_);
    c[a] = int(std::clamp(f, -1.0e9f, 1.0e9f));
  }
  return c;
}

std::uint64_t PointGrid::key(int x, int y, int z) {
  return std::uint64_t(std::uint32_t(x)) | (std::uint64_t(std::uint32_t(y)) << kBits) |
         (std::uint64_t(std::uint32_t(z)) << (2 * kBits));
}

PointGrid::PointGrid(const std::vector<Eigen::Vector3f>& points, float cell) : cell_(cell), inv_cell_(1.0f / cell) {
  const std::size_t n = points.size();
  if (n == 0) return;
  Eigen::Vector3f lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Keep the key's 21 bits a side: a set wider than 2^21 cells gets larger cells.
  const float extent = (hi - lo).maxCoeff();
  if (!(cell_ > 0) || extent / cell_ > float(kSpan - 2)) {
    cell_ = std::max(extent / float(kSpan - 2), 1e-30f);
    inv_cell_ = 1.0f / cell_;
  }
  lo_ = cell_of(lo);
  hi_ = cell_of(hi);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i c = cell_of(points[i]) - lo_;
    keyed[i] = {key(c.x(), c.y(), c.z()), std::uint32_t(i)};
  }
  // (key, index) pairs are unique, so any sort gives the same order.
  if (n < 8192)
    std::sort(keyed.begin(), keyed.end());
  else
    tbb::parallel_sort(keyed.begin(), keyed.end());
  order_.resize(n);
  sorted_.resize(n);
  std::size_t cells = 0;
  for (std::size_t i = 0; i < n; ++i) {
    order_[i] = keyed[i].second;
    sorted_[i] = points[keyed[i].second];
    cells += i == 0 || keyed[i].first != keyed[i - 1].first;
  }
  occupied_ = cells;
  std::size_t slots = 16;
  while (slots < 2 * cells) slots *= 2;
  table_.assign(slots, Slot{kEmpty, 0, 0});
  mask_ = slots - 1;
  for (std::size_t b = 0; b < n;) {
    std::size_t e = b + 1;
    while (e < n && keyed[e].first == keyed[b].first) ++e;
    std::uint64_t h = (keyed[b].first * 0x9E3779B97F4A7C15ull) >> 17;
    while (table_[h & mask_].key != kEmpty) ++h;
    table_[h & mask_] = {keyed[b].first, std::uint32_t(b), std::uint32_t(e)};
    b = e;
  }
}

const PointGrid::Slot* PointGrid::find(int x, int y, int z) const {
  const std::uint64_t k = key(x - lo_.x(), y - lo_.y(), z - lo_.z());
  for (std::uint64_t h = (k * 0x9E3779B97F4A7C15ull) >> 17;; ++h) {
    const Slot& s = table_[h & mask_];
    if (s.key == k) return &s;
    if (s.key == kEmpty) return nullptr;
  }
}

template <class Fn>
void PointGrid::cells(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, Fn&& fn) const {
  const Eigen::Vector3i a = lo.cwiseMax(lo_), b = hi.cwiseMin(hi_);
  if ((a.array() > b.array()).any()) return;
  const Eigen::Vector3d span = (b - a).cast<double>().array() + 1.0;
  if (span.prod() > double(occupied_)) {
    // More cells in the box than occupied ones (a radius far above the cell):
    // all points, which are in the same (cell) order; the caller filters by distance.
    fn(std::uint32_t(0), std::uint32_t(sorted_.size()));
    return;
  }
  for (int z = a.z(); z <= b.z(); ++z)
    for (int y = a.y(); y <= b.y(); ++y)
      for (int x = a.x(); x <= b.x(); ++x)
        if (const Slot* s = find(x, y, z)) fn(s->begin, s->end);
}

void PointGrid::radius(const Eigen::Vector3f& q, float radius, std::vector<std::pair<std::size_t, float>>& out) const {
  out.clear();
  if (order_.empty()) return;
  const float r2 = radius * radius;
  const Eigen::Vector3f d = Eigen::Vector3f::Constant(radius);
  cells(cell_of(q - d), cell_of(q + d), [&](std::uint32_t b, std::uint32_t e) {
    for (std::uint32_t i = b; i < e; ++i) {
      const float d2 = (sorted_[i] - q).squaredNorm();
      if (d2 <= r2) out.emplace_back(order_[i], d2);
    }
  });
}

bool PointGrid::any_within(const Eigen::Vector3f& q, float radius) const {
  if (order_.empty()) return false;
  const float r2 = radius * radius;
  const Eigen::Vector3f d = Eigen::Vector3f::Constant(radius);
  bool found = false;
  cells(cell_of(q - d), cell_of(q + d), [&](std::uint32_t b, std::uint32_t e) {
    for (std::uint32_t i = b; i < e && !found; ++i) found = (sorted_[i] - q).squaredNorm() <= r2;
  });
  return found;
}

std::size_t PointGrid::nearest(const Eigen::Vector3f& q, float* d2) const {
  if (order_.empty()) {
    if (d2) *d2 = 0;
    return 0;
  }
  const Eigen::Vector3i c = cell_of(q);
  std::size_t best = order_.size();
  float best_d2 = std::numeric_limits<float>::infinity();
  auto visit = [&](int x, int y, int z) {
    const Slot* s = find(x, y, z);
    if (!s) return;
    for (std::uint32_t i = s->begin; i < s->end; ++i) {
      const float dd = (sorted_[i] - q).squaredNorm();
      if (dd < best_d2 || (dd == best_d2 && order_[i] < best)) {
        best_d2 = dd;
        best = order_[i];
      }
    }
  };
  // Rings of cells at Chebyshev distance k from q's cell, starting with the
  // first that reaches the occupied box; after ring k every unvisited point
  // lies outside the box of cells c +- k, so at least that box's face distance away.
  int k = 0;
  for (int a = 0; a < 3; ++a) k = std::max({k, lo_[a] - c[a], c[a] - hi_[a]});
  for (;; ++k) {
    const Eigen::Vector3i lo = c.array() - k, hi = c.array() + k;
    const Eigen::Vector3i a = lo.cwiseMax(lo_), b = hi.cwiseMin(hi_);
    const Eigen::Vector3d span = (b - a).cast<double>().array() + 1.0;
    if (span.x() * span.y() + span.y() * span.z() + span.x() * span.z() > double(occupied_)) {
      // The ring's faces hold more cells than are occupied (a query far from
      // a sparse set): every point once is cheaper, and exact.
      for (std::size_t i = 0; i < sorted_.size(); ++i) {
        const float dd = (sorted_[i] - q).squaredNorm();
        if (dd < best_d2 || (dd == best_d2 && order_[i] < best)) {
          best_d2 = dd;
          best = order_[i];
        }
      }
      break;
    }
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y) {
        const bool inner = z > lo.z() && z < hi.z() && y > lo.y() && y < hi.y();
        if (!inner) {
          for (int x = a.x(); x <= b.x(); ++x) visit(x, y, z);
        } else {
          if (lo.x() >= lo_.x()) visit(lo.x(), y, z);
          if (hi.x() <= hi_.x() && k > 0) visit(hi.x(), y, z);
        }
      }
    if ((lo.array() <= lo_.array()).all() && (hi.array() >= hi_.array()).all()) break;  // saw every cell
    float bound = std::numeric_limits<float>::infinity();
    for (int a2 = 0; a2 < 3; ++a2)
      bound = std::min({bound, q[a2] - float(lo[a2]) * cell_, float(hi[a2] + 1) * cell_ - q[a2]});
    bound = std::max(bound, 0.0f);
    if (best < order_.size() && best_d2 <= bound * bound) break;
  }
  if (d2) *d2 = best_d2;
  return best;
}

}  // namespace exsynth::search
