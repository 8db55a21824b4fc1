#pragma once
// The coordinate method's last stage: seams judged at the scale of whole
// patches. The corrections compare 3 x 3 appearance vectors of 5 x 5
// windows, and a seam between two sources that agree there can still break
// the structure an 8 x 8 patch across it shows (brick's mortar lines); on the
// 8 exemplars of bench_quality.py 69 % of the output's 8 x 8 patches crossed a
// seam with a mean nn_rel of 0.45 there (G'MIC's: 45 %, 0.35; docs/solid.md).
//
// Each round is one step of discrete texture optimisation (Kwatra et al.
// 2005's energy, Han et al. 2006's discrete solve) in coordinate space:
//   match  every output patch (refine_patch^2, corners refine_stride apart)
//          finds its nearest exemplar patch in colour, PatchMatch-style
//          (Barnes et al. 2009): the coordinates the patch holds shifted back
//          to its corner, its grid neighbours' matches from the last round,
//          and seeded random probes at halving radii around the best;
//   vote   each pixel takes, among its own coordinate and those its covering
//          patches' matches propose, the one whose colour is nearest (sum of
//          squares) to all the proposals' colours.
// Both steps read only the previous state, so any thread order gives one
// result; every output pixel stays an exemplar pixel.
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/solid.hpp"
#include "image/coordinate_synthesis.hpp"

namespace exsynth::image {

class PatchRefiner {
 public:
  /// `colours`: the (analysis-scaled) exemplar; patches keep every pixel's
  /// coordinate in [lowest, highest].
  PatchRefiner(const Image& colours, Coord lowest, Coord highest, const CoordinateSynthesisOptions& opt, bool tileable,
               std::uint64_t seed);

  /// Patch edge used (refine_patch, shrunk to fit the exemplar's valid range and the output).
  int patch(const CoordImage& s) const;
  /// Top-left corners along an output edge of `size` pixels.
  std::vector<int> corners(int size, int n) const;

  /// Squared colour distance between output patch at (px, py) of `s` and the
  /// exemplar patch with top-left coordinate e (n x n, wrapped when tileable).
  float distance(const CoordImage& s, int px, int py, Coord e, int n) const;

  /// One match step: `nn` (one per patch, row-major over corners; empty on
  /// the first round) becomes each patch's best candidate; returns the mean
  /// squared distance per patch pixel.
  double match(const CoordImage& s, std::vector<Coord>& nn, int round, StageProgress& progress,
               std::vector<float>* dist = nullptr) const;
  /// One vote step from the matches.
  void vote(CoordImage& s, const std::vector<Coord>& nn, StageProgress& progress) const;
  /// Candidates of patch (gx, gy) in the match step, in the order scored
  /// (the reference the tests compare the search with): without `probes`
  /// the last match, the sources the patch holds and the neighbours'
  /// matches (every valid position with `exhaustive`); with `probes` the
  /// round's random probes around `best`.
  std::vector<Coord> match_candidates(const CoordImage& s, const std::vector<Coord>& nn, int gx, int gy, int round,
                                      Coord best, bool probes) const;

  /// Every round (refine_passes), progress in ctx's [lo, hi]; energies appended.
  void run(CoordImage& s, ExecContext* ctx, double lo, double hi, std::vector<double>* energy) const;

 private:
  bool valid(Coord e, int n) const {
    return e.u >= lo_.u && e.v >= lo_.v && e.u + n - 1 <= hi_.u && e.v + n - 1 <= hi_.v;
  }
  /// match_candidates with the patch edge and the corners given (match()
  /// computes them once per round, not once per patch).
  std::vector<Coord> match_candidates(const CoordImage& s, const std::vector<Coord>& nn, int n,
                                      const std::vector<int>& xs, const std::vector<int>& ys, int gx, int gy,
                                      int round, Coord best, bool probes) const;
  /// Colours at the output's coordinates, padded by n - 1 (wrapped when tileable) so patches read rows.
  Image gather(const CoordImage& s, int n) const;
  float distance(const Image& out, int px, int py, Coord e, int n, float bound) const;

  const Image& colours_;
  Coord lo_, hi_;
  CoordinateSynthesisOptions opt_;
  bool tileable_;
  std::uint64_t seed_;
};

}  // namespace exsynth::image
