#pragma once
// The coordinate method's seam placement: graph cuts that move the seams
// between coherent regions to where the overlapping sources agree (Kwatra
// et al. 2003, "Graphcut Textures"; the min-error boundary of Efros &
// Freeman 2001). The corrections choose each pixel's coordinate from 3 x 3
// appearance neighbourhoods, which leaves the seams where the regions
// happened to meet: on the 8 exemplars of bench_quality.py 69 % of the 8 x 8
// patches cross one, at a mean nn_rel of 0.45 (docs/solid.md).
//
// The finest coordinate image is a labelling: pixel p holding coordinate c
// continues the source "offset c - p". The energy is
//   E = sum over 4-neighbour pairs (p, q = p + e) of
//         |E(c_p) - E(c_q - e)| + |E(c_p + e) - E(c_q)|     (Kwatra's seam cost:
//         the colour difference of the two sources at both pixels; 0 inside a region)
//     + cut_leave * #{p : c_p != the synthesis's coordinate}
// with E() the exemplar's colour and |.| the Euclidean norm over channels.
// The seam cost is a metric on sources, so an expansion move (every pixel
// of a window keeps its source or takes source alpha) is a submodular binary
// problem solved exactly by one min cut (Boykov, Veksler & Zabih 2001;
// Kolmogorov & Zabih 2004). Moves are local: windows of cut_window^2
// pixels whose one-pixel border stays fixed, alpha running over the
// cut_labels commonest sources in the window and its border (the
// neighbouring regions). Windows of one of 2 x 2 classes (3 x 3 when a
// tileable axis has an odd count of windows) never touch, so a
// class runs in parallel with one result on any thread count; pass k shifts
// the window grid by half a window on odd passes so seams can cross
// window edges. A move is kept only when it lowers E (evaluated directly),
// so E never rises. Every output pixel stays an exemplar pixel.
#include <cstdint>
#include <utility>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/solid.hpp"
#include "image/coordinate_synthesis.hpp"

namespace exsynth::image {

class SeamCutter {
 public:
  /// `colours`: the (analysis-scaled) exemplar; coordinates stay in [lowest, highest].
  SeamCutter(const Image& colours, Coord lowest, Coord highest, const CoordinateSynthesisOptions& opt, bool tileable,
             std::uint64_t seed = 0);

  /// Seam cost between output neighbours p (coordinate a) and q = p + (ex, ey) (coordinate b).
  float pair_cost(Coord a, Coord b, int ex, int ey) const;
  /// E above for `s`, with `start` the synthesis's coordinates (same size).
  double energy(const CoordImage& s, const CoordImage& start) const;

  /// A window: inside pixels [x0, x0 + w) x [y0, y0 + h) (x0, y0 may pass the
  /// edge when tileable: positions are unwrapped, pixels wrapped).
  struct Window {
    int x0, y0, w, h;
  };
  /// The windows of pass `pass`, by class (the windows of a class never touch).
  std::vector<std::vector<Window>> windows(const CoordImage& s, int pass) const;
  /// The sources tried as alpha in window `win` (offsets c - p, unwrapped
  /// positions), commonest first, at most cut_labels.
  std::vector<Coord> sources(const CoordImage& s, const Window& win) const;
  /// The nearest exemplar patches of the output's patches (cut_matches): their
  /// corners and matches, for match_sources.
  struct Matches {
    int n = 0;
    std::vector<int> xs, ys;
    std::vector<Coord> nn;
  };
  Matches matches(const CoordImage& s, StageProgress& progress) const;
  /// The sources (offsets, unwrapped as the window's positions) of the
  /// matches whose patch corners lie in `win`, not already in `have`, each
  /// with its patch's footprint (the pixels it may take with cut_reach).
  std::vector<std::pair<Coord, Window>> match_sources(const CoordImage& s, const Matches& m, const Window& win,
                                                      const std::vector<Coord>& have) const;
  /// One expansion move of `win` by source `alpha`, kept only when it lowers
  /// E; returns E's change (<= 0). With cut_reach, the pixels within reach of
  /// alpha's pixels or of `seed` (a new source's footprint) may take it.
  double expand(CoordImage& s, const CoordImage& start, const Window& win, Coord alpha,
                const Window* seed = nullptr) const;

  /// Every pass (cut_passes), progress in ctx's [lo, hi]; E after each pass appended to `energy`.
  void run(CoordImage& s, ExecContext* ctx, double lo, double hi, std::vector<double>* energy) const;

 private:
  bool valid(Coord c) const { return c.u >= lo_.u && c.v >= lo_.v && c.u <= hi_.u && c.v <= hi_.v; }
  /// Pixel index of unwrapped position (x, y), -1 when outside (not tileable).
  long index(const CoordImage& s, int x, int y) const;
  /// The window edge along an output edge of `size` pixels.
  int edge(int size) const;

  const Image& colours_;
  Coord lo_, hi_;
  CoordinateSynthesisOptions opt_;
  bool tileable_;
  std::uint64_t seed_;
};

}  // namespace exsynth::image
