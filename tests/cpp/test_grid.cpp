// Sampling, resizing and Gaussian pyramids of images and volumes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/exec_context.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/sample.hpp"
#include "support/textures.hpp"

namespace {

using exsynth::Boundary;
using exsynth::Image;
using exsynth::Volume;
using exsynth::testing::random_image;

Volume random_volume(int nx, int ny, int nz, int c, std::uint64_t seed) {
  Volume vol(nx, ny, nz, c);
  for (std::size_t i = 0; i < vol.values().size(); ++i) {
    vol.values()[i] = float(exsynth::IndexRng(seed, i).uniform());
  }
  return vol;
}

int ref_index(int i, int n, Boundary b) {
  if (b == Boundary::Wrap) return ((i % n) + n) % n;
  return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

const double kTap[5] = {1 / 16.0, 4 / 16.0, 6 / 16.0, 4 / 16.0, 1 / 16.0};

// Direct (non-separable) 5x5 blur evaluated at the kept samples.
Image reference_downsample(const Image& img, Boundary b) {
  Image out((img.width() + 1) / 2, (img.height() + 1) / 2, img.channels());
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < img.channels(); ++c) {
        double s = 0;
        for (int j = 0; j < 5; ++j)
          for (int i = 0; i < 5; ++i)
            s += kTap[i] * kTap[j] *
                 img.at(ref_index(2 * x + i - 2, img.width(), b),
                        ref_index(2 * y + j - 2, img.height(), b), c);
        out.at(x, y, c) = float(s);
      }
  return out;
}

Volume reference_downsample(const Volume& vol, Boundary b) {
  Volume out((vol.nx() + 1) / 2, (vol.ny() + 1) / 2, (vol.nz() + 1) / 2, vol.channels());
  for (int z = 0; z < out.nz(); ++z)
    for (int y = 0; y < out.ny(); ++y)
      for (int x = 0; x < out.nx(); ++x)
        for (int c = 0; c < vol.channels(); ++c) {
          double s = 0;
          for (int k = 0; k < 5; ++k)
            for (int j = 0; j < 5; ++j)
              for (int i = 0; i < 5; ++i)
                s += kTap[i] * kTap[j] * kTap[k] *
                     vol.at(ref_index(2 * x + i - 2, vol.nx(), b),
                            ref_index(2 * y + j - 2, vol.ny(), b),
                            ref_index(2 * z + k - 2, vol.nz(), b), c);
          out.at(x, y, z, c) = float(s);
        }
  return out;
}

// ---- sampling ---------------------------------------------------------------

TEST(Sample, BilinearIsExactOnLinearFunctions) {
  Image img(7, 5, 2);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      img.at(x, y, 0) = 2.0f * x + 3.0f * y + 1.0f;
      img.at(x, y, 1) = -0.5f * x + 0.25f * y;
    }
  for (Boundary b : {Boundary::Clamp, Boundary::Wrap}) {
    for (double y = 0; y <= 4.0; y += 0.37)
      for (double x = 0; x <= 6.0; x += 0.41) {
        EXPECT_NEAR(exsynth::sample_bilinear(img, x, y, 0, b), 2 * x + 3 * y + 1, 1e-5);
        EXPECT_NEAR(exsynth::sample_bilinear(img, x, y, 1, b), -0.5 * x + 0.25 * y, 1e-5);
      }
  }
}

// A volume whose voxel (x, y, z) holds f(x, y, z, c) in channel c.
template <class F>
Volume volume_of(int nx, int ny, int nz, int channels, F f) {
  Volume vol(nx, ny, nz, channels);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        for (int c = 0; c < channels; ++c) vol.at(x, y, z, c) = float(f(x, y, z, c));
  return vol;
}

TEST(Sample, TrilinearIsExactOnLinearFunctions) {
  auto f = [](double x, double y, double z, int c) {
    return (c + 1) * x - 2.0 * y + 0.5 * z + c;
  };
  const Volume vol = volume_of(5, 6, 4, 3, f);
  float all[3];
  for (double z = 0; z <= 3.0; z += 0.43)
    for (double y = 0; y <= 5.0; y += 0.61)
      for (double x = 0; x <= 4.0; x += 0.29) {
        exsynth::sample_trilinear(vol, x, y, z, all);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(exsynth::sample_trilinear(vol, x, y, z, c), f(x, y, z, c), 1e-5);
          EXPECT_NEAR(all[c], f(x, y, z, c), 1e-5);
        }
      }
}

