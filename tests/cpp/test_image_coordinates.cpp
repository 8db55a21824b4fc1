// 2D synthesis of exemplar coordinates (Lefebvre & Hoppe 2005 in appearance
// space): the fast candidate search against brute-force references, the
// distance against a direct evaluation, determinism over thread counts,
// cancellation in every stage, every output pixel an exemplar pixel, and
// bad options.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "exsynth/errors.hpp"
#include "exsynth/solid.hpp"
#include "image/coordinate_synthesis.hpp"
#include "image/patch_refinement.hpp"
#include "support/cancel.hpp"
#include "support/errors.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using exsynth::image::Coord;
using exsynth::image::CoordImage;
using exsynth::image::CoordinateSolver;
using exsynth::testing::disc_texture;
using ::testing::HasSubstr;

namespace {

CoordinateSynthesisOptions plain() {
  CoordinateSynthesisOptions o;
  o.coherence = 0.0;  // the references below are plain minima
  o.coarsest_spacing = 2;
  return o;
}

/// One correction pass over `before` at `level` (no progress reporting).
CoordImage corrected(const CoordinateSolver& s, const CoordImage& before, int level) {
  CoordImage after = before;
  StageProgress progress(nullptr, "", 0, 1, 1);
  s.correct(after, level, progress);
  return after;
}

/// The neighbourhood distance written out from its definition: over the
/// 3 x 3 output neighbours inside the image (or wrapped), the squared
/// difference between the appearance at the neighbour's coordinate and at
/// the candidate moved by the neighbour's offset times the spacing (clamped).
double reference_distance(const CoordinateSolver& s, const CoordImage& img, int x, int y, Coord c, int level,
                          bool tileable) {
  const Image& a = s.appearance(level);
  const int h = s.spacing(level);
  double d = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      int nx = x + dx, ny = y + dy;
      if (tileable) nx = (nx + img.width) % img.width, ny = (ny + img.height) % img.height;
      else if (nx < 0 || ny < 0 || nx >= img.width || ny >= img.height) continue;
      const Coord q = img.at(nx, ny);
      const int eu = std::clamp(c.u + h * dx, 0, a.width() - 1), ev = std::clamp(c.v + h * dy, 0, a.height() - 1);
      for (int k = 0; k < a.channels(); ++k) {
        const double e = double(a.at(eu, ev, k)) - double(a.at(q.u, q.v, k));
        d += e * e;
      }
    }
  return d;
}

ImageSynthesisOptions small_image() {
  ImageSynthesisOptions o;
  o.width = 40;
  o.height = 36;
  o.seed = 3;
  return o;
}

}  // namespace

TEST(ImageCoordinates, DistanceMatchesItsDefinition) {
  const Image ex = disc_texture(20, 18, 3, 31);
  for (bool tileable : {false, true}) {
    const CoordinateSolver s(ex, plain(), tileable, 4, nullptr, 0, 1);
    const int level = s.levels() - 1;
    const CoordImage img = s.initial(9, 7);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        for (Coord c : {s.lowest(), s.highest(), img.at((x + 3) % 9, y)}) {
          const double ref = reference_distance(s, img, x, y, c, level, tileable);
          EXPECT_NEAR(s.distance(img, x, y, c, level), ref, 1e-4 * (1 + ref)) << x << "," << y;
        }
  }
}

TEST(ImageCoordinates, ExhaustiveCorrectionFindsTheGlobalMinimum) {
  // Pixels of the first sub-pass (even x, even y) are decided from the
  // state before the pass and not touched by the later sub-passes.
  const Image ex = disc_texture(16, 16, 3, 32);
  CoordinateSynthesisOptions o = plain();
  o.exhaustive = true;
  const CoordinateSolver s(ex, o, false, 5, nullptr, 0, 1);
  const int level = s.levels() - 1;
  const CoordImage before = s.initial(10, 8);
  const CoordImage after = corrected(s, before, level);
  for (int y = 0; y < before.height; y += 2)
    for (int x = 0; x < before.width; x += 2) {
      double best = std::numeric_limits<double>::infinity();
      for (int v = s.lowest().v; v <= s.highest().v; ++v)
        for (int u = s.lowest().u; u <= s.highest().u; ++u)
          best = std::min(best, reference_distance(s, before, x, y, {u, v}, level, false));
      EXPECT_NEAR(reference_distance(s, before, x, y, after.at(x, y), level, false), best, 1e-4 * (1 + best));
    }
}

