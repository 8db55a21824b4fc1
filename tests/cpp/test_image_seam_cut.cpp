// Seam cuts of the coordinate method (image/seam_cut.*, image/max_flow.*):
// the max-flow against every cut of tiny graphs, one expansion move against
// every labelling it allows, the energy never rising, windows that never
// touch, determinism over thread counts, cancellation, bad options.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "exsynth/errors.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/solid.hpp"
#include "image/coordinate_synthesis.hpp"
#include "image/max_flow.hpp"
#include "image/seam_cut.hpp"
#include "support/cancel.hpp"
#include "support/errors.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using exsynth::image::Coord;
using exsynth::image::CoordImage;
using exsynth::image::MaxFlow;
using exsynth::image::SeamCutter;
using exsynth::testing::disc_texture;
using ::testing::HasSubstr;

namespace {

struct Edge {
  int i, j;
  double cap;
};

/// A random coordinate image: patches of a few sources (so there are seams) and some noise pixels.
CoordImage random_coords(int w, int h, Coord lo, Coord hi, std::uint64_t seed) {
  CoordImage s{w, h, std::vector<Coord>(std::size_t(w) * h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint64_t p = std::uint64_t(y) * w + x;
      IndexRng block(seed, std::uint64_t((y / 3) * 64 + x / 3), 1);
      const int du = int(block.below(std::uint64_t(hi.u - lo.u + 1))), dv = int(block.below(std::uint64_t(hi.v - lo.v + 1)));
      Coord c{lo.u + (du + x) % (hi.u - lo.u + 1), lo.v + (dv + y) % (hi.v - lo.v + 1)};
      IndexRng noise(seed, p, 2);
      if (noise.uniform() < 0.15)
        c = {lo.u + int(noise.below(std::uint64_t(hi.u - lo.u + 1))), lo.v + int(noise.below(std::uint64_t(hi.v - lo.v + 1)))};
      s.at(x, y) = c;
    }
  return s;
}

CoordinateSynthesisOptions cutting(int passes, int window, double leave) {
  CoordinateSynthesisOptions o;
  o.cut_passes = passes;
  o.cut_window = window;
  o.cut_leave = leave;
  return o;
}

ImageSynthesisOptions small_cut_image() {
  ImageSynthesisOptions o;
  o.width = 40;
  o.height = 36;
  o.seed = 3;
  o.coordinates.cut_passes = 2;
  o.coordinates.cut_window = 12;
  return o;
}

}  // namespace

TEST(ImageMaxFlow, EqualsTheMinimumOfEveryCutOnTinyGraphs) {
  for (std::uint64_t trial = 0; trial < 300; ++trial) {
    IndexRng r(91, trial, 0);
    const int n = 1 + int(r.below(8));
    std::vector<double> src(static_cast<std::size_t>(n)), snk(static_cast<std::size_t>(n));
    std::vector<Edge> edges;
    MaxFlow flow(n);
    for (int i = 0; i < n; ++i) {
      src[std::size_t(i)] = r.uniform() < 0.6 ? r.uniform() * 3 : 0.0;
      snk[std::size_t(i)] = r.uniform() < 0.6 ? r.uniform() * 3 : 0.0;
      flow.add_terminal(i, src[std::size_t(i)], snk[std::size_t(i)]);
    }
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (i != j && r.uniform() < 0.4) {
          const double c = r.uniform() * 2;
          edges.push_back({i, j, c});
          flow.add_edge(i, j, c, 0.0);
        }
    // Every assignment of the nodes to the source (bit 0) or sink (bit 1) side.
    auto cut = [&](unsigned sink_side) {
      double c = 0.0;
      for (int i = 0; i < n; ++i) c += (sink_side >> i & 1u) ? src[std::size_t(i)] : snk[std::size_t(i)];
      for (const Edge& e : edges)
        if (!(sink_side >> e.i & 1u) && (sink_side >> e.j & 1u)) c += e.cap;
      return c;
    };
    double best = std::numeric_limits<double>::infinity();
    for (unsigned m = 0; m < (1u << n); ++m) best = std::min(best, cut(m));
    const double f = flow.solve();
    EXPECT_NEAR(f, best, 1e-9) << "trial " << trial;
    unsigned found = 0;
    for (int i = 0; i < n; ++i)
      if (!flow.source_side(i)) found |= 1u << i;
    EXPECT_NEAR(cut(found), best, 1e-9) << "trial " << trial << ": the reported cut is a minimum one";
  }
}

TEST(ImageMaxFlow, ReusedAfterReset) {
  MaxFlow flow(2);
  flow.add_terminal(0, 5, 0);
  flow.add_edge(0, 1, 2, 0);
  flow.add_terminal(1, 0, 7);
  EXPECT_NEAR(flow.solve(), 2.0, 1e-12);
  EXPECT_TRUE(flow.source_side(0));
  EXPECT_FALSE(flow.source_side(1));
  flow.reset(1);
  flow.add_terminal(0, 1, 3);
  EXPECT_NEAR(flow.solve(), 1.0, 1e-12);
  EXPECT_TRUE(flow.source_side(0) == false);
}

TEST(ImageSeamCut, PairCostIsKwatrasAndZeroInsideAPatch) {
  const Image ex = disc_texture(16, 16, 3, 60);
  const SeamCutter cut(ex, {0, 0}, {15, 15}, cutting(1, 8, 0), false);
  EXPECT_EQ(cut.pair_cost({4, 5}, {5, 5}, 1, 0), 0.0f);
  EXPECT_EQ(cut.pair_cost({4, 5}, {4, 6}, 0, 1), 0.0f);
  auto norm = [&](Coord a, Coord b) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += std::pow(double(ex.at(a.u, a.v, k)) - ex.at(b.u, b.v, k), 2);
    return std::sqrt(d);
  };
  // p holds (3, 7), q = p + (1, 0) holds (9, 2): sources A = (3, 7) + ., B = (8, 2) + .
  EXPECT_NEAR(cut.pair_cost({3, 7}, {9, 2}, 1, 0), norm({3, 7}, {8, 2}) + norm({4, 7}, {9, 2}), 1e-5);
  EXPECT_NEAR(cut.pair_cost({3, 7}, {9, 2}, 0, 1), norm({3, 7}, {9, 1}) + norm({3, 8}, {9, 2}), 1e-5);
  // cut_radius 1: the mean over the 3 x 3 pixels around each (clamped at the exemplar's edge).
  CoordinateSynthesisOptions o = cutting(1, 8, 0);
  o.cut_radius = 1;
  const SeamCutter wide(ex, {0, 0}, {15, 15}, o, false);
  auto at = [](int u, int v) { return Coord{std::clamp(u, 0, 15), std::clamp(v, 0, 15)}; };
  for (auto [a, b] : {std::pair{Coord{3, 7}, Coord{9, 2}}, std::pair{Coord{0, 15}, Coord{15, 0}}}) {
    double want = 0;
    for (int dv = -1; dv <= 1; ++dv)
      for (int du = -1; du <= 1; ++du)
        want += norm(at(a.u + du, a.v + dv), at(b.u - 1 + du, b.v + dv)) + norm(at(a.u + 1 + du, a.v + dv), at(b.u + du, b.v + dv));
    EXPECT_NEAR(wide.pair_cost(a, b, 1, 0), want / 9, 1e-5);
  }
  EXPECT_EQ(wide.pair_cost({4, 5}, {5, 5}, 1, 0), 0.0f);
}