// Catmull-Rom reproduces polynomials up to degree 2 exactly: on a smooth,
// monotone function away from the edges the range limit never binds.
TEST(Sample, TricubicIsExactOnQuadraticsAndKeepsCentres) {
  auto f = [](double x, double y, double z, int c) { return 0.3 * x * x + 0.2 * y * y + (c + 1) * 0.15 * z * z + x + c; };
  const Volume vol = volume_of(7, 6, 8, 2, f);
  float got[2];
  for (double z = 1.0; z <= 6.0; z += 0.37)
    for (double y = 1.0; y <= 4.0; y += 0.41)
      for (double x = 1.0; x <= 5.0; x += 0.29) {
        exsynth::sample_tricubic(vol, x, y, z, got);
        for (int c = 0; c < 2; ++c) EXPECT_NEAR(got[c], f(x, y, z, c), 1e-4) << x << " " << y << " " << z;
      }
  const Volume noise = random_volume(5, 4, 6, 2, 9);
  for (Boundary b : {Boundary::Clamp, Boundary::Wrap}) {
    exsynth::sample_tricubic(noise, 3.0, 1.0, 4.0, got, b);
    EXPECT_FLOAT_EQ(got[1], noise.at(3, 1, 4, 1));
  }
}

// Each channel lies within the 8 nearest voxels' values (no halo), and the
// wrap boundary repeats with the volume's period.
TEST(Sample, TricubicStaysInTheCellsRangeAndWraps) {
  const Volume vol = random_volume(4, 5, 6, 1, 11);
  float got = 0.0f, again = 0.0f;
  for (double z = -0.9; z < 5.0; z += 0.53)
    for (double y = -0.7; y < 4.0; y += 0.47)
      for (double x = -0.3; x < 3.0; x += 0.31) {
        exsynth::sample_tricubic(vol, x, y, z, &got, Boundary::Wrap);
        exsynth::sample_tricubic(vol, x + 4.0, y - 10.0, z + 6.0, &again, Boundary::Wrap);
        EXPECT_NEAR(got, again, 1e-5);
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y)), z0 = int(std::floor(z));
        float lo = 1e9f, hi = -1e9f;
        for (int k = 0; k < 2; ++k)
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
              const float v = vol.at((x0 + i + 4) % 4, (y0 + j + 5) % 5, (z0 + k + 6) % 6);
              lo = std::min(lo, v), hi = std::max(hi, v);
            }
        EXPECT_GE(got, lo);
        EXPECT_LE(got, hi);
      }
  EXPECT_EQ(exsynth::interpolation_from_name("cubic", "interpolation"), exsynth::Interpolation::Cubic);
  EXPECT_THROW(exsynth::interpolation_from_name("bicubic", "interpolation"), exsynth::InvalidInput);
}

TEST(Sample, ClampHoldsEdgeValues) {
  Image img = random_image(4, 3, 1, 1);
  EXPECT_FLOAT_EQ(exsynth::sample_bilinear(img, -5.0, 1.0, 0), img.at(0, 1));
  EXPECT_FLOAT_EQ(exsynth::sample_bilinear(img, 3.7, -0.2, 0), img.at(3, 0));
  EXPECT_FLOAT_EQ(exsynth::sample_bilinear(img, 100.0, 100.0, 0), img.at(3, 2));
  Volume vol = random_volume(3, 4, 5, 1, 2);
  EXPECT_FLOAT_EQ(exsynth::sample_trilinear(vol, -1.0, 9.0, 2.0, 0), vol.at(0, 3, 2));
}

