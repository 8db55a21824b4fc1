// Built-in exemplar pairs: grids, sign conventions, the change A -> A' in
// the expected direction (volume, surface), distances that are distances
// (|grad| ~ 1 near the surface), unit fields, determinism and bad options.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "exsynth/errors.hpp"
#include "exsynth/pairs.hpp"

using namespace exsynth;
using ::testing::HasSubstr;

namespace {

const PairPreset kAll[] = {PairPreset::Spikes, PairPreset::Pits, PairPreset::Holes, PairPreset::Grooves,
                           PairPreset::Dilate};

bool is_slab(PairPreset p) { return p == PairPreset::Spikes || p == PairPreset::Pits || p == PairPreset::Holes; }

double h_of(const Volume& v) { return v.transform().voxel_size; }

double inside_volume(const Volume& v) {
  const double h = h_of(v);
  return double(std::count_if(v.values().begin(), v.values().end(), [](float s) { return s < 0; })) * h * h * h;
}

// Surface-area proxy: voxels within one voxel of the surface.
std::size_t shell_count(const Volume& v) {
  const float h = float(h_of(v));
  return std::size_t(std::count_if(v.values().begin(), v.values().end(), [h](float s) { return std::abs(s) < h; }));
}

// Nearest voxel index to a world coordinate (the grid is a cube).
int index_of(const Volume& v, double w) {
  return int(std::lround((w - v.transform().origin[0]) / h_of(v)));
}

// Median |grad sdf| by central differences over voxels within 1.5 voxels
// of the surface.
double median_gradient_norm(const Volume& v) {
  const double h = h_of(v);
  std::vector<double> norms;
  for (int z = 1; z + 1 < v.nz(); ++z)
    for (int y = 1; y + 1 < v.ny(); ++y)
      for (int x = 1; x + 1 < v.nx(); ++x) {
        if (std::abs(v.at(x, y, z)) > 1.5 * h) continue;
        const double gx = (v.at(x + 1, y, z) - v.at(x - 1, y, z)) / (2 * h);
        const double gy = (v.at(x, y + 1, z) - v.at(x, y - 1, z)) / (2 * h);
        const double gz = (v.at(x, y, z + 1) - v.at(x, y, z - 1)) / (2 * h);
        norms.push_back(std::sqrt(gx * gx + gy * gy + gz * gz));
      }
  EXPECT_GT(norms.size(), 100u);
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  return norms[norms.size() / 2];
}

void expect_same_grid(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.nx(), b.nx());
  EXPECT_EQ(a.ny(), b.ny());
  EXPECT_EQ(a.nz(), b.nz());
  EXPECT_EQ(a.transform().origin, b.transform().origin);
  EXPECT_EQ(a.transform().voxel_size, b.transform().voxel_size);
}

void expect_invalid(PairPreset preset, const PairOptions& o, const std::string& name) {
  try {
    make_exemplar_pair(preset, o);
    ADD_FAILURE() << "expected InvalidInput naming " << name;
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr(name));
  }
}

}  // namespace

TEST(PairTest, EveryPresetGivesTwoDistanceFieldsOnOneGridAndAUnitField) {
  for (PairPreset p : kAll) {
    SCOPED_TRACE(pair_preset_name(p));
    PairOptions o;
    o.resolution = 48;
    const ExemplarPair pair = make_exemplar_pair(p, o);
    ASSERT_EQ(pair.a.nx(), 48);
    ASSERT_EQ(pair.a.ny(), 48);
    ASSERT_EQ(pair.a.nz(), 48);
    EXPECT_EQ(pair.a.channels(), 1);
    EXPECT_EQ(pair.a_prime.channels(), 1);
    EXPECT_EQ(pair.field_a.channels(), 3);
    expect_same_grid(pair.a, pair.a_prime);
    expect_same_grid(pair.a, pair.field_a);
    EXPECT_DOUBLE_EQ(pair.a.transform().voxel_size, 2.0 / 48);
    EXPECT_DOUBLE_EQ(pair.a.transform().origin[0], -1.0 + 1.0 / 48);

    for (float s : pair.a.values()) ASSERT_TRUE(std::isfinite(s));
    for (float s : pair.a_prime.values()) ASSERT_TRUE(std::isfinite(s));
    double worst = 0;
    for (std::size_t i = 0; i < pair.field_a.voxel_count(); ++i) {
      const float* t = pair.field_a.data() + 3 * i;
      worst = std::max(worst, std::abs(std::sqrt(double(t[0]) * t[0] + double(t[1]) * t[1] + double(t[2]) * t[2]) - 1));
    }
    EXPECT_LT(worst, 1e-5);
  }
}

