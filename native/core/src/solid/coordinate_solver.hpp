#pragma once
// One pyramid level of solid synthesis by exemplar coordinates (Dong et al.
// 2008, after Lefebvre & Hoppe 2005/2006): every voxel holds a Triple (the
// texel it is in each view's exemplar). A level starts from random table
// triples (coarsest) or from the coarser level's coordinates (child =
// 2 * parent + offset) and runs correction passes: each voxel takes, among
// k-coherence candidates of its neighbours, the triple whose appearance-space
// crossbar neighbourhoods in the three slices best match its neighbours'.
// Voxels are corrected in sub-passes of equal coordinate parity, so no two
// voxels of a sub-pass are neighbours: parallel and thread-count independent.
#include <array>
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "solid/crossbar_candidates.hpp"
#include "solid/exemplar_index.hpp"

namespace exsynth::solid {

class CoordinateSolver {
 public:
  /// `views` (nullptr = inactive) are this level's exemplar analyses, whose
  /// PCA coefficients are the appearance-space features; they and
  /// `candidates` must outlive the solver.
  CoordinateSolver(const std::array<int, 3>& dims, const std::array<const ExemplarIndex*, 3>& views,
                   const CrossbarCandidates& candidates, int coherence_k, bool wrap, std::uint64_t seed);

  /// Coarsest level: each voxel a random table triple (seeded per voxel).
  void initialize(StageProgress& progress);
  /// Finer level: each voxel's texel in view i is 2 * (its parent's) + its
  /// offset from the parent along that view's slice axes; the child one step
  /// along view i's own axis takes view i's texel from the crossbar table
  /// instead (not its sibling's, which would extrude it).
  void upsample(const CoordinateSolver& coarser, StageProgress& progress);
  /// One correction pass over every voxel (sub-passes by parity).
  void correct(StageProgress& progress);
  /// Units of progress initialize, upsample and correct each report.
  std::size_t units() const { return coords_.size(); }

  /// Per voxel (x fastest): the exemplar values of its texel in the view
  /// that fits its neighbours best, read from `images` (the views' exemplars at this level's
  /// resolution, nullptr = inactive; any channel count, same per view).
  Volume colours(const std::array<const Image*, 3>& images, StageProgress& progress) const;
  const std::vector<Triple>& coordinates() const { return coords_; }
  /// Mean over voxels of the best candidate's cost after the last pass.
  double energy() const { return energy_; }

 private:
  std::size_t voxel(int x, int y, int z) const { return (std::size_t(z) * dims_[1] + y) * dims_[0] + x; }
  /// Voxel index of the neighbour one step along `axis` (sign s), or -1
  /// outside a non-tiling volume.
  std::int64_t neighbour(const std::array<int, 3>& p, int axis, int s) const;
  /// Texel of valid centre j of view i moved by (du, dv), clamped to valid centres.
  std::int32_t shift(int view, std::int32_t j, int du, int dv) const;
  const float* feature(int view, std::int32_t j) const { return features_[view] + std::size_t(j) * dims_pca_[view]; }
  /// Per view: how far the voxel's texel's crossbar neighbourhood is from its neighbours' texels.
  std::array<float, 3> view_costs(const std::array<int, 3>& p) const;
  /// Corrects one voxel; returns its cost.
  float correct_voxel(const std::array<int, 3>& p, std::vector<Triple>& candidates, Triple& best) const;

  std::array<int, 3> dims_;
  std::array<const ExemplarIndex*, 3> views_;
  const CrossbarCandidates& table_;
  int k_;
  // Weight of the crossbar consistency (Euclidean line distance) against the
  // neighbourhood match (Euclidean feature distances): 0.25 against 1 and 4
  // at 64^3, stone33 contrast 0.84 / 0.82 -> 0.85, crackedground 0.92 -> 0.95
  // (docs/solid.md, sixth pass).
  const float consistency_ = 0.25f;
  bool wrap_;
  std::uint64_t seed_;
  std::array<const float*, 3> features_{};
  std::array<int, 3> dims_pca_{};
  std::vector<Triple> coords_;
  double energy_ = 0.0;
};

}  // namespace exsynth::solid