TEST(ImageCoordinates, KCoherenceCorrectionTakesTheBestOfItsCandidates) {
  const Image ex = disc_texture(24, 24, 3, 33);
  CoordinateSynthesisOptions o = plain();
  o.coherence_k = 3;
  for (bool tileable : {false, true}) {
    const CoordinateSolver s(ex, o, tileable, 6, nullptr, 0, 1);
    const int level = s.levels() - 1;
    const CoordImage before = s.initial(12, 10);
    const CoordImage after = corrected(s, before, level);
    int moved = 0;
    for (int y = 0; y < before.height; y += 2)
      for (int x = 0; x < before.width; x += 2) {
        const std::vector<Coord> cands = s.candidates(before, x, y, level);
        ASSERT_GE(cands.size(), 2u);
        double best = std::numeric_limits<double>::infinity();
        for (const Coord& c : cands) best = std::min(best, reference_distance(s, before, x, y, c, level, tileable));
        const Coord got = after.at(x, y);
        EXPECT_NE(std::find(cands.begin(), cands.end(), got), cands.end()) << "not one of the candidates";
        EXPECT_NEAR(reference_distance(s, before, x, y, got, level, tileable), best, 1e-4 * (1 + best));
        moved += !(got == before.at(x, y));
      }
    EXPECT_GT(moved, 0);  // from a random start the pass changes something
  }
}

TEST(ImageCoordinates, UpsamplingContinuesTheParentPatch) {
  const Image ex = disc_texture(64, 64, 3, 34);
  CoordinateSynthesisOptions o = plain();
  o.coarsest_spacing = 8;
  const CoordinateSolver s(ex, o, false, 7, nullptr, 0, 1);
  ASSERT_EQ(s.levels(), 4);
  const CoordImage parent = s.initial(5, 4);
  const CoordImage child = s.upsample(parent, 9, 8, 1);  // spacing 4
  for (int y = 0; y < child.height; ++y)
    for (int x = 0; x < child.width; ++x) {
      const Coord p = parent.at(x / 2, y / 2);
      // Past the valid range a coordinate wraps to its other end (no smear of one clamped column).
      const int nu = s.highest().u - s.lowest().u + 1, nv = s.highest().v - s.lowest().v + 1;
      const Coord want{s.lowest().u + (p.u + 4 * (x & 1) - s.lowest().u) % nu,
                       s.lowest().v + (p.v + 4 * (y & 1) - s.lowest().v) % nv};
      EXPECT_TRUE(child.at(x, y) == want);
    }
}

TEST(ImageCoordinates, SameSeedSameImageOnOneTwoAndEightThreads) {
  const Image ex = disc_texture(32, 32, 3, 35);
  for (bool tileable : {false, true}) {
    ImageSynthesisOptions o = small_image();
    o.tileable = tileable;
    o.coordinates.refine_passes = 2;  // the patch refinement too (off by default)
    const Image one = exsynth::testing::on_threads(1, [&] { return synthesize_image(ex, o); });
    const Image two = exsynth::testing::on_threads(2, [&] { return synthesize_image(ex, o); });
    const Image eight = exsynth::testing::on_threads(8, [&] { return synthesize_image(ex, o); });
    EXPECT_EQ(one.values(), two.values());
    EXPECT_EQ(one.values(), eight.values());
    o.seed = 4;
    EXPECT_NE(synthesize_image(ex, o).values(), one.values());
  }
}

TEST(ImageCoordinates, EveryPixelIsAnExemplarPixel) {
  const Image ex = disc_texture(24, 20, 2, 36);
  ImageSynthesisOptions o = small_image();
  o.width = 7;  // below the optimiser's size rule: the coordinate method takes any size
  o.height = 5;
  for (int w : {7, 41}) {
    o.width = w;
    const Image out = synthesize_image(ex, o);
    ASSERT_EQ(out.width(), w);
    ASSERT_EQ(out.height(), 5);
    for (std::size_t p = 0; p < out.pixel_count(); ++p) {
      bool found = false;
      for (std::size_t q = 0; q < ex.pixel_count() && !found; ++q)
        found = out.data()[p * 2] == ex.data()[q * 2] && out.data()[p * 2 + 1] == ex.data()[q * 2 + 1];
      ASSERT_TRUE(found) << "pixel " << p;
    }
  }
}