TEST(PairTest, SignsArePositiveOutsideAndNegativeInside) {
  for (PairPreset p : kAll) {
    SCOPED_TRACE(pair_preset_name(p));
    PairOptions o;
    o.resolution = 64;
    const ExemplarPair pair = make_exemplar_pair(p, o);
    // World (0, 0, 0) is between slab features (a lattice corner), on the
    // cylinder's axis and at the sphere's centre: inside in both.
    const int c = index_of(pair.a, 0.0);
    EXPECT_LT(pair.a.at(c, c, c), 0);
    EXPECT_LT(pair.a_prime.at(c, c, c), 0);
    // Far above (the top corner) is outside.
    EXPECT_GT(pair.a.at(63, 63, 63), 0);
    EXPECT_GT(pair.a_prime.at(63, 63, 63), 0);
    if (is_slab(p)) {
      // Only z matters in the plain slab: |z| - thickness / 2.
      const double z = pair.a.transform().index_to_world(0, 0, 50)[2];
      EXPECT_NEAR(pair.a.at(5, 17, 50), std::abs(z) - 0.2, 1e-6);
    }
  }
}

TEST(PairTest, SpikesAddVolumeAndSurface) {
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, {});
  EXPECT_GT(inside_volume(pair.a_prime), inside_volume(pair.a) * 1.02);
  EXPECT_GT(shell_count(pair.a_prime), shell_count(pair.a) * 1.1);
  // Up a spike (apex at world (0.25, 0.25, 0.5); radius 0.08 at z = 0.3): inside A' only.
  const int x = index_of(pair.a, 0.25), z = index_of(pair.a, 0.3);
  EXPECT_GT(pair.a.at(x, x, z), 0);
  EXPECT_LT(pair.a_prime.at(x, x, z), 0);
}

TEST(PairTest, PitsAndHolesRemoveVolume) {
  for (PairPreset p : {PairPreset::Pits, PairPreset::Holes}) {
    SCOPED_TRACE(pair_preset_name(p));
    const ExemplarPair pair = make_exemplar_pair(p, {});
    EXPECT_LT(inside_volume(pair.a_prime), inside_volume(pair.a) * 0.98);
    EXPECT_GT(shell_count(pair.a_prime), shell_count(pair.a));
  }
}

TEST(PairTest, PitsDentTheTopButKeepTheBottom) {
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Pits, {});
  const int x = index_of(pair.a, 0.25);
  EXPECT_GT(pair.a_prime.at(x, x, index_of(pair.a, 0.15)), 0);   // in the dent
  EXPECT_LT(pair.a_prime.at(x, x, index_of(pair.a, -0.15)), 0);  // under it, still slab
}

TEST(PairTest, AColumnThroughAHoleCentreIsOutsideEverywhere) {
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Holes, {});
  const int x = index_of(pair.a, 0.25), y = index_of(pair.a, -0.75);
  for (int z = 0; z < pair.a_prime.nz(); ++z) EXPECT_GT(pair.a_prime.at(x, y, z), 0) << "z " << z;
  // ... while the slab between holes is solid.
  const int c = index_of(pair.a, 0.0);
  EXPECT_LT(pair.a_prime.at(c, c, c), 0);
}

