// Volume analogies (isotropic variant): B' is to B as A' is to A.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>


#include "exsynth/analogy.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/rng.hpp"
#include "support/volumes.hpp"
#include "support/threads.hpp"

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
  opt.levels = 2;
  // A filter, not a pattern: every voxel's own best match, no coherence
  // (coherent copies follow A's blobs, which are not B's).
  opt.coherence = 0;
  opt.coherence_slack = 0;
  const AnalogyResult r = synthesize_analogy(a, box_blur(a), b, opt);
  const Volume want = box_blur(b);
  // B' is clearly closer to the blurred B than B itself is (measured 0.65x:
  // the error left is that of copying values from a 24^3 exemplar, whose
  // nearest 5^3 neighbourhood is never an exact match).
  EXPECT_LT(mean_abs_difference(r.b_prime, want), 0.75 * mean_abs_difference(b, want));
  EXPECT_EQ(r.culled, 0u);
  EXPECT_EQ(r.searched, std::size_t(2) * (24 * 24 * 24 + 12 * 12 * 12));
}

TEST(Analogy, APairThatChangesNothingIsAnError) {
  const Volume b = blobs(16, 4);
  AnalogyOptions opt;
  opt.cull_distance = 0;
  try {
    synthesize_analogy(b, b, b, opt);
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("does not differ from A"));
  }
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
  EXPECT_THROW(synthesize_analogy(a, box_blur(a), b, budget), OverBudget);
  ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(synthesize_analogy(a, box_blur(a), b, {}, &ctx), Cancelled);
}

namespace {

// Faces between 6-neighbours of opposite sign: a voxel measure of the area
// of the zero set.
std::size_t sign_changes(const Volume& v) {
  std::size_t n = 0;
  for (int z = 0; z < v.nz(); ++z)
    for (int y = 0; y < v.ny(); ++y)
      for (int x = 0; x < v.nx(); ++x) {
        const bool in = v.at(x, y, z) < 0;
        if (x + 1 < v.nx() && in != (v.at(x + 1, y, z) < 0)) ++n;
        if (y + 1 < v.ny() && in != (v.at(x, y + 1, z) < 0)) ++n;
        if (z + 1 < v.nz() && in != (v.at(x, y, z + 1) < 0)) ++n;
      }
  return n;
}

// A grid of n^3 voxels of size h centred on the origin.
GridTransform centred(int n, double h) {
  GridTransform t;
  t.voxel_size = h;
  t.origin = {-0.5 * (n - 1) * h, -0.5 * (n - 1) * h, -0.5 * (n - 1) * h};
  return t;
}

// Circles around the z axis: the field of the grooves pair, for any grid
// centred on the origin (support/volumes.hpp).
Volume around_z(const Volume& like) { return exsynth::testing::around_z_field(like); }

// Connected parts (6-neighbours) of the inside (sdf < 0) or the outside.
int components(const Volume& v, bool inside) {
  std::vector<int> label(v.voxel_count(), -1);
  int parts = 0;
  std::vector<std::array<int, 3>> stack;
  for (int z = 0; z < v.nz(); ++z)
    for (int y = 0; y < v.ny(); ++y)
      for (int x = 0; x < v.nx(); ++x) {
        if ((v.at(x, y, z) < 0) != inside || label[v.voxel_index(x, y, z)] >= 0) continue;
        stack.push_back({x, y, z});
        label[v.voxel_index(x, y, z)] = parts;
        while (!stack.empty()) {
          const auto [cx, cy, cz] = stack.back();
          stack.pop_back();
          const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
          for (const auto& d : nb) {
            const int qx = cx + d[0], qy = cy + d[1], qz = cz + d[2];
            if (qx < 0 || qy < 0 || qz < 0 || qx >= v.nx() || qy >= v.ny() || qz >= v.nz()) continue;
            const std::size_t q = v.voxel_index(qx, qy, qz);
            if ((v.at(qx, qy, qz) < 0) != inside || label[q] >= 0) continue;
            label[q] = parts;
            stack.push_back({qx, qy, qz});
          }
        }
        ++parts;
      }
  return parts;
}

// Mean |dV/dT| and mean |dV/dB| (central differences) over voxels near V's
// surface, with T from `field` and B = T x N, N from the smooth `frame_sdf`'s
// gradient: a pattern that runs along the field changes V little along T
// and a lot along B.
std::pair<double, double> along_across(const Volume& v, const Volume& frame_sdf, const Volume& field) {
  double along = 0, across = 0;
  std::size_t n = 0;
  const float h = float(v.transform().voxel_size);
  for (int z = 1; z + 1 < v.nz(); ++z)
    for (int y = 1; y + 1 < v.ny(); ++y)
      for (int x = 1; x + 1 < v.nx(); ++x) {
        if (std::abs(v.at(x, y, z)) > 1.5f * h) continue;
        const auto grad = [&](const Volume& w) -> Eigen::Vector3f {
          return Eigen::Vector3f(w.at(x + 1, y, z) - w.at(x - 1, y, z), w.at(x, y + 1, z) - w.at(x, y - 1, z),
                                 w.at(x, y, z + 1) - w.at(x, y, z - 1)) / (2.0f * h);
        };
        const Eigen::Vector3f g = grad(v), nrm = grad(frame_sdf).normalized();
        const float* t = field.data() + 3 * v.voxel_index(x, y, z);
        Eigen::Vector3f tv(t[0], t[1], t[2]);
        tv -= tv.dot(nrm) * nrm;
        if (tv.norm() < 1e-3f) continue;
        tv.normalize();
        along += std::abs(g.dot(tv));
        across += std::abs(g.dot(tv.cross(nrm)));
        ++n;
      }
  return {along / double(n), across / double(n)};
}

}  // namespace

