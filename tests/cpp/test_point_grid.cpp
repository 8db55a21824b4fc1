// search::PointGrid (the point texture's radius search) against brute force:
// radius sets, any_within and nearest (ties to the lowest index, queries far
// outside the points), duplicates, and a cell too small for the key's range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "search/point_grid.hpp"

using V3 = Eigen::Vector3f;

namespace {

std::vector<V3> cloud(int n, unsigned seed) {
  // A sphere shell, a dense clump with exact duplicates, and a few far outliers.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<V3> p;
  for (int i = 0; i < n; ++i) p.push_back(V3(u(rng), u(rng), u(rng)).normalized());
  for (int i = 0; i < n / 10; ++i) p.push_back(V3(0.3f, 0.2f, 0.1f) + 0.02f * V3(u(rng), u(rng), u(rng)));
  for (int i = 0; i < 20; ++i) p.push_back(p[std::size_t(i) * 7]);  // duplicates: ties for nearest
  p.push_back(V3(40, -30, 5));
  p.push_back(V3(-25, 12, -60));
  return p;
}

void check_against_brute_force(const std::vector<V3>& pts, float cell, unsigned seed) {
  const exsynth::search::PointGrid grid(pts, cell);
  ASSERT_EQ(grid.size(), pts.size());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.3f, 1.3f), rr(0.01f, 0.4f);
  std::vector<std::pair<std::size_t, float>> got;
  for (int k = 0; k < 400; ++k) {
    V3 q(u(rng), u(rng), u(rng));
    if (k % 40 == 0) q *= 100.0f;  // far from every point
    if (k % 17 == 0) q = pts[std::size_t(k) % pts.size()];  // on a point
    const float r = rr(rng);
    std::vector<std::size_t> want;
    std::size_t best = pts.size();
    float best_d2 = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const float d2 = (pts[i] - q).squaredNorm();
      if (d2 <= r * r) want.push_back(i);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    grid.radius(q, r, got);
    std::vector<std::size_t> ids;
    for (const auto& [i, d2] : got) {
      ids.push_back(i);
      EXPECT_FLOAT_EQ(d2, (pts[i] - q).squaredNorm());
    }
    std::sort(ids.begin(), ids.end());
    EXPECT_EQ(ids, want) << "query " << q.transpose() << " r " << r;
    EXPECT_EQ(grid.any_within(q, r), !want.empty());
    float d2 = -1;
    EXPECT_EQ(grid.nearest(q, &d2), best) << "query " << q.transpose();
    EXPECT_FLOAT_EQ(d2, best_d2);
  }
}

}  // namespace

TEST(PointGrid, RadiusAnyWithinAndNearestMatchBruteForce) {
  const std::vector<V3> pts = cloud(3000, 3);
  for (float cell : {0.05f, 0.2f, 1.0f}) check_against_brute_force(pts, cell, 7);
}

TEST(PointGrid, TinyCellsAreWidenedToTheKeyRange) {
  // 100 units at 1e-6 per cell would need 2^27 cells a side: the grid widens them.
  std::vector<V3> pts = cloud(500, 5);
  pts.push_back(V3(100, 0, 0));
  const exsynth::search::PointGrid grid(pts, 1e-6f);
  EXPECT_GT(grid.cell(), 1e-6f);
  check_against_brute_force(pts, 1e-6f, 9);
}

TEST(PointGrid, EmptyAndSinglePoint) {
  const std::vector<V3> none;
  const exsynth::search::PointGrid empty(none, 0.1f);
  std::vector<std::pair<std::size_t, float>> got{{1, 1.0f}};
  empty.radius(V3::Zero(), 1.0f, got);
  EXPECT_TRUE(got.empty());
  EXPECT_FALSE(empty.any_within(V3::Zero(), 1.0f));
  EXPECT_EQ(empty.nearest(V3::Zero()), 0u);  // size()
  const std::vector<V3> one{V3(1, 2, 3)};
  const exsynth::search::PointGrid single(one, 0.1f);
  float d2 = 0;
  EXPECT_EQ(single.nearest(V3(-5, 0, 0), &d2), 0u);
  EXPECT_FLOAT_EQ(d2, (one[0] - V3(-5, 0, 0)).squaredNorm());
}