TEST(PairTest, GroovesRemoveVolumeAndLeaveTheCylinderAlonePastThem) {
  for (GrooveDirection dir : {GrooveDirection::Around, GrooveDirection::Along}) {
    SCOPED_TRACE(dir == GrooveDirection::Around ? "around" : "along");
    PairOptions o;
    o.groove_direction = dir;
    const ExemplarPair pair = make_exemplar_pair(PairPreset::Grooves, o);
    EXPECT_LT(inside_volume(pair.a_prime), inside_volume(pair.a) * 0.98);
    const double h = h_of(pair.a), R = o.cylinder_radius, r = o.feature_radius, s = o.spacing;
    const int n = std::max(3, int(std::lround(2 * M_PI * R / s)));
    std::size_t checked = 0, differ = 0;
    for (int z = 0; z < pair.a.nz(); ++z)
      for (int y = 0; y < pair.a.ny(); ++y)
        for (int x = 0; x < pair.a.nx(); ++x) {
          const auto p = pair.a.transform().index_to_world(x, y, z);
          const double q = std::hypot(p[0], p[1]);
          // Distance to the nearest groove's centre line, written out here.
          double d;
          if (dir == GrooveDirection::Around) {
            const double zk = (std::floor(p[2] / s) + 0.5) * s;
            d = std::hypot(q - R, p[2] - zk);
          } else {
            d = INFINITY;
            for (int k = 0; k < n; ++k) {
              const double ang = (k + 0.5) * 2 * M_PI / n;
              d = std::min(d, std::hypot(p[0] - R * std::cos(ang), p[1] - R * std::sin(ang)));
            }
          }
          // Near the cylinder's surface and clear of every groove.
          if (std::abs(pair.a.at(x, y, z)) < 2 * h && d > r + 3 * h) {
            ++checked;
            if (pair.a_prime.at(x, y, z) != pair.a.at(x, y, z)) ++differ;
          }
          if (d < 0.5 * r) EXPECT_GT(pair.a_prime.at(x, y, z), 0);  // in a groove
        }
    EXPECT_GT(checked, 1000u);
    EXPECT_EQ(differ, 0u);
  }
}

TEST(PairTest, GrooveFieldRunsAlongTheGrooves) {
  PairOptions o;
  o.resolution = 32;
  const ExemplarPair around = make_exemplar_pair(PairPreset::Grooves, o);
  o.groove_direction = GrooveDirection::Along;
  const ExemplarPair along = make_exemplar_pair(PairPreset::Grooves, o);
  for (int z = 0; z < 32; z += 3)
    for (int y = 0; y < 32; y += 3)
      for (int x = 0; x < 32; x += 3) {
        const auto p = around.a.transform().index_to_world(x, y, z);
        const double q = std::hypot(p[0], p[1]);
        // Around: tangent to circles about z (orthogonal to the radius and to z).
        EXPECT_NEAR(around.field_a.at(x, y, z, 0) * p[0] / q + around.field_a.at(x, y, z, 1) * p[1] / q, 0, 1e-6);
        EXPECT_EQ(around.field_a.at(x, y, z, 2), 0.0f);
        EXPECT_EQ(along.field_a.at(x, y, z, 2), 1.0f);
      }
}

TEST(PairTest, SlabAndDilateFieldsAreTheGlobalXAxis) {
  for (PairPreset p : {PairPreset::Spikes, PairPreset::Pits, PairPreset::Holes, PairPreset::Dilate}) {
    SCOPED_TRACE(pair_preset_name(p));
    PairOptions o;
    o.resolution = 16;
    const ExemplarPair pair = make_exemplar_pair(p, o);
    for (std::size_t i = 0; i < pair.field_a.voxel_count(); ++i) {
      ASSERT_EQ(pair.field_a.values()[3 * i], 1.0f);
      ASSERT_EQ(pair.field_a.values()[3 * i + 1], 0.0f);
      ASSERT_EQ(pair.field_a.values()[3 * i + 2], 0.0f);
    }
  }
}

TEST(PairTest, DilationGrowsTheVolumeByTheCubeOfTheRadii) {
  PairOptions o;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Dilate, o);
  const double r = o.sphere_radius, d = o.dilation;
  const double expected = std::pow((r + d) / r, 3);
  EXPECT_NEAR(inside_volume(pair.a_prime) / inside_volume(pair.a), expected, 0.05 * expected);
  EXPECT_NEAR(inside_volume(pair.a), 4.0 / 3.0 * M_PI * r * r * r, 0.05 * (4.0 / 3.0 * M_PI * r * r * r));
}

TEST(PairTest, ValuesAreDistancesNearTheSurface) {
  for (PairPreset p : kAll) {
    SCOPED_TRACE(pair_preset_name(p));
    PairOptions o;
    o.jitter = 0.15;
    o.seed = 3;
    const ExemplarPair pair = make_exemplar_pair(p, o);
    EXPECT_NEAR(median_gradient_norm(pair.a), 1.0, 0.05);
    EXPECT_NEAR(median_gradient_norm(pair.a_prime), 1.0, 0.05);
  }
}