TEST(ImageSeamCut, ExpansionIsTheBestOfEveryLabellingItAllows) {
  const Image ex = disc_texture(14, 14, 3, 61);
  const Coord lo{1, 1}, hi{12, 12};
  for (bool tileable : {false, true})
    for (double leave : {0.0, 0.3})
      for (int reach : {0, 1})
      for (std::uint64_t seed = 0; seed < 6; ++seed) {
        // Odd seeds: a new source's footprint (2 x 2 at the window's corner) seeds the reach too.
        const SeamCutter::Window foot{2, 1, 2, 2};
        const bool footed = seed % 2 == 1;
        CoordinateSynthesisOptions o = cutting(1, 8, leave);
        o.cut_reach = reach;
        o.cut_radius = int(seed % 2);  // Kwatra's pair cost, and the mean over 3 x 3 around
        const SeamCutter cut(ex, lo, hi, o, tileable);
        const CoordImage start = random_coords(7, 6, lo, hi, seed + 10 * tileable);
        const SeamCutter::Window win{2, 1, 3, 3};  // 9 pixels: 512 labellings
        CoordImage s = start;
        for (const Coord& alpha : cut.sources(start, win)) {
          // The pixels that may take alpha (inside, valid, not already alpha's).
          std::vector<std::size_t> free;
          for (int y = win.y0; y < win.y0 + win.h; ++y)
            for (int x = win.x0; x < win.x0 + win.w; ++x) {
              const Coord c{x + alpha.u, y + alpha.v};
              // With a reach: some pixel of the padded window within `reach` already continues alpha.
              bool near = reach == 0;
              for (int yy = y - reach; yy <= y + reach && footed; ++yy)
                for (int xx = x - reach; xx <= x + reach; ++xx)
                  near = near || (xx >= foot.x0 && yy >= foot.y0 && xx < foot.x0 + foot.w && yy < foot.y0 + foot.h);
              for (int yy = std::max(y - reach, win.y0 - 1); yy <= std::min(y + reach, win.y0 + win.h) && !near; ++yy)
                for (int xx = std::max(x - reach, win.x0 - 1); xx <= std::min(x + reach, win.x0 + win.w) && !near; ++xx) {
                  if (!tileable && (xx < 0 || yy < 0 || xx >= s.width || yy >= s.height)) continue;
                  const Coord q = s.at((xx + s.width) % s.width, (yy + s.height) % s.height);
                  near = q == Coord{xx + alpha.u, yy + alpha.v};
                }
              if (near && c.u >= lo.u && c.v >= lo.v && c.u <= hi.u && c.v <= hi.v && !(c == s.at(x, y)))
                free.push_back(std::size_t(y) * s.width + x);
            }
          const double before = cut.energy(s, start);
          double best = before;
          for (unsigned m = 0; m < (1u << free.size()); ++m) {
            CoordImage t = s;
            for (std::size_t k = 0; k < free.size(); ++k)
              if (m >> k & 1u) {
                const int x = int(free[k] % std::size_t(s.width)), y = int(free[k] / std::size_t(s.width));
                t.s[free[k]] = {x + alpha.u, y + alpha.v};
              }
            best = std::min(best, cut.energy(t, start));
          }
          const double delta = cut.expand(s, start, win, alpha, footed ? &foot : nullptr);
          const double after = cut.energy(s, start);
          EXPECT_LE(delta, 0.0);
          EXPECT_NEAR(after, before + delta, 1e-4);
          EXPECT_NEAR(after, best, 1e-4) << "tileable " << tileable << " leave " << leave << " reach " << reach
                                         << " seed " << seed;
        }
      }
}

