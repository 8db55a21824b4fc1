// Solid synthesis by exemplar coordinates (SolidMethod::Coordinates): the
// crossbar candidate table against its brute-force twin, values that are the
// exemplar's own texels, determinism over thread counts, cancellation in
// every stage, and the inputs it refuses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "exsynth/errors.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/solid.hpp"
#include "solid/crossbar_candidates.hpp"
#include "solid/exemplar_index.hpp"
#include "support/cancel.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using exsynth::testing::disc_texture;
using exsynth::testing::one_exemplar;
using exsynth::testing::random_image;
using ::testing::HasSubstr;

namespace {

SolidOptions coordinate_options() {
  SolidOptions o;
  o.method = SolidMethod::Coordinates;
  o.size = 24;
  o.levels = 2;
  o.iterations = 2;
  o.seed = 3;
  return o;
}

// Brute-force crossbar cost of a triple, straight from the definition:
// for each pair of views, the squared difference of their lines along the
// axis their slices share.
float crossbar_cost(const std::array<const solid::ExemplarIndex*, 3>& views, const solid::Triple& t, int half) {
  float cost = 0;
  const int dims = (2 * half + 1) * views[0]->image().channels();
  std::vector<float> a(static_cast<std::size_t>(dims)), b(static_cast<std::size_t>(dims));
  for (int i = 0; i < 3; ++i)
    for (int k = i + 1; k < 3; ++k) {
      if (!views[i] || !views[k]) continue;
      const int axis = solid::shared_axis(i, k);
      solid::crossbar_line(*views[i], i, t[i], axis, half, a.data());
      solid::crossbar_line(*views[k], k, t[k], axis, half, b.data());
      for (int d = 0; d < dims; ++d) cost += (a[d] - b[d]) * (a[d] - b[d]);
    }
  return cost;
}

}  // namespace

TEST(CrossbarCandidates, KdTreeTableEqualsTheBruteForceTable) {
  const Image x = random_image(14, 12, 3, 1), y = random_image(12, 13, 3, 2), z = random_image(13, 14, 3, 3);
  const std::vector<float> lo(3, 0.0f), hi(3, 1.0f);
  const solid::ExemplarIndex ix(x, 5, 0.95, 8, 2, 16, lo, hi, nullptr, "x", 0, 1);
  const solid::ExemplarIndex iy(y, 5, 0.95, 8, 2, 16, lo, hi, nullptr, "y", 0, 1);
  const solid::ExemplarIndex iz(z, 5, 0.95, 8, 2, 16, lo, hi, nullptr, "z", 0, 1);
  const std::array<const solid::ExemplarIndex*, 3> views{&ix, &iy, &iz};
  const solid::CrossbarCandidates fast(views, 2, 2, 3, nullptr, "table", 0, 1);
  const solid::CrossbarCandidates brute(views, 2, 2, 3, nullptr, "table", 0, 1, solid::CrossbarCandidates::Search::BruteForce);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < views[i]->count(); ++j)
      for (int r = 0; r < 2; ++r) {
        const solid::Triple t = fast.of(i, j)[r];
        EXPECT_EQ(t, brute.of(i, j)[r]) << "view " << i << " texel " << j << " rank " << r;
        EXPECT_EQ(t[i], j);  // the table's triples of (view, texel) contain that texel
        EXPECT_NEAR(fast.cost(i, j)[r], crossbar_cost(views, t, 2), 1e-4f);
      }
  // Ranked best first.
  for (int j = 0; j < ix.count(); ++j) EXPECT_LE(fast.cost(0, j)[0], fast.cost(0, j)[1]);
}

TEST(CrossbarCandidates, TwoViewsLeaveTheThirdEmpty) {
  const Image x = random_image(12, 12, 2, 4);
  const std::vector<float> lo(2, 0.0f), hi(2, 1.0f);
  const solid::ExemplarIndex ix(x, 5, 0.95, 8, 2, 16, lo, hi, nullptr, "x", 0, 1);
  const std::array<const solid::ExemplarIndex*, 3> views{&ix, nullptr, &ix};
  const solid::CrossbarCandidates table(views, 2, 1, 2, nullptr, "table", 0, 1);
  for (int j = 0; j < ix.count(); ++j) {
    EXPECT_EQ(table.of(0, j)[0][1], -1);
    EXPECT_GE(table.of(0, j)[0][2], 0);
    EXPECT_NEAR(table.cost(0, j)[0], crossbar_cost(views, table.of(0, j)[0], 2), 1e-4f);
  }
}