TEST(ImageCoordinates, TinyAndHugeValuedExemplarsWork) {
  for (float scale : {1e-30f, 1e30f}) {
    Image ex = disc_texture(16, 16, 1, 37);
    for (float& v : ex.values()) v *= scale;
    ImageSynthesisOptions o = small_image();
    const Image out = synthesize_image(ex, o);
    float lo = out.values()[0], hi = lo;
    for (float v : out.values()) lo = std::min(lo, v), hi = std::max(hi, v);
    EXPECT_GT(hi, lo);  // structure, not one repeated pixel
  }
}

TEST(ImageCoordinates, CancelInEveryStage) {
  const Image ex = disc_texture(32, 32, 3, 38);
  ImageSynthesisOptions o = small_image();
  o.coordinates.refine_passes = 2;  // off by default
  const auto job = [&](ExecContext* ctx) { synthesize_image(ex, o, ctx); };
  const auto log = exsynth::testing::stages_of(job);
  ASSERT_GE(log.names.size(), 4u);
  EXPECT_NEAR(log.final_progress, 1.0, 1e-9);
  for (const std::string& stage : log.names) {
    const auto outcome = exsynth::testing::cancel_in_stage(job, stage);
    EXPECT_TRUE(outcome.threw_cancelled) << stage;
    EXPECT_EQ(outcome.stage_at_throw, stage);
  }
  EXPECT_THAT(log.names.back(), HasSubstr("patch refinement"));
  EXPECT_THAT(log.names[log.names.size() - 2], HasSubstr("(coordinates)"));
}

TEST(ImageCoordinates, BadOptionsNameTheOption) {
  const Image ex = disc_texture(16, 16, 3, 39);
  auto message = [&](auto change) {
    ImageSynthesisOptions o = small_image();
    change(o);
    return exsynth::testing::invalid_input_message([&] { synthesize_image(ex, o); });
  };
  EXPECT_THAT(message([](auto& o) { o.coordinates.jitter = -1; }), HasSubstr("jitter must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.jitter_from = 3; }), HasSubstr("jitter_from must be a power of two"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.coherence_k = 0; }), HasSubstr("coherence_k must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.appearance_window = 4; }), HasSubstr("appearance_window must be odd"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.coarsest_spacing = 6; }), HasSubstr("coarsest_spacing must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.coherence = -1; }), HasSubstr("coherence must be"));
  EXPECT_THAT(message([](auto& o) { o.width = 0; }), HasSubstr("width must be between 1 and"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.refine_passes = 17; }), HasSubstr("refine_passes must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.refine_patch = 1; }), HasSubstr("refine_patch must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.refine_stride = 17; }), HasSubstr("refine_stride must be between 1 and refine_patch"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.refine_random = -1; }), HasSubstr("refine_random must be"));
  Image bad = ex;
  bad.at(3, 4, 1) = std::nanf("");
  EXPECT_THROW(synthesize_image(bad, small_image()), InvalidInput);
}

// ---- patch refinement (image/patch_refinement.*) ----

namespace {

using exsynth::image::PatchRefiner;

CoordinateSynthesisOptions refining(int patch, int stride) {
  CoordinateSynthesisOptions o = plain();
  o.refine_passes = 1;
  o.refine_patch = patch;
  o.refine_stride = stride;
  return o;
}

/// The patch distance written out: over the n x n output pixels from
/// (px, py) (wrapped when tileable), the squared colour difference between
/// the exemplar at the pixel's coordinate and at e + its offset.
double reference_patch_distance(const Image& colours, const CoordImage& s, int px, int py, Coord e, int n) {
  double d = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Coord q = s.at((px + i) % s.width, (py + j) % s.height);
      for (int k = 0; k < colours.channels(); ++k) {
        const double t = double(colours.at(q.u, q.v, k)) - double(colours.at(e.u + i, e.v + j, k));
        d += t * t;
      }
    }
  return d;
}