TEST(ImageSeamCut, WindowsOfAClassNeverTouchAndCoverEveryPixelOnce) {
  const Image ex = disc_texture(16, 16, 3, 62);
  for (bool tileable : {false, true})
    for (int w : {5, 8, 13, 40})
      for (int pass : {0, 1}) {
        const SeamCutter cut(ex, {0, 0}, {15, 15}, cutting(2, 4, 0), tileable);
        const CoordImage s{w, 11, std::vector<Coord>(std::size_t(w) * 11)};
        std::vector<int> covered(s.s.size(), 0);
        for (const auto& cls : cut.windows(s, pass)) {
          std::vector<int> owner(s.s.size(), -1);
          auto wrap = [&](int x, int y) { return std::size_t((y + s.height) % s.height) * w + std::size_t((x + w) % w); };
          for (std::size_t k = 0; k < cls.size(); ++k)
            for (int y = cls[k].y0; y < cls[k].y0 + cls[k].h; ++y)
              for (int x = cls[k].x0; x < cls[k].x0 + cls[k].w; ++x) {
                ++covered[wrap(x, y)];
                owner[wrap(x, y)] = int(k);
              }
          // No window's border (or inside) holds another window's pixel of the same class.
          for (std::size_t k = 0; k < cls.size(); ++k)
            for (int y = cls[k].y0 - 1; y <= cls[k].y0 + cls[k].h; ++y)
              for (int x = cls[k].x0 - 1; x <= cls[k].x0 + cls[k].w; ++x) {
                if (!tileable && (x < 0 || y < 0 || x >= w || y >= s.height)) continue;
                const int o = owner[wrap(x, y)];
                EXPECT_TRUE(o < 0 || o == int(k)) << "tileable " << tileable << " width " << w << " pass " << pass;
              }
        }
        for (int c : covered) EXPECT_EQ(c, 1) << "tileable " << tileable << " width " << w << " pass " << pass;
      }
}