// Each pair applied once to a sphere of radius 26 voxels (the pairs'
// features are ~12 voxels apart) with a field of circles around z.
struct SphereRun {
  Volume b, field;
  AnalogyResult r;
};
const SphereRun& on_sphere(PairPreset preset) {
  static std::map<PairPreset, SphereRun> runs;
  auto it = runs.find(preset);
  if (it != runs.end()) return it->second;
  PairOptions po;
  po.resolution = 48;
  const ExemplarPair pair = make_exemplar_pair(preset, po);
  const double h = pair.a.transform().voxel_size;
  SphereRun run;
  run.b = sphere_sdf(Volume(68, 68, 68, 1, 0.0f, centred(68, h)), 26 * h);
  run.field = around_z(run.b);
  run.r = synthesize_analogy(pair.a, pair.a_prime, pair.field_a, run.b, run.field);
  return runs.emplace(preset, std::move(run)).first->second;
}

TEST(AnalogyOnASphere, SpikesAddAreaAndVolumeAndStayAttached) {
  const SphereRun& s = on_sphere(PairPreset::Spikes);
  EXPECT_GT(double(sign_changes(s.r.b_prime)), 1.3 * double(sign_changes(s.b)));  // measured 1.54x
  EXPECT_GT(inside_volume(s.r.b_prime), 1.04 * inside_volume(s.b));  // measured +10 %
  EXPECT_EQ(components(s.r.b_prime, true), 1);   // no spike floats free
  EXPECT_EQ(components(s.r.b_prime, false), 1);  // and no bubbles
  EXPECT_GT(s.r.coherent, s.r.searched / 2);     // patches of A' were copied whole
}

TEST(AnalogyOnASphere, PitsAndHolesAddAreaAndRemoveVolume) {
  for (PairPreset preset : {PairPreset::Pits, PairPreset::Holes}) {
    const SphereRun& s = on_sphere(preset);
    EXPECT_GT(double(sign_changes(s.r.b_prime)), 1.15 * double(sign_changes(s.b))) << pair_preset_name(preset);
    EXPECT_LT(inside_volume(s.r.b_prime), inside_volume(s.b)) << pair_preset_name(preset);
    EXPECT_EQ(components(s.r.b_prime, true), 1) << pair_preset_name(preset);
  }
}

