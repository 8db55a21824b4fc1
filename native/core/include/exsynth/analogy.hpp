#pragma once
// Volumetric geometric texture by example (Bhat, Ingram & Turk 2004): B' is
// to B as A' is to A. This first engine is the isotropic variant (the
// paper's blur and dilation analogies): one global frame, neighbourhoods
// aligned with the grid axes, voxels visited in scanline order. The
// field-aligned frames and sweep order of §4 are not implemented yet.
//
// Per level, coarse to fine, every voxel q of B' gets A'(p) for the voxel p
// of A whose feature vector is nearest to q's: [causal fine neighbourhood of
// B' (voxels already visited), full fine neighbourhood of B, full coarse
// neighbourhood of B', full coarse neighbourhood of B]; A's are built the
// same way from A' and A. Nearest neighbours: PCA + nanoflann k-d tree.
#include <cstddef>
#include <cstdint>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {

struct AnalogyOptions {
  int levels = 2;               ///< Gaussian pyramid levels (coarsest first)
  int fine_size = 5;            ///< edge of the fine neighbourhood cube (odd)
  int coarse_size = 3;          ///< edge of the coarse neighbourhood cube (odd)
  int sweeps = 2;               ///< synthesis passes per level
  double pca_variance = 0.95;   ///< PCA keeps this fraction of variance ...
  int max_pca_dims = 24;        ///< ... in at most this many dimensions
  double ann_eps = 0.5;         ///< nanoflann approximation tolerance (0 = exact in PCA space)
  /// Culling (values are signed distances, positive outside): voxels whose
  /// current B' (B at the coarsest level, the upsampled coarser B' above) is
  /// farther than this from the surface keep that value without a search
  /// (EMPTY or OPAQUE by the sign). < 0 = automatic: the fine neighbourhood's
  /// half-width in world units at each level; 0 = no culling.
  double cull_distance = -1.0;
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;       ///< unused: the synthesis is deterministic
};

struct AnalogyResult {
  Volume b_prime;              ///< same grid and transform as B
  std::size_t searched = 0;    ///< voxel searches made, all levels and sweeps
  std::size_t culled = 0;      ///< voxel visits skipped by culling
};

/// a, a_prime: same grid, 1 channel; b: 1 channel, any size (same voxel
/// scale as A assumed). Throws InvalidInput, OverBudget, Cancelled.
AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& b,
                                 const AnalogyOptions& opt = {}, ExecContext* ctx = nullptr);

}  // namespace exsynth
