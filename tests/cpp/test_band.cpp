// The analogy's band helpers and padding against brute-force references.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "analogy/band.hpp"
#include "analogy/features.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/errors.hpp"
#include "support/threads.hpp"

using namespace exsynth;

namespace {

std::vector<std::uint32_t> stable_reference(const std::vector<float>& key) {
  std::vector<std::uint32_t> order(key.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) { return key[i] < key[j]; });
  return order;
}

std::vector<float> keys_with_ties(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(-50, 50);  // many ties, both signs, and +-0
  std::vector<float> key(n);
  for (float& k : key) k = float(value(rng)) * 0.25f;
  key[0] = -0.0f;
  key[1] = 0.0f;
  key[2] = -1e30f;
  key[3] = 1e30f;
  return key;
}

}  // namespace

TEST(SortedBy, IsTheStableSortOfTheKeys) {
  const StageProgress none(nullptr, "", 0, 1, 1);
  for (std::size_t n : {std::size_t(4), std::size_t(1000), std::size_t(200000)}) {
    const std::vector<float> key = keys_with_ties(n, unsigned(n));
    EXPECT_EQ(analogy::sorted_by(key, none), stable_reference(key)) << n << " keys";
  }
}

TEST(SortedBy, SameOrderWhateverTheThreadCount) {
  const StageProgress none(nullptr, "", 0, 1, 1);
  const std::vector<float> key = keys_with_ties(300000, 5);
  const auto run = [&] { return analogy::sorted_by(key, none); };
  const std::vector<std::uint32_t> one = exsynth::testing::on_threads(1, run);
  const std::vector<std::uint32_t> eight = exsynth::testing::on_threads(8, run);
  EXPECT_EQ(one, eight);
}

TEST(SortedBy, ACancelStopsIt) {
  ExecContext ctx;
  const StageProgress progress(&ctx, "sort", 0, 1, 1);
  const std::vector<float> key = keys_with_ties(1000, 3);
  EXPECT_NO_THROW(analogy::sorted_by(key, progress));
  ctx.cancel();
  EXPECT_THROW(analogy::sorted_by(key, progress), Cancelled);
}

TEST(AnalogyPadding, CoversEveryNeighbourhoodOffsetAtTheFinestLevel) {
  // Brute force over the neighbourhoods the analogy samples: the farthest
  // fine offset, plus the farthest coarse one in fine voxels (x2).
  for (int fine = 3; fine <= 9; fine += 2)
    for (int coarse = 1; coarse <= 7; coarse += 2) {
      const analogy::Neighbourhoods n = analogy::make_neighbourhoods(fine, coarse, false);
      float reach = 0, coarse_reach = 0;
      for (const auto& o : n.fine) reach = std::max(reach, o.cwiseAbs().maxCoeff());
      for (const auto& o : n.coarse) coarse_reach = std::max(coarse_reach, o.cwiseAbs().maxCoeff());
      EXPECT_EQ(analogy_padding(fine, coarse), int(reach + 2 * coarse_reach)) << fine << ", " << coarse;
    }
  EXPECT_EQ(analogy_padding(), analogy_padding(AnalogyOptions{}.fine_size, AnalogyOptions{}.coarse_size));
}