TEST(SolidCoordinates, EveryVoxelIsAnExemplarTexel) {
  const Image ex = disc_texture(32, 32, 3, 10);
  const TextureResult r = synthesize_solid(one_exemplar(ex), coordinate_options());
  ASSERT_EQ(r.texture.nx(), 24);
  ASSERT_EQ(r.texture.channels(), 3);
  std::set<std::array<float, 3>> texels;
  for (std::size_t p = 0; p < ex.pixel_count(); ++p)
    texels.insert({ex.data()[p * 3], ex.data()[p * 3 + 1], ex.data()[p * 3 + 2]});
  std::set<std::array<float, 3>> used;
  for (std::size_t v = 0; v < r.texture.voxel_count(); ++v) {
    const std::array<float, 3> c{r.texture.data()[v * 3], r.texture.data()[v * 3 + 1], r.texture.data()[v * 3 + 2]};
    ASSERT_TRUE(texels.count(c)) << "voxel " << v;
    used.insert(c);
  }
  EXPECT_GT(used.size(), texels.size() / 4);  // not a few flat texels everywhere
  ASSERT_FALSE(r.energy.empty());
  EXPECT_LT(r.energy.back(), r.energy.front());
}

// Fraction of voxels whose value equals their +1 neighbour's along `axis`.
double equal_neighbours(const Volume& v, int axis) {
  std::size_t same = 0, n = 0;
  const int c = v.channels();
  for (int z = 0; z < v.nz(); ++z)
    for (int y = 0; y < v.ny(); ++y)
      for (int x = 0; x < v.nx(); ++x) {
        std::array<int, 3> q{x, y, z};
        if (++q[axis] >= std::array<int, 3>{v.nx(), v.ny(), v.nz()}[axis]) continue;
        const float* a = v.data() + v.offset(x, y, z);
        const float* b = v.data() + v.offset(q[0], q[1], q[2]);
        same += std::equal(a, a + c, b);
        ++n;
      }
  return double(same) / double(n);
}

TEST(SolidCoordinates, NoAxisIsAnExtrusion) {
  // Every texel of a noise exemplar is distinct, so a voxel equals its
  // neighbour only where the solid repeats a texel along that axis. The
  // sibling-sharing upsampling gave 0.17 / 0.38 / 0.04 along x / y / z here
  // (now 0.02 / 0.07 / 0.03).
  const Image ex = random_image(32, 32, 3, 21);
  SolidOptions o = coordinate_options();
  o.size = 32;
  o.levels = 3;
  const Volume v = synthesize_solid(one_exemplar(ex), o).texture;
  for (int axis = 0; axis < 3; ++axis) {
    const double f = equal_neighbours(v, axis);
    EXPECT_LT(f, 0.1) << "axis " << "xyz"[axis];
  }
}

// RMS contrast (per-channel standard deviation, mean over channels) of `n`
// values of `c` channels.
double rms_contrast(const float* v, std::size_t n, int c) {
  double total = 0;
  for (int k = 0; k < c; ++k) {
    double s = 0, s2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      s += v[i * c + k];
      s2 += double(v[i * c + k]) * v[i * c + k];
    }
    total += std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)));
  }
  return total / c;
}

TEST(SolidCoordinates, KeepsTheExemplarsContrast) {
  // Discs on a flat background: with squared costs the corrections favour
  // the background (the texel that half-fits every neighbour).
  const Image ex = disc_texture(48, 48, 3, 31, 24, 4.0f);
  SolidOptions o = coordinate_options();
  o.size = 32;
  o.levels = 3;
  o.iterations = 3;
  const Volume v = synthesize_solid(one_exemplar(ex), o).texture;
  const double ratio = rms_contrast(v.data(), v.voxel_count(), 3) / rms_contrast(ex.data(), ex.pixel_count(), 3);
  EXPECT_GT(ratio, 0.92);  // squared costs: 0.825; Euclidean: 1.017
}

