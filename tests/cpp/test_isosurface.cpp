// Volume -> mesh extraction, and the mesh helpers it is checked with.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "exsynth/errors.hpp"
#include "exsynth/exec_context.hpp"
#include "exsynth/isosurface.hpp"
#include "exsynth/mesh.hpp"

namespace {

using exsynth::GridTransform;
using exsynth::IsosurfaceOptions;
using exsynth::TriangleMesh;
using exsynth::Volume;

constexpr double kPi = 3.14159265358979323846;

// A box of n^3 voxels of size h centred at world `box_centre`, holding a
// sphere of `radius` centred at `centre`; f maps the signed distance to the
// stored value.
template <class F>
Volume sphere_volume(int n, double h, double radius, std::array<double, 3> box_centre,
                     std::array<double, 3> centre, F f) {
  GridTransform xf;
  xf.voxel_size = h;
  xf.origin = {box_centre[0] - h * (n - 1) / 2.0, box_centre[1] - h * (n - 1) / 2.0,
               box_centre[2] - h * (n - 1) / 2.0};
  Volume v(n, n, n, 1, 0.0f, xf);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const auto p = xf.index_to_world(x, y, z);
        const double d = std::sqrt((p[0] - centre[0]) * (p[0] - centre[0]) +
                                   (p[1] - centre[1]) * (p[1] - centre[1]) +
                                   (p[2] - centre[2]) * (p[2] - centre[2])) -
                         radius;
        v.at(x, y, z) = float(f(d));
      }
  return v;
}

// Closed and consistently oriented: every directed edge appears once and its
// reverse appears once.
bool is_closed_and_oriented(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) ++edges[{f[k], f[(k + 1) % 3]}];
  for (const auto& [e, count] : edges) {
    if (count != 1) return false;
    auto rev = edges.find({e.second, e.first});
    if (rev == edges.end() || rev->second != 1) return false;
  }
  return true;
}

TriangleMesh unit_cube() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(float(i & 1), float((i >> 1) & 1), float(i >> 2));
  // Counter-clockwise seen from outside.
  const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                        {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& t : f) m.faces.emplace_back(t[0], t[1], t[2]);
  return m;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// ---- mesh helpers -------------------------------------------------------------

TEST(Mesh, EnclosedVolumeOfUnitCubeIsExact) {
  TriangleMesh cube = unit_cube();
  EXPECT_TRUE(is_closed_and_oriented(cube));
  EXPECT_EQ(exsynth::enclosed_volume(cube), 1.0);
  for (auto& f : cube.faces) std::swap(f[1], f[2]);
  EXPECT_EQ(exsynth::enclosed_volume(cube), -1.0);
  // Translation does not change a closed mesh's volume.
  for (auto& v : cube.vertices) v += Eigen::Vector3f(3.0f, -2.0f, 5.0f);
  EXPECT_NEAR(exsynth::enclosed_volume(cube), -1.0, 1e-9);
}

