// rotate_exemplar: the exemplar in its four quarter turns (docs/solid.md,
// fourteenth pass). The mosaic against explicit turns; the feature channel
// turned with it; the solver's texels coming from every turn.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "exsynth/solid.hpp"
#include "solid/exemplar_rotations.hpp"
#include "solid/feature_channel.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using namespace exsynth::testing;

namespace {

// The square `sq` (edge s) turned q x 90 degrees clockwise, pixel (x, y):
// written out per turn, not by repeating one turn as the mosaic does.
float turned(const Image& sq, int q, int x, int y, int c) {
  const int s = sq.width();
  switch (q) {
    case 0: return sq.at(x, y, c);
    case 1: return sq.at(y, s - 1 - x, c);          // clockwise: the left column becomes the top row
    case 2: return sq.at(s - 1 - x, s - 1 - y, c);
    default: return sq.at(s - 1 - y, x, c);
  }
}

Image crop(const Image& img, int x0, int y0, int s) {
  Image out(s, s, img.channels());
  for (int y = 0; y < s; ++y)
    for (int x = 0; x < s; ++x)
      for (int c = 0; c < img.channels(); ++c) out.at(x, y, c) = img.at(x0 + x, y0 + y, c);
  return out;
}

SolidOptions small_rotated_options() {
  SolidOptions o;
  o.method = SolidMethod::Optimization;
  o.size = 24;
  o.levels = 2;
  o.iterations = 2;
  o.seed = 9;
  o.rotate_exemplar = RotateExemplar::On;
  return o;
}

}  // namespace

TEST(ExemplarRotations, MosaicHoldsTheCentralSquaresFourTurns) {
  const Image ex = random_image(7, 4, 2, 3);  // wide: the central 4 x 4 square starts at x = 1
  const Image m = solid::quarter_turn_mosaic(ex);
  ASSERT_EQ(m.width(), 8);
  ASSERT_EQ(m.height(), 8);
  ASSERT_EQ(m.channels(), 2);
  const Image sq = crop(ex, 1, 0, 4);
  for (int q = 0; q < 4; ++q)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 2; ++c)
          EXPECT_EQ(m.at((q & 1) * 4 + x, (q >> 1) * 4 + y, c), turned(sq, q, x, y, c)) << "turn " << q;
  // A tall exemplar: the square is centred vertically.
  const Image tall = random_image(3, 6, 1, 4);
  const Image mt = solid::quarter_turn_mosaic(tall);
  ASSERT_EQ(mt.width(), 6);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_EQ(mt.at(x, y, 0), tall.at(x, y + 1, 0));
}

// Larger squares: quarters of kMaxTurnedTile pixels from the square's
// corners (overlapping), then its four quadrants, each turned once; the
// mosaic never outgrows max(256^2, the square).
TEST(ExemplarRotations, LargeSquaresTurnTheirCornersOrQuadrants) {
  EXPECT_EQ(solid::quarter_turn_tile(100), 100);
  EXPECT_EQ(solid::quarter_turn_tile(128), 128);
  EXPECT_EQ(solid::quarter_turn_tile(200), 128);
  EXPECT_EQ(solid::quarter_turn_tile(256), 128);
  EXPECT_EQ(solid::quarter_turn_tile(520), 260);
  for (const auto& [w, h] : {std::pair{230, 200}, std::pair{300, 261}}) {
    const Image ex = random_image(w, h, 1, 11);
    const int s = std::min(w, h), t = solid::quarter_turn_tile(s);
    const int x0 = (w - s) / 2, y0 = (h - s) / 2;
    const Image m = solid::quarter_turn_mosaic(ex);
    ASSERT_EQ(m.width(), 2 * t);
    ASSERT_EQ(m.height(), 2 * t);
    for (int q = 0; q < 4; ++q) {
      const Image corner = crop(ex, x0 + (q & 1) * (s - t), y0 + (q >> 1) * (s - t), t);
      int wrong = 0;
      for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x) wrong += m.at((q & 1) * t + x, (q >> 1) * t + y, 0) != turned(corner, q, x, y, 0);
      EXPECT_EQ(wrong, 0) << w << "x" << h << ", turn " << q;
    }
  }
}

// The solver turns the exemplar after adding its feature channel; that is
// the feature channel of each turned exemplar (square window, Euclidean
// distances, the global luminance std: all turn with the image).
TEST(ExemplarRotations, TheFeatureChannelTurnsWithTheExemplar) {
  const Image ex = disc_texture(20, 20, 3, 21);
  const Image m = solid::quarter_turn_mosaic(solid::with_feature_channel(ex, 2.0f, 4, 0.5));
  for (int q = 0; q < 4; ++q) {
    Image t(20, 20, 3);
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x)
        for (int c = 0; c < 3; ++c) t.at(x, y, c) = turned(ex, q, x, y, c);
    const Image f = solid::with_feature_channel(t, 2.0f, 4, 0.5);
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x)
        EXPECT_NEAR(m.at((q & 1) * 20 + x, (q >> 1) * 20 + y, 3), f.at(x, y, 3), 1e-5f) << "turn " << q << " at " << x << "," << y;
  }
}