TEST(ImageSeamCut, NeverRaisesTheEnergyAndLowersIt) {
  const Image ex = disc_texture(24, 24, 3, 63);
  const Coord lo{2, 2}, hi{21, 21};
  for (bool tileable : {false, true})
    for (double leave : {0.0, 0.5}) {
      const SeamCutter cut(ex, lo, hi, cutting(3, 8, leave), tileable);
      CoordImage s = random_coords(29, 23, lo, hi, 5);
      const CoordImage start = s;
      std::vector<double> energy;
      cut.run(s, nullptr, 0, 1, &energy);
      ASSERT_EQ(energy.size(), 3u);
      const double before = cut.energy(start, start) / double(s.s.size());
      EXPECT_LT(energy[0], before);
      EXPECT_LE(energy[1], energy[0]);
      EXPECT_LE(energy[2], energy[1]);
      EXPECT_NEAR(energy[2], cut.energy(s, start) / double(s.s.size()), 1e-9);
      for (const Coord& c : s.s) EXPECT_TRUE(c.u >= lo.u && c.v >= lo.v && c.u <= hi.u && c.v <= hi.v);
    }
}

TEST(ImageSeamCut, SameSeedSameImageOnOneTwoAndEightThreads) {
  const Image ex = disc_texture(32, 32, 3, 64);
  for (bool tileable : {false, true})
  for (bool matches : {false, true}) {
    ImageSynthesisOptions o = small_cut_image();
    o.tileable = tileable;
    o.coordinates.jitter = 0.5;
    o.coordinates.cut_matches = matches;  // the PatchMatch sources as alpha too
    o.coordinates.refine_patch = 6;
    const Image one = exsynth::testing::on_threads(1, [&] { return synthesize_image(ex, o); });
    const Image two = exsynth::testing::on_threads(2, [&] { return synthesize_image(ex, o); });
    const Image eight = exsynth::testing::on_threads(8, [&] { return synthesize_image(ex, o); });
    EXPECT_EQ(one.values(), two.values());
    EXPECT_EQ(one.values(), eight.values());
    o.coordinates.cut_passes = 0;
    EXPECT_NE(synthesize_image(ex, o).values(), one.values());  // the cuts changed something
  }
}

TEST(ImageSeamCut, EveryPixelIsAnExemplarPixel) {
  const Image ex = disc_texture(24, 20, 2, 65);
  ImageSynthesisOptions o = small_cut_image();
  o.width = 41;
  o.height = 5;
  const Image out = synthesize_image(ex, o);
  for (std::size_t p = 0; p < out.pixel_count(); ++p) {
    bool found = false;
    for (std::size_t q = 0; q < ex.pixel_count() && !found; ++q)
      found = out.data()[p * 2] == ex.data()[q * 2] && out.data()[p * 2 + 1] == ex.data()[q * 2 + 1];
    ASSERT_TRUE(found) << "pixel " << p;
  }
}

TEST(ImageSeamCut, CancelInEveryStage) {
  const Image ex = disc_texture(32, 32, 3, 66);
  ImageSynthesisOptions o = small_cut_image();
  o.coordinates.cut_matches = true;
  o.coordinates.refine_patch = 6;
  const auto job = [&](ExecContext* ctx) { synthesize_image(ex, o, ctx); };
  const auto log = exsynth::testing::stages_of(job);
  ASSERT_GE(log.names.size(), 4u);
  EXPECT_NEAR(log.final_progress, 1.0, 1e-9);
  EXPECT_TRUE(std::is_sorted(log.start_progress.begin(), log.start_progress.end()));
  EXPECT_THAT(log.names.back(), HasSubstr("seam cuts"));
  for (const std::string& stage : log.names) {
    const auto outcome = exsynth::testing::cancel_in_stage(job, stage);
    EXPECT_TRUE(outcome.threw_cancelled) << stage;
    EXPECT_EQ(outcome.stage_at_throw, stage);
  }
}

TEST(ImageSeamCut, BadOptionsNameTheOption) {
  const Image ex = disc_texture(16, 16, 3, 67);
  auto message = [&](auto change) {
    ImageSynthesisOptions o = small_cut_image();
    change(o);
    return exsynth::testing::invalid_input_message([&] { synthesize_image(ex, o); });
  };
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_passes = 17; }), HasSubstr("cut_passes must be between 0 and 16"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_window = 3; }), HasSubstr("cut_window must be between 4 and 256"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_labels = 0; }), HasSubstr("cut_labels must be between 1 and 256"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_leave = -0.5; }), HasSubstr("cut_leave must be between 0 and"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_leave = std::nan(""); }), HasSubstr("cut_leave must be"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_reach = -1; }), HasSubstr("cut_reach must be between 0 and 256"));
  EXPECT_THAT(message([](auto& o) { o.coordinates.cut_radius = 5; }), HasSubstr("cut_radius must be between 0 and 4"));
}