TEST(Mesh, ValidateNamesTheProblem) {
  EXPECT_NO_THROW(exsynth::validate_mesh(unit_cube()));
  auto message = [](const TriangleMesh& m) {
    try {
      exsynth::validate_mesh(m, "mesh 'target'");
    } catch (const exsynth::InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_TRUE(contains(message(TriangleMesh{}), "no vertices"));
  TriangleMesh no_faces = unit_cube();
  no_faces.faces.clear();
  EXPECT_TRUE(contains(message(no_faces), "no faces"));
  TriangleMesh nan = unit_cube();
  nan.vertices[5].y() = std::nanf("");
  const std::string nan_msg = message(nan);
  EXPECT_TRUE(contains(nan_msg, "vertex 5 of mesh 'target' is not finite (nan)")) << nan_msg;
  TriangleMesh bad = unit_cube();
  bad.faces[3][1] = 99;
  const std::string bad_msg = message(bad);
  EXPECT_TRUE(contains(bad_msg, "face 3 of mesh 'target' refers to vertex 99 but the mesh has 8 vertices"))
      << bad_msg;
  bad.faces[3][1] = -1;
  EXPECT_TRUE(contains(message(bad), "refers to vertex -1"));
}

// ---- isosurface ---------------------------------------------------------------

TEST(Isosurface, SphereSdf) {
  const double h = 0.1, r = 1.5;
  Volume sdf = sphere_volume(48, h, r, {0.3, -0.2, 1.0}, {0.3, -0.2, 1.0}, [](double d) { return d; });
  exsynth::ExecContext ctx;
  TriangleMesh m = exsynth::isosurface(sdf, {}, &ctx);
  ASSERT_FALSE(m.faces.empty());
  EXPECT_NO_THROW(exsynth::validate_mesh(m));
  EXPECT_TRUE(is_closed_and_oriented(m));
  for (const auto& v : m.vertices) {
    const double dist = (v.cast<double>() - Eigen::Vector3d(0.3, -0.2, 1.0)).norm();
    ASSERT_NEAR(dist, r, 0.5 * h);
  }
  const double want = 4.0 / 3.0 * kPi * r * r * r;
  const double got = exsynth::enclosed_volume(m);
  EXPECT_GT(got, 0.0);
  EXPECT_NEAR(got, want, 0.03 * want);
  EXPECT_EQ(ctx.stage(), "isosurface");
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);
}

TEST(Isosurface, TinyVoxelsWork) {
  // A model a millionth of a unit across: OpenVDB refuses such scales in a
  // transform, so meshing runs in index space. Same shape as SphereSdf, scaled.
  const double s = 1e-6, h = 0.1 * s, r = 1.5 * s;
  Volume sdf = sphere_volume(48, h, r, {0.3 * s, 0, 0}, {0.3 * s, 0, 0}, [](double d) { return d; });
  TriangleMesh m = exsynth::isosurface(sdf);
  ASSERT_FALSE(m.faces.empty());
  EXPECT_TRUE(is_closed_and_oriented(m));
  for (const auto& v : m.vertices) ASSERT_NEAR((v.cast<double>() - Eigen::Vector3d(0.3 * s, 0, 0)).norm(), r, 0.5 * h);
  const double want = 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(exsynth::enclosed_volume(m), want, 0.03 * want);
}

TEST(Isosurface, InvertedDensityIsOrientedOutwards) {
  const double h = 0.1, r = 1.2;
  // A smooth density: 1 inside, 0 outside, 0.5 on the sphere.
  Volume density =
      sphere_volume(40, h, r, {0, 0, 0}, {0, 0, 0}, [h](double d) { return 1.0 / (1.0 + std::exp(d / h)); });
  IsosurfaceOptions opt;
  opt.isovalue = 0.5;
  opt.invert = true;
  TriangleMesh m = exsynth::isosurface(density, opt);
  ASSERT_FALSE(m.faces.empty());
  EXPECT_TRUE(is_closed_and_oriented(m));
  const double want = 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_GT(exsynth::enclosed_volume(m), 0.0);
  EXPECT_NEAR(exsynth::enclosed_volume(m), want, 0.03 * want);

  // Without invert the inside is the complement: the box minus the sphere,
  // capped within half a voxel beyond the border voxels' centres.
  opt.invert = false;
  TriangleMesh shell = exsynth::isosurface(density, opt);
  EXPECT_TRUE(is_closed_and_oriented(shell));
  const double shell_volume = exsynth::enclosed_volume(shell);
  EXPECT_GT(shell_volume, std::pow(39 * h, 3) - 1.03 * want);
  EXPECT_LT(shell_volume, std::pow(40 * h, 3) - 0.97 * want);
}

TEST(Isosurface, ShapesCutByTheBoxComeOutClosed) {
  // A sphere centred on the box's corner voxel: an eighth of it is inside
  // the box, capped by three of the box's faces.
  const int n = 12;
  const double h = 1.0, r = 6.0;
  Volume sdf = sphere_volume(n, h, r, {5.5, 5.5, 5.5}, {0, 0, 0}, [](double d) { return d; });
  TriangleMesh m = exsynth::isosurface(sdf);
  ASSERT_FALSE(m.faces.empty());
  EXPECT_TRUE(is_closed_and_oriented(m));
  // The caps lie between the border voxels' centres and half a voxel beyond.
  const double eighth = 4.0 / 3.0 * kPi * r * r * r / 8.0;
  const double slabs = 3 * 0.5 * kPi * r * r / 4.0;
  const double vol = exsynth::enclosed_volume(m);
  EXPECT_GT(vol, 0.97 * eighth);
  EXPECT_LT(vol, eighth + slabs);
}

TEST(Isosurface, AdaptiveMeshIsSmallerAndStillClosed) {
  Volume sdf = sphere_volume(32, 0.1, 1.0, {0, 0, 0}, {0, 0, 0}, [](double d) { return d; });
  IsosurfaceOptions opt;
  const std::size_t uniform = exsynth::isosurface(sdf, opt).faces.size();
  opt.adaptivity = 0.1;
  TriangleMesh m = exsynth::isosurface(sdf, opt);
  EXPECT_LT(m.faces.size(), uniform / 2);
  EXPECT_TRUE(is_closed_and_oriented(m));
  // Coarse flat facets cut corners: the volume drops a little (~5% here).
  const double want = 4.0 / 3.0 * kPi;
  EXPECT_GT(exsynth::enclosed_volume(m), 0.9 * want);
  EXPECT_LT(exsynth::enclosed_volume(m), want);
}

TEST(Isosurface, UsesTheRequestedChannel) {
  Volume two(10, 10, 10, 2, 1.0f);
  for (int z = 0; z < 10; ++z)
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 10; ++x) two.at(x, y, z, 1) = float(x) - 4.5f;  // a plane at x = 4.5
  IsosurfaceOptions opt;
  EXPECT_TRUE(exsynth::isosurface(two, opt).faces.empty());
  opt.channel = 1;
  TriangleMesh m = exsynth::isosurface(two, opt);
  ASSERT_FALSE(m.faces.empty());
  EXPECT_TRUE(is_closed_and_oriented(m));
  // Inside is x < 4.5, capped at the box: about 5 x 10 x 10 voxels.
  EXPECT_NEAR(exsynth::enclosed_volume(m), 5.0 * 9.0 * 9.0, 0.2 * 5.0 * 9.0 * 9.0);
}