/// Every valid top-left position of an n x n exemplar patch.
std::vector<Coord> every_patch(const CoordinateSolver& s, int n) {
  std::vector<Coord> all;
  for (int v = s.lowest().v; v + n - 1 <= s.highest().v; ++v)
    for (int u = s.lowest().u; u + n - 1 <= s.highest().u; ++u) all.push_back({u, v});
  return all;
}

}  // namespace

TEST(ImagePatchRefinement, CornersCoverTheOutput) {
  const Image ex = disc_texture(24, 24, 3, 40);
  for (bool tileable : {false, true}) {
    const CoordinateSolver s(ex, refining(6, 4), tileable, 1, nullptr, 0, 1);
    const PatchRefiner r(ex, s.lowest(), s.highest(), refining(6, 4), tileable, 1);
    const std::vector<int> xs = r.corners(19, 6);
    std::vector<int> covered(19, 0);
    for (int x : xs)
      for (int o = 0; o < 6; ++o) {
        ASSERT_TRUE(tileable || x + o < 19);
        ++covered[std::size_t((x + o) % 19)];
      }
    for (int c : covered) EXPECT_GE(c, 1);
    EXPECT_EQ(xs.front(), 0);
  }
}

TEST(ImagePatchRefinement, DistanceMatchesItsDefinition) {
  const Image ex = disc_texture(20, 18, 3, 41);
  for (bool tileable : {false, true}) {
    const CoordinateSolver s(ex, refining(5, 2), tileable, 2, nullptr, 0, 1);
    const PatchRefiner r(ex, s.lowest(), s.highest(), refining(5, 2), tileable, 2);
    const CoordImage img = s.initial(11, 9);
    for (int py : r.corners(9, 5))
      for (int px : r.corners(11, 5))
        for (Coord e : {s.lowest(), Coord{s.highest().u - 4, s.highest().v - 4}}) {
          const double ref = reference_patch_distance(ex, img, px, py, e, 5);
          EXPECT_NEAR(r.distance(img, px, py, e, 5), ref, 1e-4 * (1 + ref));
        }
  }
}

TEST(ImagePatchRefinement, ExhaustiveMatchFindsTheNearestPatch) {
  // The brute-force twin of the PatchMatch search: every valid position.
  const Image ex = disc_texture(16, 16, 3, 42);
  CoordinateSynthesisOptions o = refining(4, 3);
  o.exhaustive = true;
  const CoordinateSolver s(ex, o, false, 3, nullptr, 0, 1);
  const PatchRefiner r(ex, s.lowest(), s.highest(), o, false, 3);
  const CoordImage img = s.initial(10, 9);
  std::vector<Coord> nn;
  StageProgress progress(nullptr, "", 0, 1, 1);
  r.match(img, nn, 0, progress);
  const std::vector<int> xs = r.corners(10, 4), ys = r.corners(9, 4);
  ASSERT_EQ(nn.size(), xs.size() * ys.size());
  for (std::size_t gy = 0; gy < ys.size(); ++gy)
    for (std::size_t gx = 0; gx < xs.size(); ++gx) {
      double best = std::numeric_limits<double>::infinity();
      for (Coord e : every_patch(s, 4)) best = std::min(best, reference_patch_distance(ex, img, xs[gx], ys[gy], e, 4));
      EXPECT_NEAR(reference_patch_distance(ex, img, xs[gx], ys[gy], nn[gy * xs.size() + gx], 4), best,
                  1e-4 * (1 + best));
    }
}