TEST(SolidCoordinates, SameSeedSameSolidWithOneTwoAndEightThreads) {
  const Image ex = disc_texture(32, 32, 3, 11);
  SolidOptions o = coordinate_options();
  o.size = 23;  // odd: the wrap-around sub-pass class
  auto run = [&] { return synthesize_solid(one_exemplar(ex), o).texture.values(); };
  const auto one = exsynth::testing::on_threads(1, run);
  EXPECT_EQ(exsynth::testing::on_threads(2, run), one);
  EXPECT_EQ(exsynth::testing::on_threads(8, run), one);
  o.feature_weight = 0.0;  // the optimiser's option (a default of SolidOptions): not this method's
  EXPECT_EQ(run(), one);
  o.seed = 4;
  EXPECT_NE(run(), one);
}

TEST(SolidCoordinates, TwoViewsAndPerViewExemplars) {
  SolidExemplars ex;
  ex.views[0] = disc_texture(32, 32, 2, 12);
  ex.views[2] = disc_texture(30, 34, 2, 13);
  ex.active = {true, false, true};
  SolidOptions o = coordinate_options();
  o.tileable = false;
  const TextureResult r = synthesize_solid(ex, o);
  EXPECT_EQ(r.texture.channels(), 2);
  EXPECT_EQ(r.texture.nz(), 24);
}

TEST(SolidCoordinates, CancelInEveryStage) {
  const Image ex = disc_texture(32, 32, 3, 14);
  SolidOptions o = coordinate_options();
  o.coordinate_coherence_k = 1;  // with the k-coherence sets' stage (the default 0 skips it)
  const exsynth::testing::Job job = [&](ExecContext* ctx) { synthesize_solid(one_exemplar(ex), o, ctx); };
  const auto log = exsynth::testing::stages_of(job);
  EXPECT_DOUBLE_EQ(log.final_progress, 1.0);
  const std::vector<std::string> expected{"solid: level 1/2 exemplar analysis (neighbourhoods, PCA)",
                                          "solid: level 2/2 exemplar analysis (k-coherence sets)", "solid: level 1/2 crossbar candidates",
                                          "solid: level 1/2 correction 1/2", "solid: level 2/2 upsample",
                                          "solid: level 2/2 correction 2/2", "solid: colours"};
  for (const std::string& stage : expected) {
    EXPECT_NE(std::find(log.names.begin(), log.names.end(), stage), log.names.end()) << stage;
    const auto outcome = exsynth::testing::cancel_in_stage(job, stage);
    EXPECT_TRUE(outcome.threw_cancelled) << stage;
    EXPECT_EQ(outcome.stage_at_throw, stage);
  }
  for (std::size_t s = 1; s < log.start_progress.size(); ++s) EXPECT_GE(log.start_progress[s], log.start_progress[s - 1]);
}

TEST(SolidCoordinates, RefusesWhatItCannotDo) {
  const Image ex = disc_texture(32, 32, 3, 15);
  SolidExemplars with_constraint = one_exemplar(ex);
  with_constraint.constraint = Volume(24, 24, 24, 4);
  try {
    synthesize_solid(with_constraint, coordinate_options());
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("constraint"));
    EXPECT_THAT(e.what(), HasSubstr("method='optimization'"));
  }
  SolidOptions deep = coordinate_options();
  deep.levels = 4;
  deep.size = 64;
  try {
    synthesize_solid(one_exemplar(disc_texture(32, 32, 3, 16)), deep);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("too small for method 'coordinates'"));
  }
  EXPECT_THROW(solid_method_from_name("lazy"), InvalidInput);
  EXPECT_EQ(solid_method_from_name(solid_method_name(SolidMethod::Coordinates)), SolidMethod::Coordinates);
  EXPECT_EQ(solid_method_names().size(), 2u);
}
