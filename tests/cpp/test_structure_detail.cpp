// structure_sigma (solid/structure_detail.hpp): the separable blur against a
// brute-force 3D convolution, the rank histogram match against the
// exemplar's quantiles, and the option through synthesize_solid
// (determinism, cancel, constraint, bad values).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "exsynth/rng.hpp"
#include "exsynth/solid.hpp"
#include "solid/structure_detail.hpp"
#include "support/cancel.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using exsynth::testing::disc_texture;
using exsynth::testing::one_exemplar;
using ::testing::HasSubstr;

namespace {

Volume random_volume(int nx, int ny, int nz, int channels, std::uint64_t seed) {
  Volume v(nx, ny, nz, channels);
  for (std::size_t i = 0; i < v.values().size(); ++i) v.values()[i] = float(IndexRng(seed, i).uniform());
  return v;
}

// The 3D Gaussian as one sum over the (2r + 1)^3 box, weights exp(-d^2 / 2s^2)
// normalised per axis as the separable blur's (the product of three 1-D kernels).
Volume brute_force_blur(const Volume& v, double sigma, Boundary b, int channels) {
  const int r = std::max(1, int(std::ceil(3 * sigma)));
  std::vector<double> k(2 * r + 1);
  double sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[i + r] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& w : k) w /= sum;
  const int n[3] = {v.nx(), v.ny(), v.nz()};
  auto index = [&](int i, int a) {
    return b == Boundary::Wrap ? ((i % n[a]) + n[a]) % n[a] : std::clamp(i, 0, n[a] - 1);
  };
  const int rz = n[2] > 1 ? r : 0;  // one voxel thick (an image): no blur across
  Volume out = v;
  for (int z = 0; z < n[2]; ++z)
    for (int y = 0; y < n[1]; ++y)
      for (int x = 0; x < n[0]; ++x)
        for (int c = 0; c < channels; ++c) {
          double acc = 0;
          for (int dz = -rz; dz <= rz; ++dz)
            for (int dy = -r; dy <= r; ++dy)
              for (int dx = -r; dx <= r; ++dx)
                acc += (rz ? k[dz + r] : 1.0) * k[dy + r] * k[dx + r] *
                       v.at(index(x + dx, 0), index(y + dy, 1), index(z + dz, 2), c);
          out.at(x, y, z, c) = float(acc);
        }
  return out;
}

SolidOptions split_options() {
  SolidOptions o;
  o.method = SolidMethod::Optimization;
  o.size = 24;
  o.levels = 2;
  o.iterations = 2;
  o.seed = 9;
  o.rotate_exemplar = RotateExemplar::Off;  // the exemplar itself is the histogram's target
  o.structure_sigma = 1.0;
  return o;
}

}  // namespace

TEST(StructureDetail, BlurIsTheBruteForceGaussianOnEveryBoundary) {
  for (Boundary b : {Boundary::Wrap, Boundary::Clamp})
    for (double sigma : {0.7, 1.5}) {
      const Volume v = random_volume(7, 5, 6, 3, 4);
      Volume blurred = v;
      StageProgress progress(nullptr, "blur", 0, 1, solid::blur_units(v));
      solid::gaussian_blur(blurred, sigma, b, 2, progress);  // the third channel is left alone
      const Volume expected = brute_force_blur(v, sigma, b, 2);
      for (std::size_t i = 0; i < v.voxel_count(); ++i) {
        for (int c = 0; c < 2; ++c) ASSERT_NEAR(blurred.data()[i * 3 + c], expected.data()[i * 3 + c], 1e-5) << i;
        ASSERT_EQ(blurred.data()[i * 3 + 2], v.data()[i * 3 + 2]) << i;
      }
    }
}

TEST(StructureDetail, BlurOfAnImageStaysInItsPlane) {
  const Volume v = random_volume(9, 8, 1, 1, 5);
  Volume blurred = v;
  StageProgress progress(nullptr, "blur", 0, 1, solid::blur_units(v));
  solid::gaussian_blur(blurred, 1.0, Boundary::Wrap, 1, progress);
  const Volume expected = brute_force_blur(v, 1.0, Boundary::Wrap, 1);
  for (std::size_t i = 0; i < v.voxel_count(); ++i) ASSERT_NEAR(blurred.data()[i], expected.data()[i], 1e-5) << i;
}

