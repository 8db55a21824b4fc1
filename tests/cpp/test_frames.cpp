// Frames in volumes: orthonormal, N from the geometry, T following the field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "exsynth/frames.hpp"
#include "support/shapes.hpp"
#include "support/threads.hpp"

using namespace exsynth;

namespace {

// A sphere's signed distance on [-1, 1]^3 and the around-z field on an icosphere of the same radius.
struct SphereCase {
  Volume sdf;
  std::vector<Eigen::Vector3f> points, vectors;
};

SphereCase sphere_case(int n = 32, float radius = 0.6f) {
  SphereCase c;
  GridTransform xf;
  xf.voxel_size = 2.0 / n;
  xf.origin = {-1 + xf.voxel_size / 2, -1 + xf.voxel_size / 2, -1 + xf.voxel_size / 2};
  c.sdf = Volume(n, n, n, 1, 0.0f, xf);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const auto p = xf.index_to_world(x, y, z);
        c.sdf.at(x, y, z) = float(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - radius);
      }
  const TriangleMesh m = exsynth::testing::icosphere(radius, 3);
  c.points = m.vertices;
  for (const auto& p : m.vertices) c.vectors.push_back(Eigen::Vector3f::UnitZ().cross(p));
  return c;
}

Eigen::Vector3f at3(const Volume& v, int x, int y, int z) {
  return {v.at(x, y, z, 0), v.at(x, y, z, 1), v.at(x, y, z, 2)};
}

double angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::clamp(double(a.normalized().dot(b.normalized())), -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

TEST(Frames, OrthonormalRightHandedNormalFromGeometryTangentFromField) {
  const SphereCase c = sphere_case();
  const VolumeFrames f = volume_frames(c.sdf, c.points, c.vectors);
  const Volume& s = c.sdf;
  int checked_n = 0, checked_t = 0;
  for (int z = 0; z < s.nz(); ++z)
    for (int y = 0; y < s.ny(); ++y)
      for (int x = 0; x < s.nx(); ++x) {
        const Eigen::Vector3f t = at3(f.t, x, y, z), n = at3(f.n, x, y, z), b = at3(f.b, x, y, z);
        ASSERT_NEAR(t.norm(), 1.0f, 1e-4f);
        ASSERT_NEAR(n.norm(), 1.0f, 1e-4f);
        ASSERT_NEAR(t.dot(n), 0.0f, 1e-4f);
        ASSERT_LT((b - t.cross(n)).norm(), 1e-4f);
        const auto w = s.transform().index_to_world(x, y, z);
        const Eigen::Vector3f p{float(w[0]), float(w[1]), float(w[2])};
        if (p.norm() > 0.25f) {  // N: radial (the sphere's gradient)
          EXPECT_LT(angle_deg(n, p), 3.0) << p.transpose();
          ++checked_n;
        }
        if (std::hypot(p.x(), p.y()) > 0.3f && std::abs(s.at(x, y, z)) < 0.3f) {  // T: around z
          EXPECT_LT(angle_deg(t, Eigen::Vector3f::UnitZ().cross(p)), 12.0) << p.transpose();
          ++checked_t;
        }
      }
  EXPECT_GT(checked_n, 1000);
  EXPECT_GT(checked_t, 500);
}

TEST(Frames, SameWithOneOrEightThreads) {
  const SphereCase c = sphere_case(20);
  const VolumeFrames one = exsynth::testing::on_threads(1, [&] { return volume_frames(c.sdf, c.points, c.vectors); });
  const VolumeFrames two = exsynth::testing::on_threads(8, [&] { return volume_frames(c.sdf, c.points, c.vectors); });
  EXPECT_EQ(one.t.values(), two.t.values());
  EXPECT_EQ(one.b.values(), two.b.values());
}

TEST(Frames, BadInputNamesTheProblem) {
  const SphereCase c = sphere_case(12);
  EXPECT_THROW(volume_frames(c.sdf, {}, {}), InvalidInput);
  EXPECT_THROW(volume_frames(c.sdf, c.points, {c.vectors[0]}), InvalidInput);
  Volume far = c.sdf;
  for (float& v : far.values()) v = 10.0f;
  try {
    volume_frames(far, c.points, c.vectors);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("no voxels within"));
  }
  std::vector<Eigen::Vector3f> nan = c.vectors;
  nan[2].x() = std::nanf("");
  EXPECT_THROW(volume_frames(c.sdf, c.points, nan), InvalidInput);
}
