// Model thickness: known thicknesses (a slab, a sphere, a cylinder), the
// per-sample inscribed balls against a brute-force reference that measures
// them on the mesh itself (exact point-triangle distances), determinism
// across thread counts, cancel and bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "exsynth/errors.hpp"
#include "exsynth/thickness.hpp"
#include "exsynth/voxelize.hpp"
#include "support/cancel.hpp"
#include "support/shapes.hpp"
#include "support/threads.hpp"
#include "voxel/triangle_distance.hpp"

using namespace exsynth;
using exsynth::testing::box;
using exsynth::testing::icosphere;
using ::testing::HasSubstr;

namespace {

// Closed cylinder along z: radius r, from z0 to z1, n sides, capped by fans.
TriangleMesh cylinder(float r, float z0, float z1, int n) {
  TriangleMesh m;
  for (int i = 0; i < n; ++i) {
    const float a = 2.0f * float(M_PI) * float(i) / float(n);
    m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), z0);
    m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), z1);
  }
  const int bottom = int(m.vertices.size()), top = bottom + 1;
  m.vertices.emplace_back(0.0f, 0.0f, z0);
  m.vertices.emplace_back(0.0f, 0.0f, z1);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n, b0 = 2 * i, t0 = 2 * i + 1, b1 = 2 * j, t1 = 2 * j + 1;
    m.faces.emplace_back(b0, b1, t1);
    m.faces.emplace_back(b0, t1, t0);
    m.faces.emplace_back(bottom, b1, b0);
    m.faces.emplace_back(top, t0, t1);
  }
  return m;
}

float mesh_distance(const TriangleMesh& m, const Eigen::Vector3f& p) {
  float best = std::numeric_limits<float>::max();
  for (const auto& f : m.faces)
    best = std::min(best, voxel::point_triangle_distance2(p, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]]));
  return std::sqrt(best);
}

// The reference: the same definition (the largest t for which the centre
// surface + t * inward stays at least t - h/2 from the surface, from the same
// surface point and normal) with exact distances to every triangle instead
// of the grid's interpolated ones, walked in 1/8-voxel steps.
float brute_force_diameter(const TriangleMesh& m, const ThicknessSample& s, float h) {
  auto fits = [&](float t) { return mesh_distance(m, s.surface + t * s.inward) >= t - 0.5f * h; };
  float good = 0.0f, t = h / 8;
  while (fits(t) && t < 100 * h) good = t, t += h / 8;
  float bad = t;
  for (int k = 0; k < 3; ++k) {
    const float mid = 0.5f * (good + bad);
    (fits(mid) ? good : bad) = mid;
  }
  return 2.0f * good;
}

ThicknessOptions at(int resolution) {
  ThicknessOptions o;
  o.resolution = resolution;
  return o;
}

}  // namespace

TEST(Thickness, SlabMeasuresItsThinSide) {
  const TriangleMesh slab = box({0, 0, 0}, {2.0f, 2.0f, 0.25f});
  const ThicknessResult r = model_thickness(slab, at(96));
  // The big faces (most of the area) touch balls of the slab's full 0.25.
  EXPECT_NEAR(r.thickness, 0.25, 1.0 * r.voxel_size);
  EXPECT_NEAR(r.median, r.thickness, 1e-9);
  EXPECT_LE(r.low, r.median);
  EXPECT_LE(r.median, r.high);
  EXPECT_GT(r.samples, 1000u);
}

TEST(Thickness, SphereMeasuresItsDiameter) {
  const ThicknessResult r = model_thickness(icosphere(1.0f, 4), at(64));
  EXPECT_NEAR(r.thickness, 2.0, 1.5 * r.voxel_size);
}

TEST(Thickness, CylinderMeasuresItsDiameterNotItsLength) {
  const ThicknessResult r = model_thickness(cylinder(0.3f, 0.0f, 3.0f, 48), at(96));
  EXPECT_NEAR(r.thickness, 0.6, 1.5 * r.voxel_size);
  // Sides dominate; the caps' balls are smaller, none larger.
  EXPECT_LE(r.high, 0.6 + 1.5 * r.voxel_size);
}

TEST(Thickness, SamplesMatchBruteForceOnTheMesh) {
  for (const TriangleMesh& mesh : {box({0, 0, 0}, {1.0f, 0.6f, 0.3f}), cylinder(0.4f, -0.5f, 0.5f, 24)}) {
    VoxelizeOptions vopt;
    vopt.resolution = 32;
    const Volume sdf = voxelize(mesh, vopt).sdf;
    const float h = float(sdf.transform().voxel_size);
    const std::vector<ThicknessSample> samples = thickness_samples(sdf);
    ASSERT_GT(samples.size(), 200u);
    std::vector<float> fast, exact;
    std::size_t close = 0;
    for (const ThicknessSample& s : samples) {
      const float ref = brute_force_diameter(mesh, s, h);
      fast.push_back(s.diameter);
      exact.push_back(ref);
      close += std::abs(s.diameter - ref) <= 1.0f * h;
    }
    // Per sample within a voxel nearly everywhere (the grid's distance is cut
    // off across the medial axis, by at most half a voxel of slack each way).
    EXPECT_GE(double(close), 0.95 * double(samples.size()));
    for (double q : {10.0, 50.0, 90.0}) EXPECT_NEAR(percentile_of(fast, q), percentile_of(exact, q), 1.0 * h) << q;
  }
}

TEST(Thickness, PercentileIsNearestRank) {
  EXPECT_EQ(percentile_of({3, 1, 2}, 0), 1);
  EXPECT_EQ(percentile_of({3, 1, 2}, 50), 2);
  EXPECT_EQ(percentile_of({3, 1, 2}, 100), 3);
  EXPECT_EQ(percentile_of({4, 1, 3, 2}, 25), 2);  // rank 0.75 -> 1
}

TEST(Thickness, SameResultOnAnyThreadCount) {
  const TriangleMesh mesh = cylinder(0.3f, 0.0f, 2.0f, 32);
  const ThicknessResult one = exsynth::testing::on_threads(1, [&] { return model_thickness(mesh, at(48)); });
  for (int n : {2, 8}) {
    const ThicknessResult r = exsynth::testing::on_threads(n, [&] { return model_thickness(mesh, at(48)); });
    EXPECT_EQ(r.thickness, one.thickness);
    EXPECT_EQ(r.samples, one.samples);
    EXPECT_EQ(r.low, one.low);
    EXPECT_EQ(r.high, one.high);
  }
}

TEST(Thickness, EveryStageCancels) {
  const TriangleMesh mesh = icosphere(1.0f, 3);
  exsynth::testing::expect_every_stage_cancels([&](ExecContext* ctx) { model_thickness(mesh, at(48), ctx); }, 2);
}

TEST(Thickness, BadInput) {
  const TriangleMesh cube = box({0, 0, 0}, {1, 1, 1});
  ThicknessOptions o;
  o.resolution = 8;
  EXPECT_THAT([&] { model_thickness(cube, o); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("resolution must be 16..1024 (got 8)")));
  o = {};
  o.percentile = 101;
  EXPECT_THAT([&] { model_thickness(cube, o); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("percentile must be in [0, 100]")));
  o.percentile = std::nan("");
  EXPECT_THROW(model_thickness(cube, o), InvalidInput);
  TriangleMesh flat;  // one triangle: no inside
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  flat.faces = {{0, 1, 2}};
  EXPECT_THAT([&] { model_thickness(flat, at(32)); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("no inside")));
}