TEST(StructureDetail, HistogramMatchGivesTheExemplarsQuantilesInTheVolumesOrder) {
  const Volume v = random_volume(6, 5, 4, 2, 6);
  const Image a = disc_texture(9, 7, 2, 1), b = disc_texture(5, 4, 2, 2);
  Volume matched = v;
  StageProgress progress(nullptr, "match", 0, 1, 2);
  solid::match_histograms(matched, 1, {&a, &b}, progress);
  std::vector<float> target;
  for (const Image* img : {&a, &b})
    for (std::size_t p = 0; p < img->pixel_count(); ++p) target.push_back(img->data()[p * 2]);
  std::sort(target.begin(), target.end());
  const std::size_t N = v.voxel_count();
  // the voxels in the order of their values (ties: lower index first)
  std::vector<std::size_t> order(N);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return v.data()[i * 2] < v.data()[j * 2]; });
  for (std::size_t r = 0; r < N; ++r) {
    const std::size_t q = std::min(target.size() - 1, std::size_t((r + 0.5) * target.size() / N));
    ASSERT_EQ(matched.data()[order[r] * 2], target[q]) << "rank " << r;
    ASSERT_EQ(matched.data()[order[r] * 2 + 1], v.data()[order[r] * 2 + 1]);  // channel 1 untouched
  }
}

// The option is the split of the two solids the engine makes without it:
// the exemplar values (structure_sigma 0) and the weighted mean
// (exemplar_values off), whose matches are the same.
TEST(StructureDetail, SolidIsTheSplitOfItsMeanAndItsExemplarValues) {
  const Image ex = disc_texture(32, 32, 3, 23);
  const SolidOptions o = split_options();
  SolidOptions values_only = o, mean_only = o;
  values_only.structure_sigma = 0;
  mean_only.exemplar_values = false;
  Volume values = synthesize_solid(one_exemplar(ex), values_only).texture;
  Volume mean = synthesize_solid(one_exemplar(ex), mean_only).texture;
  EXPECT_NE(values.values(), mean.values());
  StageProgress progress(nullptr, "split", 0, 1, solid::split_units(values, 3));
  solid::split_structure_detail(values, std::move(mean), o.structure_sigma, Boundary::Wrap, 3, {&ex}, progress);
  const TextureResult split = synthesize_solid(one_exemplar(ex), o);
  EXPECT_EQ(split.texture.values(), values.values());
}

TEST(StructureDetail, SameSolidOnOneTwoAndEightThreads) {
  const Image ex = disc_texture(32, 32, 3, 23);
  auto run = [&] { return synthesize_solid(one_exemplar(ex), split_options()).texture; };
  const Volume one = exsynth::testing::on_threads(1, run);
  EXPECT_EQ(one.values(), exsynth::testing::on_threads(2, run).values());
  EXPECT_EQ(one.values(), exsynth::testing::on_threads(8, run).values());
}

TEST(StructureDetail, CancelInsideTheSplit) {
  const Image ex = disc_texture(32, 32, 3, 23);
  const SolidOptions o = split_options();
  const auto outcome = exsynth::testing::cancel_in_stage(
      [&](ExecContext* ctx) { synthesize_solid(one_exemplar(ex), o, ctx); }, "solid: structure and detail");
  EXPECT_TRUE(outcome.threw_cancelled);
  EXPECT_EQ(outcome.stage_at_throw, "solid: structure and detail");
}

TEST(StructureDetail, TheConstraintStillWins) {
  const Image ex = disc_texture(32, 32, 3, 23);
  const SolidOptions o = split_options();
  const float target[3] = {0.9f, 0.1f, 0.4f};
  const Volume r = synthesize_solid(exsynth::testing::pinned_corner(ex, o.size, 5, target), o).texture;
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.at(x, y, z, c), target[c], 1e-6) << x << " " << y << " " << z;
}

TEST(StructureDetail, BadSigmaNamesTheOption) {
  const Image ex = disc_texture(32, 32, 3, 23);
  for (double sigma : {-1.0, kMaxStructureSigma + 1}) {
    SolidOptions o = split_options();
    o.structure_sigma = sigma;
    try {
      synthesize_solid(one_exemplar(ex), o);
      FAIL() << "accepted structure_sigma " << sigma;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr("structure_sigma must be between 0"));
    }
  }
}