// Every voxel is a texel of the mosaic, where its source says, and the
// texels come from all four turns: the turned copies reach the solver.
TEST(ExemplarRotations, SolidTakesTexelsFromEveryTurn) {
  const Image ex = disc_texture(32, 32, 3, 15);
  const TextureResult r = synthesize_solid(one_exemplar(ex), small_rotated_options());
  const Image m = solid::quarter_turn_mosaic(ex);
  ASSERT_EQ(r.source.size(), r.texture.voxel_count());
  std::array<int, 4> per_turn{};
  for (std::size_t v = 0; v < r.texture.voxel_count(); ++v) {
    ASSERT_GE(r.source[v], 0);
    const std::size_t pix = std::size_t(r.source[v]) & ((std::size_t(1) << 28) - 1);
    ASSERT_LT(pix, m.pixel_count());
    for (int c = 0; c < 3; ++c) ASSERT_EQ(r.texture.values()[v * 3 + c], m.data()[pix * 3 + c]) << "voxel " << v;
    const int x = int(pix % 64), y = int(pix / 64);
    ++per_turn[(x >= 32) + 2 * (y >= 32)];
  }
  for (int q = 0; q < 4; ++q) EXPECT_GT(per_turn[q], int(r.texture.voxel_count() / 20)) << "turn " << q;
  SolidOptions plain = small_rotated_options();
  plain.rotate_exemplar = RotateExemplar::Off;
  EXPECT_NE(synthesize_solid(one_exemplar(ex), plain).texture.values(), r.texture.values());
}

TEST(ExemplarRotations, SameSolidOnAnyThreadCount) {
  const Image ex = disc_texture(32, 32, 3, 15);
  const auto run = [&] { return synthesize_solid(one_exemplar(ex), small_rotated_options()).texture.values(); };
  const std::vector<float> one = on_threads(1, run);
  EXPECT_EQ(on_threads(3, run), one);
  EXPECT_EQ(on_threads(8, run), one);
}

// rotate_exemplar = Auto decides on exemplar_feature_stretch (exsynth.quality's
// lobe_stretch, which the Python tier compares it with): round features near
// 1, a blob stretched 3:1 well above kRoundFeatureStretch, the same stretch
// whatever the turn, and a flat exemplar counted as round.
namespace {

Image blobs(int s, double sx, double sy) {  // Gaussian blobs on a lattice, sx x sy pixels
  Image img(s, s, 1);
  for (int y = 0; y < s; ++y)
    for (int x = 0; x < s; ++x) {
      double v = 0.0;
      for (int cy = 8; cy < s; cy += 16)
        for (int cx = 8 + (cy / 16 % 2) * 8; cx < s + 8; cx += 16) {
          const double dx = (x - cx) / sx, dy = (y - cy) / sy;
          v += std::exp(-0.5 * (dx * dx + dy * dy));
        }
      img.at(x, y, 0) = float(v);
    }
  return img;
}

}  // namespace

TEST(ExemplarRotations, FeatureStretchTellsRoundFromStretchedFeatures) {
  const double round = exemplar_feature_stretch(blobs(64, 2.0, 2.0));
  const Image long_blobs = blobs(64, 4.5, 1.5);
  const double stretched = exemplar_feature_stretch(long_blobs);
  EXPECT_LT(round, 1.1);
  EXPECT_GT(stretched, 2.0);
  EXPECT_LT(round, kRoundFeatureStretch);
  EXPECT_GT(stretched, kRoundFeatureStretch);
  const Image turned_blobs = solid::quarter_turn_mosaic(long_blobs);  // its top right quarter: a quarter turn
  EXPECT_NEAR(exemplar_feature_stretch(crop(turned_blobs, 64, 0, 64)), stretched, 1e-9);
  EXPECT_EQ(exemplar_feature_stretch(Image(16, 16, 3)), 1.0);  // flat: no direction
}

TEST(ExemplarRotations, AutoTurnsRoundExemplarsOnly) {
  SolidExemplars ex;
  const Image round = blobs(48, 2.0, 2.0), stretched = blobs(48, 4.5, 1.5);
  ex.views = {round, stretched, stretched};
  SolidOptions o = small_rotated_options();
  o.rotate_exemplar = RotateExemplar::Auto;
  const TextureResult auto_result = synthesize_solid(ex, o);
  EXPECT_EQ(auto_result.rotated_exemplar, (std::array<bool, 3>{true, false, false}));
  o.rotate_exemplar = RotateExemplar::On;
  EXPECT_EQ(synthesize_solid(ex, o).rotated_exemplar, (std::array<bool, 3>{true, true, true}));
  o.rotate_exemplar = RotateExemplar::Off;
  EXPECT_EQ(synthesize_solid(ex, o).rotated_exemplar, (std::array<bool, 3>{false, false, false}));
  EXPECT_EQ(rotate_exemplar_from_name("auto"), RotateExemplar::Auto);
  EXPECT_STREQ(rotate_exemplar_name(RotateExemplar::On), "on");
  EXPECT_THROW(rotate_exemplar_from_name("yes"), InvalidInput);
}