TEST(Sample, WrapIsToroidalIncludingNegativeCoordinates) {
  Image img = random_image(4, 3, 1, 3);
  // Halfway between the last and the first column.
  EXPECT_NEAR(exsynth::sample_bilinear(img, -0.5, 1.0, 0, Boundary::Wrap),
              0.5 * (img.at(3, 1) + img.at(0, 1)), 1e-6);
  EXPECT_NEAR(exsynth::sample_bilinear(img, 3.5, 1.0, 0, Boundary::Wrap),
              0.5 * (img.at(3, 1) + img.at(0, 1)), 1e-6);
  for (double x : {0.3, 1.7, 2.9})
    for (double y : {0.1, 1.4, 2.6})
      for (int k : {-3, -1, 1, 5}) {
        EXPECT_NEAR(exsynth::sample_bilinear(img, x + 4 * k, y - 3 * k, 0, Boundary::Wrap),
                    exsynth::sample_bilinear(img, x, y, 0, Boundary::Wrap), 1e-5);
      }
  Volume vol = random_volume(3, 4, 5, 2, 4);
  EXPECT_NEAR(exsynth::sample_trilinear(vol, -3.0 + 1.25, 4.0 + 0.5, -10.0 + 2.0, 1, Boundary::Wrap),
              exsynth::sample_trilinear(vol, 1.25, 0.5, 2.0, 1, Boundary::Wrap), 1e-5);
  // Clamp and wrap differ past the edge.
  EXPECT_NE(exsynth::sample_trilinear(vol, -0.5, 1.0, 1.0, 0, Boundary::Wrap),
            exsynth::sample_trilinear(vol, -0.5, 1.0, 1.0, 0, Boundary::Clamp));
}

TEST(Sample, ResizeScalesPositionsBySizeRatio) {
  exsynth::GridTransform xf;
  xf.origin = {1.0, 2.0, 3.0};
  xf.voxel_size = 0.5;
  Volume vol(4, 4, 4, 1, 0.0f, xf);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) vol.at(x, y, z) = float(x + 10 * y + 100 * z);
  Volume up = exsynth::resize_trilinear(vol, 8, 8, 8);
  ASSERT_EQ(up.nx(), 8);
  ASSERT_EQ(up.nz(), 8);
  EXPECT_DOUBLE_EQ(up.transform().voxel_size, 0.25);
  EXPECT_EQ(up.transform().origin, xf.origin);
  for (int z = 0; z < 7; ++z)
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 7; ++x)
        EXPECT_NEAR(up.at(x, y, z), x / 2.0 + 10 * y / 2.0 + 100 * z / 2.0, 1e-4);
  Volume same = exsynth::resize_trilinear(vol, 4, 4, 4);
  EXPECT_EQ(same.values(), vol.values());
}

// ---- pyramids -----------------------------------------------------------------

TEST(Pyramid, ConstantStaysConstant) {
  for (Boundary b : {Boundary::Clamp, Boundary::Wrap}) {
    Image img(9, 6, 2, 0.75f);
    for (const Image& level : exsynth::gaussian_pyramid(img, {4, b}))
      for (float v : level.values()) EXPECT_NEAR(v, 0.75f, 1e-6);
    Volume vol(7, 5, 6, 3, -2.5f);
    for (const Volume& level : exsynth::gaussian_pyramid(vol, {3, b}))
      for (float v : level.values()) EXPECT_NEAR(v, -2.5f, 1e-6);
  }
}

TEST(Pyramid, SizesHalveRoundingUpAndStopAtOne) {
  auto levels = exsynth::gaussian_pyramid(Image(9, 5, 1), {5});
  ASSERT_EQ(levels.size(), 5u);
  const int w[] = {9, 5, 3, 2, 1}, h[] = {5, 3, 2, 1, 1};
  for (int l = 0; l < 5; ++l) {
    EXPECT_EQ(levels[l].width(), w[l]);
    EXPECT_EQ(levels[l].height(), h[l]);
    EXPECT_EQ(levels[l].channels(), 1);
  }
  auto vlevels = exsynth::gaussian_pyramid(Volume(8, 3, 1, 2), {3});
  ASSERT_EQ(vlevels.size(), 3u);
  EXPECT_EQ(vlevels[1].nx(), 4);
  EXPECT_EQ(vlevels[1].ny(), 2);
  EXPECT_EQ(vlevels[1].nz(), 1);
  EXPECT_EQ(vlevels[2].nx(), 2);
  EXPECT_EQ(vlevels[2].ny(), 1);
  EXPECT_EQ(vlevels[2].channels(), 2);
  EXPECT_EQ(exsynth::gaussian_pyramid(Image(3, 3, 1), {1}).size(), 1u);
}