TEST(Isosurface, ConstantVolumeGivesEmptyMesh) {
  for (float value : {-1.0f, 0.0f, 2.0f}) {
    for (bool invert : {false, true}) {
      IsosurfaceOptions opt;
      opt.invert = invert;
      TriangleMesh m = exsynth::isosurface(Volume(6, 6, 6, 1, value), opt);
      EXPECT_TRUE(m.vertices.empty()) << value << " " << invert;
      EXPECT_TRUE(m.faces.empty()) << value << " " << invert;
    }
  }
}

TEST(Isosurface, RejectsBadInput) {
  IsosurfaceOptions opt;
  opt.channel = 1;
  EXPECT_THROW(exsynth::isosurface(Volume(4, 4, 4, 1), opt), exsynth::InvalidInput);
  EXPECT_THROW(exsynth::isosurface(Volume()), exsynth::InvalidInput);
  Volume nan(4, 4, 4, 1, 1.0f);
  nan.at(1, 2, 3) = std::nanf("");
  try {
    exsynth::isosurface(nan);
    FAIL() << "expected InvalidInput";
  } catch (const exsynth::InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "(1, 2, 3)")) << e.what();
  }
  opt = {};
  opt.adaptivity = 2.0;
  EXPECT_THROW(exsynth::isosurface(Volume(4, 4, 4, 1), opt), exsynth::InvalidInput);
}

TEST(Isosurface, Cancelled) {
  Volume sdf = sphere_volume(16, 0.1, 0.5, {0, 0, 0}, {0, 0, 0}, [](double d) { return d; });
  exsynth::ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(exsynth::isosurface(sdf, {}, &ctx), exsynth::Cancelled);
}

}  // namespace
