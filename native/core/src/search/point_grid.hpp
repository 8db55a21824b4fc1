#pragma once
// A hashed uniform grid over 3-D points (float) for fixed-radius queries:
// cells of a given side, the points sorted by cell (one O(n log n) sort, in
// parallel), cells found through an open-addressing table. Built per patch
// of the point texture twice (old and new points) and queried there by
// hundreds of thousands of projections with one radius (the point-set
// surface's cut-off): against the nanoflann tree it replaced, a radius query
// visits at most 4 x 4 x 4 cells with no descent, and the build is a sort
// instead of a serial tree split (measured in docs/benchmarks.md, issue 9).
// The points are copied in cell order (cache-friendly distance checks);
// results carry the original indices.
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace exsynth::search {

class PointGrid {
 public:
  /// cell: the grid's side; queries of radius about `cell` visit 2-3 cells a side.
  PointGrid(const std::vector<Eigen::Vector3f>& points, float cell);
  PointGrid(const PointGrid&) = delete;
  PointGrid& operator=(const PointGrid&) = delete;

  std::size_t size() const { return order_.size(); }
  float cell() const { return cell_; }

  /// Indices and squared distances of the points within `radius` of q
  /// (d2 <= radius^2), grouped by cell (z, y, x ascending), each cell's in
  /// index order: a fixed order, whatever the thread count.
  void radius(const Eigen::Vector3f& q, float radius, std::vector<std::pair<std::size_t, float>>& out) const;
  /// True when some point is within `radius` of q (d2 <= radius^2).
  bool any_within(const Eigen::Vector3f& q, float radius) const;
  /// Nearest point's index (size() when empty; the lowest index among equal
  /// distances) and its squared distance.
  std::size_t nearest(const Eigen::Vector3f& q, float* d2 = nullptr) const;

 private:
  struct Slot {
    std::uint64_t key;
    std::uint32_t begin, end;  ///< range in order_ / sorted_
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const;
  static std::uint64_t key(int x, int y, int z);
  const Slot* find(int x, int y, int z) const;
  // Calls fn(begin, end) for every occupied cell in [lo, hi] (z, y, x order).
  template <class Fn>
  void cells(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, Fn&& fn) const;

  float cell_, inv_cell_;
  Eigen::Vector3i lo_ = Eigen::Vector3i::Zero(), hi_ = Eigen::Vector3i::Constant(-1);  ///< occupied cells' box
  std::vector<std::uint32_t> order_;       ///< point indices by (cell, index)
  std::vector<Eigen::Vector3f> sorted_;    ///< positions in that order
  std::vector<Slot> table_;                ///< power-of-two open-addressing table
  std::uint64_t mask_ = 0;
  std::size_t occupied_ = 0;  ///< occupied cells
};

}  // namespace exsynth::search