TEST(PairTest, SameSeedSameOutputAndTheSeedMovesTheJitter) {
  PairOptions o;
  o.resolution = 40;
  o.jitter = 0.2;
  o.seed = 7;
  const ExemplarPair p1 = make_exemplar_pair(PairPreset::Spikes, o);
  const ExemplarPair p2 = make_exemplar_pair(PairPreset::Spikes, o);
  EXPECT_EQ(p1.a.values(), p2.a.values());
  EXPECT_EQ(p1.a_prime.values(), p2.a_prime.values());
  EXPECT_EQ(p1.field_a.values(), p2.field_a.values());
  o.seed = 8;
  const ExemplarPair p3 = make_exemplar_pair(PairPreset::Spikes, o);
  EXPECT_NE(p1.a_prime.values(), p3.a_prime.values());
  EXPECT_EQ(p1.a.values(), p3.a.values());  // the plain slab has no features
  // Without jitter the seed does nothing.
  o.jitter = 0;
  const ExemplarPair q1 = make_exemplar_pair(PairPreset::Spikes, o);
  o.seed = 9;
  EXPECT_EQ(q1.a_prime.values(), make_exemplar_pair(PairPreset::Spikes, o).a_prime.values());
}

TEST(PairTest, BadOptionsNameTheOption) {
  PairOptions o;
  o.resolution = 4;
  expect_invalid(PairPreset::Spikes, o, "resolution");
  o = {};
  o.resolution = 513;
  expect_invalid(PairPreset::Dilate, o, "resolution");
  o = {};
  o.feature_radius = -0.1;
  expect_invalid(PairPreset::Holes, o, "feature_radius");
  o = {};
  o.feature_radius = 0.3;  // >= spacing / 2
  expect_invalid(PairPreset::Pits, o, "feature_radius");
  o = {};
  o.spacing = 0;
  expect_invalid(PairPreset::Spikes, o, "spacing");
  o = {};
  o.thickness = NAN;
  expect_invalid(PairPreset::Pits, o, "thickness");
  o = {};
  o.jitter = 0.5;
  expect_invalid(PairPreset::Spikes, o, "jitter");
  o = {};
  o.feature_height = 0.8;  // spikes would leave the grid
  expect_invalid(PairPreset::Spikes, o, "feature_height");
  o = {};
  o.thickness = 0.1;  // pits deeper than the slab
  expect_invalid(PairPreset::Pits, o, "feature_radius");
  o = {};
  o.cylinder_radius = 0.95;
  expect_invalid(PairPreset::Grooves, o, "cylinder_radius");
  o = {};
  o.dilation = 0.5;  // 0.5 + 0.5 > 0.9
  expect_invalid(PairPreset::Dilate, o, "dilation");
  o = {};
  o.sphere_radius = INFINITY;
  expect_invalid(PairPreset::Dilate, o, "sphere_radius");
}

TEST(PairTest, OverBudgetIsRefusedBeforeAllocating) {
  PairOptions o;
  o.resolution = 512;
  o.memory_budget = std::size_t(1) << 20;
  try {
    make_exemplar_pair(PairPreset::Spikes, o);
    ADD_FAILURE() << "expected OverBudget";
  } catch (const OverBudget& e) {
    EXPECT_THAT(e.what(), HasSubstr("resolution"));
    EXPECT_THAT(e.what(), HasSubstr("memory budget"));
  }
}

TEST(PairTest, ACancelledContextStopsTheJob) {
  ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(make_exemplar_pair(PairPreset::Dilate, {}, &ctx), Cancelled);
  ExecContext fresh;
  make_exemplar_pair(PairPreset::Dilate, {}, &fresh);
  EXPECT_DOUBLE_EQ(fresh.progress(), 1.0);
}

