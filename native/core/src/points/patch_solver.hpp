#pragma once
// The per-patch work of the synthesis, built once per exemplar: the
// exemplar's point-set surface, its signed distance field on one grid (so
// D(T_in) for every candidate position is a window of it), its surface
// variation, and a column index of its points. place() grows the output by
// one patch through a chart: metric search, TPS warp, blend.
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "exsynth/points.hpp"
#include "points/chart.hpp"
#include "points/output_store.hpp"
#include "points/point_surface.hpp"

namespace exsynth::points {

class PatchSolver {
 public:
  /// Throws InvalidInput when no candidate patch fits in the exemplar.
  PatchSolver(const PointExemplar& exemplar, const PointTextureOptions& opt, ExecContext* ctx);

  /// Adds one patch at `chart` (patch_id seeds its random pick).
  void place(const Chart& chart, std::uint64_t patch_id, OutputStore& out);

  double spacing() const { return spacing_; }
  double patch() const { return patch_; }
  double overlap() const { return extra_; }
  float z_min() const { return z0_; }
  float z_max() const { return z0_ + float(nz_) * float(cell_); }
  /// World radius (exemplar units) around a chart centre that holds a patch and its margin.
  float gather_radius() const;
  std::size_t candidates() const { return candidates_.size(); }
  const PointTextureResult& stats() const { return stats_; }
  PointTextureResult& stats() { return stats_; }

  /// The metric's grid: signed distance and normal of `surface` at the cell
  /// centres `cells` (x, y, z each); f truncated to +-band, invalid -> +band.
  /// `progress`, when given, is checked for a cancel per chunk of cells.
  static void sample_field(const PointSurface& surface, const std::vector<Eigen::Vector3f>& cells, float band,
                           std::vector<float>& f, std::vector<Eigen::Vector3f>& n,
                           const StageProgress* progress = nullptr);

 private:
  struct Cell {
    std::uint32_t rel;  ///< offset into the exemplar grid relative to the candidate's corner
    float f;
    Eigen::Vector3f n;
  };
  std::size_t choose(const std::vector<Cell>& overlap, std::uint64_t patch_id);
  std::vector<LocalPoint> source_points(std::size_t candidate, std::vector<float>& sigma) const;
  void warp(std::vector<LocalPoint>& src, const std::vector<float>& src_sigma, const std::vector<LocalPoint>& old,
            const std::vector<float>& old_sigma, const std::vector<char>& covered);
  void blend(std::vector<LocalPoint>& fresh, std::vector<char>& keep_new, std::vector<LocalPoint>& old,
             std::vector<char>& old_moved, std::vector<char>& old_dead, const std::vector<char>& covered,
             const PointSurface& old_surface);
  float ramp(const Eigen::Vector3f& p) const;
  int column(const Eigen::Vector3f& p) const;  ///< footprint column of a local point, -1 outside

  PointTextureOptions opt_;
  ExecContext* ctx_;
  const PointExemplar& ex_;
  std::vector<float> sigma_;
  double spacing_ = 0, patch_ = 0, extra_ = 0, margin_ = 0, cell_ = 0, band_ = 0, h_ = 0;
  int res_ = 0, nz_ = 0, gx_ = 0, gy_ = 0;
  float z0_ = 0;
  Eigen::Vector2d origin_;                 ///< exemplar grid corner (x, y)
  std::vector<float> ex_f_;                ///< exemplar field, index (j gx + i) nz + k
  std::vector<Eigen::Vector3f> ex_n_;
  std::vector<std::pair<int, int>> candidates_;  ///< footprint corner cells (i, j)
  std::vector<std::vector<std::uint32_t>> columns_;  ///< exemplar points per grid column
  PointTextureResult stats_;
};

/// Seconds since `t0`, added to `acc`; returns now.
inline std::chrono::steady_clock::time_point lap(std::chrono::steady_clock::time_point t0, double& acc) {
  const auto t1 = std::chrono::steady_clock::now();
  acc += std::chrono::duration<double>(t1 - t0).count();
  return t1;
}

}  // namespace exsynth::points
