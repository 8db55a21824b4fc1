#pragma once
// 2D texture synthesis of exemplar coordinates (Lefebvre & Hoppe 2005,
// "Parallel Controllable Texture Synthesis"), neighbourhoods compared in a
// PCA-reduced appearance space (Lefebvre & Hoppe 2006, "Appearance-Space
// Texture Synthesis").
//
// The output is an image S of exemplar coordinates, built coarse to fine:
// at level spacing h, each pixel's four children take the parent's
// coordinate plus h * (0|1, 0|1) (the patch keeps running), a seeded jitter
// moves coordinates by up to h * r, and correction passes (4 sub-passes of
// interleaved pixels) replace each coordinate by the k-coherence candidate
// (from the 3 x 3 neighbours' coordinates, shifted back by their offset,
// and their k - 1 most similar exemplar positions) whose exemplar
// neighbourhood best matches the pixel's. Neighbourhoods are 3 x 3
// appearance vectors at spacing h, from a Gaussian stack of the appearance
// image (a trous, never decimated). Colours are read from the coordinates at
// the end, so every output pixel is an exemplar pixel.
#include <cstdint>
#include <memory>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/solid.hpp"
#include "solid/exemplar_index.hpp"

namespace exsynth::image {

struct Coord {
  std::int32_t u, v;
  bool operator==(const Coord& o) const { return u == o.u && v == o.v; }
};

/// One synthesis level's coordinate image (x fastest).
struct CoordImage {
  int width = 0, height = 0;
  std::vector<Coord> s;
  Coord& at(int x, int y) { return s[std::size_t(y) * width + x]; }
  const Coord& at(int x, int y) const { return s[std::size_t(y) * width + x]; }
};

/// Built once per exemplar (appearance space, k-coherence sets, stack),
/// then run level by level.
class CoordinateSolver {
 public:
  /// `exemplar` is the working exemplar (already reduced to the working
  /// resolution); progress of the analysis goes to [lo, hi] of ctx.
  CoordinateSolver(const Image& exemplar, const CoordinateSynthesisOptions& opt, bool tileable, std::uint64_t seed,
                   ExecContext* ctx, double lo, double hi);

  /// Levels, coarsest first; spacing(l) = coarsest_spacing / 2^l, 1 at the finest.
  int levels() const { return int(stack_.size()); }
  int spacing(int level) const { return stack_spacing_[std::size_t(levels() - 1 - level)]; }

  /// The whole synthesis: coordinates at width x height, progress in [lo, hi].
  CoordImage synthesize(int width, int height, ExecContext* ctx, double lo, double hi,
                        std::vector<double>* energy = nullptr) const;
  /// Colours of the working exemplar at the coordinates.
  Image colours(const CoordImage& s) const;

  // Stages (public for the tests).
  CoordImage initial(int width, int height) const;
  CoordImage upsample(const CoordImage& parent, int width, int height, int level) const;
  void jitter(CoordImage& s, int level) const;
  /// One correction pass (4 sub-passes); returns the mean neighbourhood distance.
  double correct(CoordImage& s, int level, StageProgress& progress) const;
  /// Squared distance between pixel (x, y)'s neighbourhood in `s` and the
  /// exemplar neighbourhood at candidate c, at `level`.
  float distance(const CoordImage& s, int x, int y, Coord c, int level) const;
  /// Candidates of pixel (x, y): its own coordinate first, then the
  /// k-coherence set (or every valid exemplar position with `exhaustive`).
  std::vector<Coord> candidates(const CoordImage& s, int x, int y, int level) const;

  const Image& appearance(int level) const { return stack_[std::size_t(levels() - 1 - level)]; }
  Coord lowest() const { return {lo_u_, lo_v_}; }
  Coord highest() const { return {hi_u_, hi_v_}; }

 private:
  void build_similar(ExecContext* ctx, double lo, double hi);
  /// The k - 1 exemplar positions most like valid position c (appearance vectors).
  const Coord* similar(Coord c) const {
    return similar_.data() + (std::size_t(c.v - lo_v_) * std::size_t(hi_u_ - lo_u_ + 1) + std::size_t(c.u - lo_u_)) *
                                 std::size_t(opt_.coherence_k - 1);
  }
  Coord clamp(Coord c) const;  ///< into the valid range (wrapping)
  bool valid(Coord c) const;
  /// Neighbour (x + dx, y + dy) in the output (wrapped when tileable); false when outside.
  bool neighbour(const CoordImage& s, int x, int y, int dx, int dy, int& nx, int& ny) const;
  void correct_pixel(const CoordImage& prev, CoordImage& out, int x, int y, int level, double& sum) const;

  Image exemplar_;
  Image scaled_;  ///< the exemplar scaled for the analysis (colour distances of the refinement)
  CoordinateSynthesisOptions opt_;
  bool tileable_;
  std::uint64_t seed_;
  std::unique_ptr<solid::ExemplarIndex> index_;
  std::vector<Image> stack_;        ///< appearance at spacing 1, 2, 4, ... (finest first)
  std::vector<int> stack_spacing_;  ///< spacing of each stack entry
  int lo_u_ = 0, lo_v_ = 0, hi_u_ = 0, hi_v_ = 0;  ///< valid coordinates (appearance window inside)
  std::vector<Coord> similar_;      ///< k-coherence sets, k - 1 per valid position (row-major)
};

/// synthesize_image with ImageMethod::Coordinates (options checked there).
Image synthesize_coordinates(const Image& exemplar, const ImageSynthesisOptions& opt, ExecContext* ctx,
                             std::vector<double>* energy);

}  // namespace exsynth::image
