#pragma once
// Volumetric geometric texture by example (Bhat, Ingram & Turk 2004): B' is
// to B as A' is to A.
//
// Per level of Gaussian pyramids, coarse to fine, B' starts as B (coarsest)
// or as the coarser B' upsampled, and every voxel q near the surface is
// visited in sweep order and gets A'(p) for the voxel p of A whose feature
// vector matches q's best: [causal fine neighbourhood of B' (voxels already
// visited), full fine neighbourhood of B, full coarse neighbourhood of B',
// full coarse neighbourhood of B]. Neighbourhoods are sampled in each voxel's
// local frame (T along the direction field, N the sdf gradient, B = T x N)
// with trilinear interpolation; the causal part is the half cube on the -T
// side. Voxels are visited in order of a sweep distance whose gradient is T.
// Candidates are the approximate nearest neighbour (PCA + nanoflann k-d
// tree) and, as in Hertzmann et al.'s image analogies, the coherent
// continuations of the already visited neighbours' sources; a coherent
// candidate wins unless the nearest neighbour is clearly better. Coherence
// is what lets a pattern start on a smooth B: B' = B matches the pattern-free
// parts of A' exactly, but a continued source copies A' as it is, pattern and
// all. So the coarsest level begins with a growing pass (breadth-first, each
// voxel continuing what its visited neighbours agree on: one coherent copy
// of A' over B), and each finer level starts from the coarser sources.
//
// The isotropic variant (blur, dilation) uses one global frame and scanline
// order.
#include <cstddef>
#include <cstdint>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {

/// Option limits, checked by synthesize_analogy (exported for the bindings' messages).
struct AnalogyLimits {
  static constexpr int max_levels = 6;
  static constexpr int min_fine_size = 3, max_fine_size = 9;      ///< odd
  static constexpr int min_coarse_size = 1, max_coarse_size = 7;  ///< odd
  static constexpr int max_sweeps = 8;
  static constexpr int max_pca_dims = 4096;
};

struct AnalogyOptions {
  int levels = 2;               ///< Gaussian pyramid levels (coarsest first)
  int fine_size = 5;            ///< edge of the fine neighbourhood cube (odd)
  int coarse_size = 3;          ///< edge of the coarse neighbourhood cube (odd)
  int sweeps = 2;               ///< synthesis passes per level
  double pca_variance = 0.95;   ///< PCA keeps this fraction of variance ...
  int max_pca_dims = 24;        ///< ... in at most this many dimensions
  double ann_eps = 0.5;         ///< nanoflann approximation tolerance (0 = exact in PCA space)
  /// Hertzmann's kappa: a coherent candidate is taken unless the nearest
  /// neighbour's distance is below the coherent one's / (1 + coherence)^2.
  /// 0 = nearest neighbour only (no pattern can start on a smooth B).
  double coherence = 1.0;
  /// ... plus this fraction of the exemplar's feature variance: on a smooth
  /// B the pattern-free parts of A' match exactly (distance 0), and without
  /// an absolute slack they would always beat the continuation of a pattern.
  double coherence_slack = 0.05;
  /// Culling (values are signed distances, positive outside): voxels whose
  /// current B' (B at the coarsest level, the upsampled coarser B' above) is
  /// farther than this from the surface keep that value without a search
  /// (EMPTY or OPAQUE by the sign). < 0 = automatic: the fine neighbourhood's
  /// half-width at each level plus, outside, how far the pair moves A's
  /// surface outward (a spike's height) and, inside, inward (a pit's depth);
  /// 0 = no culling.
  double cull_distance = -1.0;
  /// Optional, 1 channel on A's grid: where A' shows the change to learn
  /// (> 0.5), e.g. near faces selected on a model whose modified copy is A';
  /// empty = wherever A' differs from A.
  Volume a_region;
  /// Signed distances only: inside parts of B' that touch none of B's
  /// inside (a spike tip copied into the air) are made empty, and empty
  /// pockets that touch none of B's outside are filled.
  bool remove_debris = true;
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;       ///< unused: the synthesis is deterministic (no random choice)
};

struct AnalogyResult {
  Volume b_prime;              ///< same grid and transform as B
  std::size_t searched = 0;    ///< voxel visits that searched, all levels and sweeps
  std::size_t coherent = 0;    ///< of those, visits where a coherent candidate won
  std::size_t ann_skipped = 0; ///< of those, visits that needed no k-d tree query (the agreed
                               ///< coherent candidate was within the slack)
  std::size_t culled = 0;      ///< voxel visits skipped by culling
  std::size_t debris = 0;      ///< voxels changed by remove_debris
};

/// Empty voxels a grid needs around a surface so that every neighbourhood
/// of the finest level stays inside it: the fine cube's half-width plus the
/// coarse cube's, whose voxels are twice as large (4 with the defaults).
/// Voxelize A, A' and B with at least this padding (plus the pattern's growth).
int analogy_padding(int fine_size = AnalogyOptions{}.fine_size, int coarse_size = AnalogyOptions{}.coarse_size);

/// Isotropic analogy (global frame, scanline order).
/// a, a_prime: same grid, 1 channel; b: 1 channel, any size; A and B must
/// share a voxel size (the pattern is copied voxel for voxel).
/// Throws InvalidInput, OverBudget, Cancelled.
AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& b,
                                 const AnalogyOptions& opt = {}, ExecContext* ctx = nullptr);

/// Field-aligned analogy. field_a / field_b: 3 channels on A's / B's grid,
/// the direction the pattern runs at every voxel (e.g. ExemplarPair::field_a
/// and VolumeFrames::t); it is projected perpendicular to the sdf gradient
/// at every level. Voxels where the field is zero or not finite are an
/// InvalidInput only if they lie near the surface.
AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& field_a, const Volume& b,
                                 const Volume& field_b, const AnalogyOptions& opt = {},
                                 ExecContext* ctx = nullptr);

}  // namespace exsynth
