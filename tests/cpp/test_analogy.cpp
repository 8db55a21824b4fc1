// Volume analogies (isotropic variant): B' is to B as A' is to A.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "exsynth/analogy.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/rng.hpp"

using namespace exsynth;
using ::testing::HasSubstr;

namespace {

// Random blobs in [0, 1], one to three voxels across: a density that a
// 3x3x3 blur changes a lot.
Volume blobs(int n, std::uint64_t seed, int count = 80) {
  Volume v(n, n, n, 1, 0.0f);
  for (int k = 0; k < count; ++k) {
    IndexRng r(seed, std::uint64_t(k));
    const double cx = r.uniform() * n, cy = r.uniform() * n, cz = r.uniform() * n, rad = 1.0 + 2.0 * r.uniform();
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz);
          v.at(x, y, z) = std::max(v.at(x, y, z), float(std::exp(-d2 / (rad * rad))));
        }
  }
  return v;
}

// 3x3x3 box blur with clamped borders: the analogy A -> A' to learn.
Volume box_blur(const Volume& v) {
  Volume out(v.nx(), v.ny(), v.nz(), 1, 0.0f, v.transform());
  for (int z = 0; z < v.nz(); ++z)
    for (int y = 0; y < v.ny(); ++y)
      for (int x = 0; x < v.nx(); ++x) {
        float s = 0;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              s += v.at(std::clamp(x + dx, 0, v.nx() - 1), std::clamp(y + dy, 0, v.ny() - 1),
                        std::clamp(z + dz, 0, v.nz() - 1));
        out.at(x, y, z) = s / 27.0f;
      }
  return out;
}

double mean_abs_difference(const Volume& a, const Volume& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.values().size(); ++i) s += std::abs(a.values()[i] - b.values()[i]);
  return s / double(a.values().size());
}

// A sphere's signed distance on the grid a pair uses ([-1, 1]^3).
Volume sphere_sdf(const Volume& like, double radius) {
  Volume v(like.nx(), like.ny(), like.nz(), 1, 0.0f, like.transform());
  for (int z = 0; z < v.nz(); ++z)
    for (int y = 0; y < v.ny(); ++y)
      for (int x = 0; x < v.nx(); ++x) {
        const auto p = v.transform().index_to_world(x, y, z);
        v.at(x, y, z) = float(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - radius);
      }
  return v;
}

double inside_volume(const Volume& sdf) {
  std::size_t n = 0;
  for (float s : sdf.values()) n += s < 0;
  return double(n) * std::pow(sdf.transform().voxel_size, 3);
}

}  // namespace

TEST(Analogy, LearnsABlur) {
  const Volume a = blobs(24, 1), b = blobs(24, 2);
  AnalogyOptions opt;
  opt.cull_distance = 0;  // densities, not distances
  const AnalogyResult r = synthesize_analogy(a, box_blur(a), b, opt);
  const Volume want = box_blur(b);
  // B' is clearly closer to the blurred B than B itself is (measured 0.62x:
  // the error left is that of copying values from a 24^3 exemplar, whose
  // nearest 5^3 neighbourhood is never an exact match).
  EXPECT_LT(mean_abs_difference(r.b_prime, want), 0.75 * mean_abs_difference(b, want));
  EXPECT_EQ(r.culled, 0u);
  EXPECT_EQ(r.searched, std::size_t(2) * (24 * 24 * 24 + 12 * 12 * 12));
}

TEST(Analogy, IdentityAnalogyOfBWithItselfReproducesB) {
  // A = A' = B: every voxel's nearest exemplar neighbourhood is its own.
  const Volume b = blobs(16, 4);
  AnalogyOptions opt;
  opt.cull_distance = 0;
  opt.ann_eps = 0;
  const AnalogyResult r = synthesize_analogy(b, b, b, opt);
  EXPECT_LT(mean_abs_difference(r.b_prime, b), 1e-3);
}

TEST(Analogy, DilationPairGrowsBByAboutThePairsRatio) {
  PairOptions po;
  po.resolution = 32;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Dilate, po);
  const double rb = 0.45, d = po.dilation;
  const Volume b = sphere_sdf(pair.a, rb);
  const AnalogyResult r = synthesize_analogy(pair.a, pair.a_prime, b);
  const double want = std::pow((rb + d) / rb, 3.0);
  const double got = inside_volume(r.b_prime) / inside_volume(b);
  EXPECT_NEAR(got, want, 0.2 * want);
  EXPECT_GT(r.culled, 0u);  // far voxels were not searched
}

TEST(Analogy, BadInputNamesTheProblem) {
  auto message = [](const Volume& a, const Volume& ap, const Volume& b, AnalogyOptions o = {}) -> std::string {
    try {
      synthesize_analogy(a, ap, b, o);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "no error";
  };
  const Volume a = blobs(12, 1), b = blobs(12, 2);
  EXPECT_THAT(message(a, blobs(10, 1), b), HasSubstr("same size"));
  EXPECT_THAT(message(a, a, Volume()), HasSubstr("B is empty"));
  EXPECT_THAT(message(a, a, Volume(4, 4, 4, 3)), HasSubstr("1 channel"));
  Volume nan = b;
  nan.at(1, 1, 1) = std::nanf("");
  EXPECT_THAT(message(a, a, nan), HasSubstr("non-finite"));
  AnalogyOptions even;
  even.fine_size = 4;
  EXPECT_THAT(message(a, a, b, even), HasSubstr("fine_size"));
  AnalogyOptions budget;
  budget.memory_budget = 1000;
  EXPECT_THROW(synthesize_analogy(a, a, b, budget), OverBudget);
  ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(synthesize_analogy(a, a, b, {}, &ctx), Cancelled);
}