TEST(ImagePatchRefinement, MatchTakesTheBestOfItsCandidates) {
  const Image ex = disc_texture(32, 32, 3, 43);
  const CoordinateSynthesisOptions o = refining(6, 2);
  for (bool tileable : {false, true}) {
    const CoordinateSolver s(ex, o, tileable, 4, nullptr, 0, 1);
    const PatchRefiner r(ex, s.lowest(), s.highest(), o, tileable, 4);
    const CoordImage img = s.initial(14, 12);
    StageProgress progress(nullptr, "", 0, 1, 1);
    std::vector<Coord> first, second;
    r.match(img, first, 0, progress);
    second = first;
    r.match(img, second, 1, progress);  // round 1: also the last matches and the neighbours'
    const std::vector<int> xs = r.corners(14, 6), ys = r.corners(12, 6);
    for (std::size_t gy = 0; gy < ys.size(); ++gy)
      for (std::size_t gx = 0; gx < xs.size(); ++gx) {
        const int px = xs[gx], py = ys[gy];
        auto d = [&](Coord e) { return reference_patch_distance(ex, img, px, py, e, 6); };
        Coord best{};
        double best_d = std::numeric_limits<double>::infinity();
        for (Coord e : r.match_candidates(img, first, int(gx), int(gy), 1, best, false))
          if (d(e) < best_d) best_d = d(e), best = e;
        ASSERT_LT(best_d, std::numeric_limits<double>::infinity());
        for (Coord e : r.match_candidates(img, first, int(gx), int(gy), 1, best, true)) best_d = std::min(best_d, d(e));
        const Coord got = second[gy * xs.size() + gx];
        EXPECT_NEAR(d(got), best_d, 1e-4 * (1 + best_d));
        // Never worse than the last round's match (it is a candidate).
        EXPECT_LE(d(got), d(first[gy * xs.size() + gx]) + 1e-4);
      }
  }
}

TEST(ImagePatchRefinement, VoteTakesTheMedoidOrTheNearestToTheMean) {
  const Image ex = disc_texture(24, 24, 2, 44);
  for (bool medoid : {true, false}) {
    CoordinateSynthesisOptions o = refining(4, 2);
    o.refine_medoid = medoid;
    const CoordinateSolver s(ex, o, false, 5, nullptr, 0, 1);
    const PatchRefiner r(ex, s.lowest(), s.highest(), o, false, 5);
    const CoordImage before = s.initial(9, 8);
    StageProgress progress(nullptr, "", 0, 1, 1);
    std::vector<Coord> nn;
    r.match(before, nn, 0, progress);
    CoordImage after = before;
    r.vote(after, nn, progress);
    const std::vector<int> xs = r.corners(9, 4), ys = r.corners(8, 4);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 9; ++x) {
        // Proposals: each covering patch's match moved to the pixel.
        std::vector<Coord> props;
        for (std::size_t gy = 0; gy < ys.size(); ++gy)
          for (std::size_t gx = 0; gx < xs.size(); ++gx)
            if (x >= xs[gx] && x < xs[gx] + 4 && y >= ys[gy] && y < ys[gy] + 4) {
              const Coord e = nn[gy * xs.size() + gx];
              props.push_back({e.u + x - xs[gx], e.v + y - ys[gy]});
            }
        ASSERT_FALSE(props.empty());
        auto cost = [&](Coord c) {  // sum of colour distances (squared: !medoid) to the proposals, one per patch
          double t = 0.0;
          for (Coord p : props) {
            double e = 0.0;
            for (int k = 0; k < 2; ++k) e += std::pow(double(ex.at(c.u, c.v, k)) - double(ex.at(p.u, p.v, k)), 2);
            t += medoid ? std::sqrt(e) : e;  // the mean minimises the sum of squares
          }
          return t;
        };
        double best = cost(before.at(x, y));
        for (Coord p : props) best = std::min(best, cost(p));
        const Coord got = after.at(x, y);
        EXPECT_TRUE(got == before.at(x, y) || std::find(props.begin(), props.end(), got) != props.end());
        EXPECT_NEAR(cost(got), best, 1e-4 * (1 + best));
      }
  }
}

TEST(ImagePatchRefinement, LowersThePatchEnergy) {
  const Image ex = disc_texture(32, 32, 3, 45);
  ImageSynthesisOptions o = small_image();
  o.coordinates.refine_passes = 3;
  std::vector<double> energy;
  synthesize_image(ex, o, nullptr, &energy);
  const std::size_t levels_passes = energy.size() - 3;
  ASSERT_GE(energy.size(), 4u);
  // The rounds' match energies (mean squared colour distance per patch pixel) fall.
  EXPECT_LE(energy[levels_passes + 2], energy[levels_passes] + 1e-9);
  EXPECT_GT(energy[levels_passes], 0.0);
}