TEST(AnalogyOnASphere, GroovesRunAlongTheField) {
  // Measured from B''s signed distance: grooves along T change it across T
  // (along B = T x N) much more than along T. Spikes are the control: no
  // direction, ratio about 1.
  const SphereRun& g = on_sphere(PairPreset::Grooves);
  const SphereRun& c = on_sphere(PairPreset::Spikes);
  const auto [g_along, g_across] = along_across(g.r.b_prime, g.b, g.field);
  const auto [c_along, c_across] = along_across(c.r.b_prime, c.b, c.field);
  EXPECT_GT(g_across / g_along, 4.0);  // measured 8.7 (the exemplar's own grooves: 18)
  EXPECT_LT(c_across / c_along, 1.2);
  EXPECT_GT(double(sign_changes(g.r.b_prime)), 1.07 * double(sign_changes(g.b)));  // measured 1.14x
}

TEST(Analogy, SameInputSameResultWhateverTheThreadCount) {
  PairOptions po;
  po.resolution = 32;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const Volume b = sphere_sdf(Volume(40, 40, 40, 1, 0.0f, centred(40, h)), 14 * h);
  const Volume field = around_z(b);
  const auto run = [&] { return synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field); };
  const AnalogyResult one = exsynth::testing::on_threads(1, run);
  const AnalogyResult many = exsynth::testing::on_threads(8, run);
  EXPECT_EQ(one.b_prime.values(), many.b_prime.values());
  EXPECT_EQ(one.searched, many.searched);
  EXPECT_EQ(one.coherent, many.coherent);
}

TEST(Analogy, BadFieldsNameTheProblem) {
  PairOptions po;
  po.resolution = 16;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const Volume b = sphere_sdf(Volume(20, 20, 20, 1, 0.0f, centred(20, h)), 6 * h);
  auto message = [&](const Volume& field_a, const Volume& field_b) -> std::string {
    try {
      synthesize_analogy(pair.a, pair.a_prime, field_a, b, field_b);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "no error";
  };
  const Volume field = around_z(b);
  const Volume zeros(20, 20, 20, 3, 0.0f, b.transform());
  EXPECT_THAT(message(pair.field_a, zeros), HasSubstr("field_b is zero or not finite"));
  Volume nan = field;
  for (int z = 0; z < 20; ++z) nan.at(10, 4, z, 0) = std::nanf("");  // crosses the surface
  EXPECT_THAT(message(pair.field_a, nan), HasSubstr("field_b is zero or not finite"));
  EXPECT_THAT(message(pair.field_a, Volume(20, 20, 20, 1)), HasSubstr("field_b must have 3 channels"));
  EXPECT_THAT(message(Volume(8, 8, 8, 3, 1.0f), field), HasSubstr("field_a must have 3 channels on A's grid"));
}

TEST(Analogy, ARegionLimitsWhatIsLearnt) {
  PairOptions po;
  po.resolution = 24;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const Volume b = sphere_sdf(Volume(28, 28, 28, 1, 0.0f, centred(28, h)), 9 * h);
  const Volume field = around_z(b);
  // The slab spans voxel rows z = 9..14, the spikes stand on its top: a
  // region from just under the slab's underside up learns exactly what no
  // region learns (A' differs from A only above the underside) ...
  Volume top(24, 24, 24, 1, 0.0f, pair.a.transform()), bottom = top;
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        if (z >= 8) top.at(x, y, z) = 1.0f;
        if (z < 6) bottom.at(x, y, z) = 1.0f;  // the air under the slab
      }
  AnalogyOptions with_top;
  with_top.a_region = top;
  const AnalogyResult all = synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field);
  const AnalogyResult upper = synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field, with_top);
  EXPECT_EQ(all.b_prime.values(), upper.b_prime.values());
  // ... and the bottom half, where A' is A, has nothing to learn.
  AnalogyOptions with_bottom;
  with_bottom.a_region = bottom;
  try {
    synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field, with_bottom);
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("inside a_region"));
  }
  AnalogyOptions wrong;
  wrong.a_region = Volume(8, 8, 8, 1, 1.0f);
  EXPECT_THROW(synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field, wrong), InvalidInput);
}
