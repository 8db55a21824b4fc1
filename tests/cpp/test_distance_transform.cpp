// The separable distance transform and line coverage against brute force.
#include <gtest/gtest.h>

#include <random>

#include "exsynth/rng.hpp"
#include "voxel/distance_transform.hpp"
#include "voxel/line_coverage.hpp"

using namespace exsynth;
using namespace exsynth::voxel;

TEST(DistanceTransform, OneDimensionalMatchesBruteForce) {
  std::mt19937 gen(3);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + int(gen() % 40);
    std::vector<float> f(n, kFarAway), d(n);
    std::vector<std::int32_t> lab(n), out(n);
    std::vector<int> v(n);
    std::vector<double> g(n), z(n + 1);
    for (int i = 0; i < n; ++i) {
      lab[i] = i;
      if (gen() % 4 == 0) f[i] = float(gen() % 100) / 50.0f;
    }
    distance_transform_1d(f.data(), lab.data(), n, d.data(), out.data(), v.data(), g.data(), z.data());
    for (int q = 0; q < n; ++q) {
      float best = kFarAway;
      for (int p = 0; p < n; ++p)
        if (f[p] < kFarAway) best = std::min(best, float((q - p) * (q - p)) + f[p]);
      EXPECT_FLOAT_EQ(d[q], best);
      if (best < kFarAway) EXPECT_FLOAT_EQ(float((q - out[q]) * (q - out[q])) + f[out[q]], best);
      else EXPECT_EQ(out[q], -1);
    }
  }
}

TEST(DistanceTransform, ThreeDimensionalMatchesBruteForceAndCarriesLabels) {
  const int nx = 9, ny = 7, nz = 6;
  std::vector<float> d2(nx * ny * nz, kFarAway);
  std::vector<std::int32_t> lab(d2.size(), -1);
  struct Seed { int x, y, z; float f; };
  std::vector<Seed> seeds;
  for (int i = 0; i < 6; ++i) {
    IndexRng r(11, i);
    Seed s{int(r.below(nx)), int(r.below(ny)), int(r.below(nz)), float(r.uniform())};
    const std::size_t v = (std::size_t(s.z) * ny + s.y) * nx + s.x;
    if (d2[v] < kFarAway) continue;
    d2[v] = s.f;
    lab[v] = std::int32_t(seeds.size());
    seeds.push_back(s);
  }
  StageProgress progress(nullptr, "test", 0, 1, 1);
  distance_transform(nx, ny, nz, d2, lab, progress);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        float best = kFarAway;
        for (const auto& s : seeds)
          best = std::min(best, float((x - s.x) * (x - s.x) + (y - s.y) * (y - s.y) + (z - s.z) * (z - s.z)) + s.f);
        const std::size_t v = (std::size_t(z) * ny + y) * nx + x;
        EXPECT_NEAR(d2[v], best, 1e-4f);
        const Seed& s = seeds.at(lab[v]);
        EXPECT_NEAR(float((x - s.x) * (x - s.x) + (y - s.y) * (y - s.y) + (z - s.z) * (z - s.z)) + s.f, best, 1e-4f);
      }
}

TEST(LineCoverage, ExactOverlapAndParity) {
  // Inside on [1.25, 3.5] and [5.75, +inf) (odd count: parity runs to the end).
  std::vector<Crossing> xs = {{1.25f, -1}, {3.5f, 1}, {5.75f, -1}};
  std::vector<float> cov(8, 0.0f);
  accumulate_coverage(xs, 8, 1.0f, cov.data());
  const float expected[8] = {0, 0.25f, 1, 1, 0, 0, 0.75f, 1};
  for (int k = 0; k < 8; ++k) EXPECT_FLOAT_EQ(cov[k], expected[k]) << k;
  std::vector<std::uint8_t> inside(8);
  centre_parity(xs, 8, inside.data());
  const std::uint8_t in[8] = {0, 0, 1, 1, 0, 0, 1, 1};
  for (int k = 0; k < 8; ++k) EXPECT_EQ(inside[k], in[k]) << k;
}