TEST(Pyramid, RejectsBadLevels) {
  try {
    exsynth::gaussian_pyramid(Image(4, 4, 1), {0});
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("levels"), std::string::npos) << e.what();
  }
  EXPECT_THROW(exsynth::gaussian_pyramid(Volume(4, 4, 4, 1), {-1}), exsynth::InvalidInput);
  EXPECT_THROW(exsynth::gaussian_pyramid(Volume(), {2}), exsynth::InvalidInput);
}

TEST(Pyramid, ImageDownsampleMatchesBruteForceBlur) {
  for (Boundary b : {Boundary::Clamp, Boundary::Wrap}) {
    for (auto [w, h] : {std::pair{7, 6}, std::pair{8, 5}, std::pair{1, 3}, std::pair{2, 2}}) {
      Image img = random_image(w, h, 2, 10 + w * 7 + h);
      Image got = exsynth::downsample(img, b);
      Image want = reference_downsample(img, b);
      ASSERT_EQ(got.width(), want.width());
      ASSERT_EQ(got.height(), want.height());
      for (std::size_t i = 0; i < got.values().size(); ++i)
        EXPECT_NEAR(got.values()[i], want.values()[i], 1e-6) << "w=" << w << " h=" << h << " i=" << i;
    }
  }
}

TEST(Pyramid, VolumeDownsampleMatchesBruteForceBlur) {
  for (Boundary b : {Boundary::Clamp, Boundary::Wrap}) {
    Volume vol = random_volume(5, 6, 7, 2, 99);
    Volume got = exsynth::downsample(vol, b);
    Volume want = reference_downsample(vol, b);
    ASSERT_EQ(got.nx(), 3);
    ASSERT_EQ(got.ny(), 3);
    ASSERT_EQ(got.nz(), 4);
    for (std::size_t i = 0; i < got.values().size(); ++i)
      EXPECT_NEAR(got.values()[i], want.values()[i], 1e-6) << "i=" << i;
  }
}

TEST(Pyramid, WrapCommutesWithEvenShifts) {
  // On a torus, shifting the input by 2 shifts the output by exactly 1.
  Image img = random_image(8, 6, 1, 5);
  Image shifted(8, 6, 1);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) shifted.at((x + 2) % 8, y) = img.at(x, y);
  Image a = exsynth::downsample(img, Boundary::Wrap);
  Image b = exsynth::downsample(shifted, Boundary::Wrap);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_NEAR(b.at((x + 1) % 4, y), a.at(x, y), 1e-6);
}

TEST(Pyramid, VolumeLevelsKeepOriginAndDoubleVoxelSize) {
  exsynth::GridTransform xf;
  xf.origin = {-1.0, 0.5, 2.0};
  xf.voxel_size = 0.125;
  Volume vol(8, 8, 8, 1, 1.0f, xf);
  auto levels = exsynth::gaussian_pyramid(vol, {3});
  for (int l = 0; l < 3; ++l) {
    EXPECT_EQ(levels[l].transform().origin, xf.origin);
    EXPECT_DOUBLE_EQ(levels[l].transform().voxel_size, 0.125 * (1 << l));
  }
}

TEST(Pyramid, DeterministicAndReportsProgress) {
  Volume vol = random_volume(17, 9, 12, 2, 7);
  exsynth::ExecContext ctx;
  auto a = exsynth::gaussian_pyramid(vol, {3, Boundary::Wrap}, &ctx);
  auto b = exsynth::gaussian_pyramid(vol, {3, Boundary::Wrap});
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t l = 0; l < a.size(); ++l) EXPECT_EQ(a[l].values(), b[l].values());
  EXPECT_EQ(ctx.stage(), "pyramid");
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);
}

TEST(Pyramid, Cancelled) {
  exsynth::ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(exsynth::gaussian_pyramid(random_image(16, 16, 1, 1), {3}, &ctx), exsynth::Cancelled);
  EXPECT_THROW(exsynth::gaussian_pyramid(random_volume(8, 8, 8, 1, 1), {2}, &ctx),
               exsynth::Cancelled);
}

}  // namespace