// Features are searched only in the 3 x 3 lattice cells around a point; a
// feature missed there would make a jump at a cell border. Min and max of
// distances are 1-Lipschitz, so neighbouring voxels never differ by more
// than a voxel, even with the largest jitter and radius allowed.
TEST(PairTest, FeatureSearchMissesNothingAtLargestJitterAndRadius) {
  for (PairPreset p : {PairPreset::Spikes, PairPreset::Pits, PairPreset::Holes}) {
    SCOPED_TRACE(pair_preset_name(p));
    PairOptions o;
    o.resolution = 64;
    o.spacing = 0.3;
    o.feature_radius = 0.149;
    o.jitter = 0.25;
    o.seed = 11;
    const Volume v = make_exemplar_pair(p, o).a_prime;
    const float h = float(h_of(v)) * 1.0001f;
    float worst = 0;
    for (int z = 0; z < v.nz(); ++z)
      for (int y = 0; y < v.ny(); ++y)
        for (int x = 0; x + 1 < v.nx(); ++x) {
          worst = std::max(worst, std::abs(v.at(x + 1, y, z) - v.at(x, y, z)));
          if (y + 1 < v.ny()) worst = std::max(worst, std::abs(v.at(x, y + 1, z) - v.at(x, y, z)));
        }
    EXPECT_LE(worst, h);
  }
}

// Brute-force twin for the spikes outside the solid: the distance to a dense
// sampling of every cone's side (all lattice cells) and to the slab's top
// outside the cones' feet.
TEST(PairTest, SpikeDistancesOutsideMatchADenseSurfaceSampling) {
  PairOptions o;
  o.resolution = 32;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, o);
  const double half = 0.5 * o.thickness, r = o.feature_radius, H = o.feature_height, s = o.spacing;
  std::vector<std::array<double, 3>> samples;
  for (int j = -3; j <= 2; ++j)
    for (int i = -3; i <= 2; ++i)
      for (int a = 0; a < 120; ++a)
        for (int k = 0; k <= 90; ++k) {
          const double t = k / 90.0, ang = 2 * M_PI * a / 120;  // t: 0 at the foot, 1 at the apex
          samples.push_back({(i + 0.5) * s + (1 - t) * r * std::cos(ang), (j + 0.5) * s + (1 - t) * r * std::sin(ang),
                             half + t * H});
        }
  int checked = 0;
  for (int z = 0; z < 32; z += 2)
    for (int y = 0; y < 32; y += 5)
      for (int x = 0; x < 32; x += 3) {
        const auto p = pair.a.transform().index_to_world(x, y, z);
        // Distance from the nearest cone's axis (no jitter: cell centres).
        const double fx = p[0] / s - std::floor(p[0] / s) - 0.5, fy = p[1] / s - std::floor(p[1] / s) - 0.5;
        const double q = std::hypot(fx * s, fy * s);
        if (p[2] <= half || q <= r * (half + H - p[2]) / H) continue;  // inside the slab or a cone
        double best = INFINITY;
        // The top plane, where the foot of the perpendicular is outside every cone.
        if (q >= r) best = p[2] - half;
        for (const auto& q : samples) best = std::min(best, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
        EXPECT_NEAR(pair.a_prime.at(x, y, z), best, 0.006) << p[0] << " " << p[1] << " " << p[2];
        ++checked;
      }
  EXPECT_GT(checked, 100);
}

TEST(ResolutionForPattern, IsTheLeastResolutionThatGivesThePairItsDetail) {
  // Brute force: the first r from `resolution` up whose pair has the detail
  // voxels, or the cap.
  auto by_hand = [](int resolution, double scale) {
    const int top = std::max(resolution, kMaxPatternResolution);
    for (int r = resolution; r < top; ++r)
      if (std::lround(scale * r) >= kPairDetailResolution) return r;
    return top;
  };
  for (int resolution : {1, 16, 96, 128, 200, 256, 511, 512, 700})
    for (double scale : {0.01, 0.05, 0.1, 0.125, 0.2231, 0.25, 0.276, 0.3333, 0.5, 0.575, 1.0, 4.0}) {
      const int r = resolution_for_pattern(resolution, scale);
      EXPECT_EQ(r, by_hand(resolution, scale)) << resolution << " x " << scale;
      EXPECT_GE(r, resolution);
    }
  EXPECT_EQ(resolution_for_pattern(128, 0.575), 128);  // the bunny's fitted pattern already has 74 voxels
  EXPECT_GT(resolution_for_pattern(128, 0.276), 128);  // the cow's 35 do not
  EXPECT_THROW(resolution_for_pattern(0, 0.5), InvalidInput);
  EXPECT_THROW(resolution_for_pattern(128, 0.0), InvalidInput);
  EXPECT_THROW(resolution_for_pattern(128, std::nan("")), InvalidInput);
}
