// Direction fields: unit tangent output, painted vertices kept, agreement
// with an analytic field on a sphere and a grid, the sparse solve against a
// dense solve and against Turk's repeated averaging (brute-force twins),
// determinism across thread counts, presets, cancel and bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <cmath>
#include <thread>

#include "exsynth/errors.hpp"
#include "exsynth/field.hpp"
#include "exsynth/rng.hpp"
#include "field/laplacian.hpp"
#include "support/load_obj.hpp"
#include "support/shapes.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using exsynth::testing::asset;
using exsynth::testing::icosphere;
using ::testing::HasSubstr;
using V3 = Eigen::Vector3f;
using Field = std::vector<V3>;

namespace {

constexpr double kDeg = 180.0 / M_PI;

// Area-weighted normals written out again (not the library's), so the
// tangency checks do not trust the code under test.
std::vector<Eigen::Vector3d> reference_normals(const TriangleMesh& m) {
  std::vector<Eigen::Vector3d> n(m.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& f : m.faces) {
    const Eigen::Vector3d a = m.vertices[f[0]].cast<double>(), b = m.vertices[f[1]].cast<double>(),
                          c = m.vertices[f[2]].cast<double>();
    for (int k = 0; k < 3; ++k) n[f[k]] += (b - a).cross(c - a);
  }
  for (auto& v : n) v.normalize();
  return n;
}

// atan2 in double: acos of a float dot product cannot resolve below ~0.02 degrees.
double angle_deg(const V3& a, const V3& b) {
  const Eigen::Vector3d u = a.cast<double>(), v = b.cast<double>();
  return std::atan2(u.cross(v).norm(), u.dot(v)) * kDeg;
}

void expect_unit_tangent(const TriangleMesh& m, const Field& f) {
  const auto n = reference_normals(m);
  ASSERT_EQ(f.size(), m.vertices.size());
  double worst_len = 0, worst_dot = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    ASSERT_TRUE(f[i].allFinite()) << "vertex " << i;
    worst_len = std::max(worst_len, std::abs(double(f[i].norm()) - 1.0));
    worst_dot = std::max(worst_dot, std::abs(f[i].cast<double>().dot(n[i])));
  }
  EXPECT_LT(worst_len, 1e-4);
  EXPECT_LT(worst_dot, 1e-4);
}

// Regular grid in the z = 0 plane: (nx x ny) vertices, x fastest, two
// triangles per cell.
TriangleMesh grid(int nx, int ny, float h = 1.0f) {
  TriangleMesh m;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) m.vertices.emplace_back(x * h, y * h, 0.0f);
  for (int y = 0; y + 1 < ny; ++y)
    for (int x = 0; x + 1 < nx; ++x) {
      const int a = y * nx + x;
      m.faces.emplace_back(a, a + 1, a + nx + 1);
      m.faces.emplace_back(a, a + nx + 1, a + nx);
    }
  return m;
}

// Capped cylinder around the z axis: `rings` circles of `seg` vertices from
// z = 0 to z = height, plus a centre vertex on each cap (on the axis).
TriangleMesh cylinder(int seg, int rings, float radius, float height) {
  TriangleMesh m;
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < seg; ++s) {
      const double t = 2 * M_PI * s / seg;
      m.vertices.emplace_back(radius * std::cos(t), radius * std::sin(t), height * r / (rings - 1));
    }
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < seg; ++s) {
      const int a = r * seg + s, b = r * seg + (s + 1) % seg;
      m.faces.emplace_back(a, b, b + seg);
      m.faces.emplace_back(a, b + seg, a + seg);
    }
  const int bottom = int(m.vertices.size()), top = bottom + 1;
  m.vertices.emplace_back(0, 0, 0);
  m.vertices.emplace_back(0, 0, height);
  for (int s = 0; s < seg; ++s) {
    m.faces.emplace_back(bottom, (s + 1) % seg, s);
    m.faces.emplace_back(top, (rings - 1) * seg + s, (rings - 1) * seg + (s + 1) % seg);
  }
  return m;
}

int nearest_vertex(const TriangleMesh& m, const V3& p) {
  int best = 0;
  for (int i = 1; i < int(m.vertices.size()); ++i)
    if ((m.vertices[i] - p).squaredNorm() < (m.vertices[best] - p).squaredNorm()) best = i;
  return best;
}

// A few painted vertices with pseudo-random directions (not tangent: the
// engine must project them).
Field random_strokes(const TriangleMesh& m, int count, std::uint64_t seed) {
  Field g(m.vertices.size(), V3::Zero());
  for (int k = 0; k < count; ++k) {
    IndexRng r(seed, std::uint64_t(k));
    const int v = int(r.uniform() * double(m.vertices.size()));
    g[v] = V3(float(r.uniform() - 0.5), float(r.uniform() - 0.5), float(r.uniform() - 0.5));
  }
  return g;
}

}  // namespace

// ---- diffusion ---------------------------------------------------------------

TEST(FieldDiffuse, UnitTangentEverywhereAndPaintedVerticesKeepTheirDirection) {
  const TriangleMesh m = exsynth::testing::load_obj(asset("meshes/bunny.obj"));
  const Field g = random_strokes(m, 25, 3);
  for (FieldWeights w : {FieldWeights::Cotangent, FieldWeights::Uniform}) {
    DirectionFieldOptions opt;
    opt.weights = w;
    const Field f = diffuse_direction_field(m, g, opt);
    expect_unit_tangent(m, f);
    const auto n = reference_normals(m);
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (g[i].isZero()) continue;
      const Eigen::Vector3d proj = g[i].cast<double>() - g[i].cast<double>().dot(n[i]) * n[i];
      EXPECT_LT(angle_deg(f[i], proj.cast<float>()), 0.01) << "painted vertex " << i;
    }
  }
}

TEST(FieldDiffuse, SphereConstrainedByTheAroundZPresetReproducesItAwayFromThePoles) {
  // 12 painted vertices (3 latitudes x 4 longitudes) taken from the preset,
  // on a 10k-vertex sphere (so the multigrid path solves it).
  const TriangleMesh m = icosphere(1.0f, 5);
  const Field preset = preset_direction_field(m, FieldPreset::AroundAxis, V3(0, 0, 1));
  Field g(m.vertices.size(), V3::Zero());
  for (double lat : {-45.0, 0.0, 45.0})
    for (int k = 0; k < 4; ++k) {
      const double lon = (k * 90.0 + (lat == 0 ? 0 : 45)) / kDeg, la = lat / kDeg;
      const int v = nearest_vertex(m, V3(float(std::cos(la) * std::cos(lon)), float(std::cos(la) * std::sin(lon)),
                                         float(std::sin(la))));
      g[v] = preset[v];
    }
  const Field f = diffuse_direction_field(m, g);
  expect_unit_tangent(m, f);
  // Stated tolerance: within 72 degrees of latitude (|z| < 0.95) every
  // vertex is within 6 degrees of the preset (measured: 4.3; 3.4-4.5 from
  // 642 to 41k vertices). At the poles the preset is singular and the
  // interpolated vector nearly cancels, so no direction is expected there.
  double worst = 0;
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    if (std::abs(m.vertices[i].z()) < 0.95f) worst = std::max(worst, angle_deg(f[i], preset[i]));
  EXPECT_LT(worst, 6.0);
}

TEST(FieldDiffuse, TwoStrokesOnAGridBlendLinearlyAndSmoothly) {
  // Left column painted +x, right column painted +y. The harmonic
  // interpolant is linear in x (cotangent weights reproduce linear
  // functions, also at the free top and bottom borders), so the field at
  // column t is normalise((1 - t, t, 0)).
  const int nx = 41, ny = 21;
  const TriangleMesh m = grid(nx, ny);
  Field g(m.vertices.size(), V3::Zero());
  for (int y = 0; y < ny; ++y) {
    g[y * nx] = V3(1, 0, 0);
    g[y * nx + nx - 1] = V3(0, 2, 0);  // length does not weigh
  }
  const Field f = diffuse_direction_field(m, g);
  expect_unit_tangent(m, f);
  double worst_step = 0;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const float t = float(x) / (nx - 1);
      EXPECT_LT(angle_deg(f[y * nx + x], V3(1 - t, t, 0)), 1e-3) << x << "," << y;
      if (x > 0) worst_step = std::max(worst_step, angle_deg(f[y * nx + x], f[y * nx + x - 1]));
      if (y > 0) worst_step = std::max(worst_step, angle_deg(f[y * nx + x], f[(y - 1) * nx + x]));
    }
  EXPECT_LT(worst_step, 3.0);  // 90 degrees over 40 steps; steepest at the middle (2 / 40 rad)
}

TEST(FieldDiffuse, SparseSolveMatchesADenseSolveOfIndependentlyBuiltCotangentWeights) {
  // Jitter the sphere so weights differ per edge (and some clamp).
  TriangleMesh m = icosphere(1.0f, 2);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    IndexRng r(11, i);
    m.vertices[i] *= float(0.8 + 0.4 * r.uniform());
  }
  const Field g = random_strokes(m, 6, 5);
  const Field f = diffuse_direction_field(m, g);

  const int n = int(m.vertices.size());
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, n);
  for (const auto& face : m.faces)
    for (int k = 0; k < 3; ++k) {
      const int p = face[k], q = face[(k + 1) % 3], r = face[(k + 2) % 3];
      const Eigen::Vector3d u = (m.vertices[q] - m.vertices[p]).cast<double>(),
                            v = (m.vertices[r] - m.vertices[p]).cast<double>();
      const double half_cot = 0.5 / std::tan(std::acos(u.normalized().dot(v.normalized())));
      w(q, r) += half_cot;
      w(r, q) += half_cot;
    }
  const auto normals = reference_normals(m);
  std::vector<int> free_rows, row(n, -1);
  Eigen::MatrixX3d fixed = Eigen::MatrixX3d::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    if (g[i].isZero()) {
      row[i] = int(free_rows.size());
      free_rows.push_back(i);
    } else {
      const Eigen::Vector3d p = g[i].cast<double>() - g[i].cast<double>().dot(normals[i]) * normals[i];
      fixed.row(i) = p.normalized().transpose();
    }
  }
  const int nf = int(free_rows.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(nf, nf);
  Eigen::MatrixX3d b = Eigen::MatrixX3d::Zero(nf, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j || w(i, j) == 0 || row[i] < 0) continue;
      const double wij = std::clamp(w(i, j), field::kMinCotWeight, field::kMaxCotWeight);
      a(row[i], row[i]) += wij;
      if (row[j] >= 0)
        a(row[i], row[j]) -= wij;
      else
        b.row(row[i]) += wij * fixed.row(j);
    }
  const Eigen::MatrixX3d x = a.ldlt().solve(b);
  for (int r = 0; r < nf; ++r) {
    const int i = free_rows[r];
    const Eigen::Vector3d t = x.row(r).transpose() - x.row(r).dot(normals[i]) * normals[i];
    EXPECT_LT(angle_deg(f[i], t.cast<float>()), 1e-3) << "vertex " << i;
  }
}

TEST(FieldDiffuse, DirectSolveIsTheLimitOfTurksRepeatedNeighbourAveraging) {
  // Turk 2001: replace every free vertex by the mean of its neighbours until
  // nothing moves (Gauss-Seidel sweeps, uniform weights), then project and
  // normalise.
  const TriangleMesh m = icosphere(1.0f, 2);
  const Field g = random_strokes(m, 5, 9);
  DirectionFieldOptions opt;
  opt.weights = FieldWeights::Uniform;
  const Field f = diffuse_direction_field(m, g, opt);

  const int n = int(m.vertices.size());
  const auto normals = reference_normals(m);
  std::vector<std::vector<int>> nbr(n);
  for (const auto& e : field::edge_weights(m, FieldWeights::Uniform)) {
    nbr[e.i].push_back(e.j);
    nbr[e.j].push_back(e.i);
  }
  std::vector<Eigen::Vector3d> x(n, Eigen::Vector3d::Zero());
  for (int i = 0; i < n; ++i)
    if (!g[i].isZero()) x[i] = (g[i].cast<double>() - g[i].cast<double>().dot(normals[i]) * normals[i]).normalized();
  for (int sweep = 0; sweep < 4000; ++sweep)
    for (int i = 0; i < n; ++i) {
      if (!g[i].isZero()) continue;
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      for (int j : nbr[i]) s += x[j];
      x[i] = s / double(nbr[i].size());
    }
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d t = x[i] - x[i].dot(normals[i]) * normals[i];
    EXPECT_LT(angle_deg(f[i], t.cast<float>()), 1e-2) << "vertex " << i;
  }
}

TEST(FieldDiffuse, SameOutputWithOneOrEightThreads) {
  // 26k vertices: the multigrid path, whose matrix products run in parallel.
  const TriangleMesh m = exsynth::testing::load_obj(asset("meshes/armadillo.obj"));
  const Field g = random_strokes(m, 20, 4);
  const Field one = exsynth::testing::on_threads(1, [&] { return diffuse_direction_field(m, g); });
  const Field two = exsynth::testing::on_threads(8, [&] { return diffuse_direction_field(m, g); });
  EXPECT_EQ(one, two);
}

TEST(FieldDiffuse, UnpaintedComponentsAndUnusedVerticesGetTheProjectedFallbackAxis) {
  // Two spheres side by side, strokes on the first only, plus a vertex no
  // face uses.
  TriangleMesh m = icosphere(1.0f, 2);
  const TriangleMesh other = icosphere(1.0f, 2, V3(3, 0, 0));
  const int offset = int(m.vertices.size());
  m.vertices.insert(m.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& f : other.faces) m.faces.emplace_back(f + Eigen::Vector3i::Constant(offset));
  m.vertices.emplace_back(9, 9, 9);
  Field g(m.vertices.size(), V3::Zero());
  g[0] = V3(1, 0, 0);
  g[7] = V3(0, 1, 0);
  DirectionFieldOptions opt;
  opt.fallback_axis = V3(0, 0, 2);
  const Field f = diffuse_direction_field(m, g, opt);
  const auto n = reference_normals(m);
  for (std::size_t i = offset; i + 1 < m.vertices.size(); ++i) {
    ASSERT_TRUE(f[i].allFinite());
    EXPECT_NEAR(f[i].norm(), 1.0f, 1e-5f);
    EXPECT_LT(std::abs(f[i].cast<double>().dot(n[i])), 1e-4);
    if (std::abs(n[i].z()) < 0.99) {  // away from the poles: the projected +z
      const Eigen::Vector3d z = Eigen::Vector3d::UnitZ() - n[i].z() * n[i];
      EXPECT_LT(angle_deg(f[i], z.cast<float>()), 1e-3) << i;
    }
  }
  EXPECT_EQ(f.back(), V3(0, 0, 1));  // no normal: the axis itself
}

TEST(FieldDiffuse, ReportsProgressAndCancels) {
  const TriangleMesh m = icosphere(1.0f, 2);
  const Field g = random_strokes(m, 3, 1);
  ExecContext ctx;
  diffuse_direction_field(m, g, {}, &ctx);
  EXPECT_DOUBLE_EQ(ctx.progress(), 1.0);
  EXPECT_THAT(ctx.stage(), HasSubstr("direction field"));
  ExecContext cancelled;
  cancelled.cancel();
  EXPECT_THROW(diffuse_direction_field(m, g, {}, &cancelled), Cancelled);
}

TEST(FieldDiffuse, CancelFromAnotherThreadStopsTheSolve) {
  const TriangleMesh m = exsynth::testing::load_obj(asset("meshes/armadillo.obj"));
  const Field g = random_strokes(m, 20, 2);
  ExecContext ctx;
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    while (!done && ctx.stage() != "direction field: solve") std::this_thread::yield();
    ctx.cancel();
  });
  EXPECT_THROW(diffuse_direction_field(m, g, {}, &ctx), Cancelled);
  done = true;
  watcher.join();
}

// ---- the solver --------------------------------------------------------------

TEST(FieldSolver, MultigridAgreesWithTheDirectFactorisation) {
  // Force a deep hierarchy on a 10k-vertex mesh and compare with LDLT.
  TriangleMesh m = icosphere(1.0f, 5);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    IndexRng r(2, i);
    m.vertices[i] *= float(0.9 + 0.2 * r.uniform());
  }
  const int n = int(m.vertices.size());
  std::vector<char> fixed(std::size_t(n), 0);
  Eigen::MatrixX3d values = Eigen::MatrixX3d::Zero(n, 3);
  for (int k = 0; k < 15; ++k) {
    IndexRng r(8, std::uint64_t(k));
    const int v = int(r.uniform() * n);
    fixed[v] = 1;
    values.row(v) = Eigen::RowVector3d(r.uniform() - 0.5, r.uniform() - 0.5, r.uniform() - 0.5).normalized();
  }
  const auto edges = field::edge_weights(m, FieldWeights::Cotangent);
  field::SpdSolveOptions direct, multigrid;
  direct.direct_size = n;
  multigrid.direct_size = 200;
  const auto exact = field::harmonic_interpolate(std::size_t(n), edges, fixed, values, nullptr, direct);
  const auto fast = field::harmonic_interpolate(std::size_t(n), edges, fixed, values, nullptr, multigrid);
  EXPECT_EQ(exact.stats.levels, 1);
  EXPECT_GE(fast.stats.levels, 3);
  EXPECT_LE(fast.stats.iterations, 40);  // about 15: the cycle does not slow down with depth
  EXPECT_LE(fast.stats.residual, multigrid.tolerance);
  EXPECT_LT((fast.values - exact.values).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(FieldErrors, RejectsBadInputWithMessagesNamingTheProblem) {
  const TriangleMesh m = icosphere(1.0f, 1);
  auto message = [&](const TriangleMesh& mesh, const Field& g, DirectionFieldOptions opt = {}) {
    try {
      diffuse_direction_field(mesh, g, opt);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  Field g(m.vertices.size(), V3::Zero());
  EXPECT_THAT(message(m, g), HasSubstr("no non-zero vectors; paint at least one stroke or use a preset"));
  g[2] = V3(1, 0, 0);
  EXPECT_THAT(message(m, Field(3, V3(1, 0, 0))), HasSubstr("has 3 vectors but the mesh has 42 vertices"));
  Field nan = g;
  nan[5] = V3(0, NAN, 0);
  EXPECT_THAT(message(m, nan), HasSubstr("vector 5 of the direction field is not finite"));
  Field inf = g;
  inf[6] = V3(INFINITY, 0, 0);
  EXPECT_THAT(message(m, inf), HasSubstr("vector 6"));
  Field normal_only(m.vertices.size(), V3::Zero());
  normal_only[4] = m.vertices[4] * 3.0f;  // on a unit sphere: along the normal
  EXPECT_THAT(message(m, normal_only), HasSubstr("along the surface normal"));
  DirectionFieldOptions bad_axis;
  bad_axis.fallback_axis = V3::Zero();
  EXPECT_THAT(message(m, g, bad_axis), HasSubstr("fallback_axis"));
  TriangleMesh broken = m;
  broken.vertices[1].x() = NAN;
  EXPECT_THAT(message(broken, g), HasSubstr("vertex 1 of mesh is not finite"));
  broken = m;
  broken.faces[3][1] = 99;
  EXPECT_THAT(message(broken, g), HasSubstr("face 3 of mesh refers to vertex 99"));
  EXPECT_THAT(message(TriangleMesh{}, {}), HasSubstr("no vertices"));
}

// ---- presets -----------------------------------------------------------------

TEST(FieldPresets, EveryPresetIsAUnitTangentFieldOnARealMesh) {
  const TriangleMesh m = exsynth::testing::load_obj(asset("meshes/bunny.obj"));
  const Field curve = {V3(-0.1f, 0.1f, 0), V3(0, 0.15f, 0.02f), V3(0.1f, 0.1f, 0)};
  for (FieldPreset p : {FieldPreset::AroundAxis, FieldPreset::AlongAxis, FieldPreset::AlongCurve}) {
    SCOPED_TRACE(int(p));
    expect_unit_tangent(m, preset_direction_field(m, p, V3(0, 1, 0), curve));
  }
}

TEST(FieldPresets, AroundAxisOnACylinderFollowsTheCircles) {
  const TriangleMesh m = cylinder(48, 10, 0.5f, 2.0f);
  const Field f = preset_direction_field(m, FieldPreset::AroundAxis, V3(0, 0, 1));
  expect_unit_tangent(m, f);
  const auto n = reference_normals(m);
  for (std::size_t i = 0; i + 2 < m.vertices.size(); ++i) {
    // Counter-clockwise about +z. On the cap rims the triangulation tilts
    // the normal a little sideways, so compare with the projected tangent.
    const Eigen::Vector3d circle = Eigen::Vector3d::UnitZ().cross(m.vertices[i].cast<double>());
    EXPECT_LT(angle_deg(f[i], (circle - circle.dot(n[i]) * n[i]).cast<float>()), 1e-3) << "vertex " << i;
    if (i >= 48 && i < 9 * 48) EXPECT_LT(angle_deg(f[i], circle.cast<float>()), 1e-3) << "vertex " << i;
  }
  // The cap centres lie on the axis: a fixed fallback, no NaN.
  for (std::size_t i = m.vertices.size() - 2; i < m.vertices.size(); ++i) {
    EXPECT_TRUE(f[i].allFinite());
    EXPECT_NEAR(f[i].norm(), 1.0f, 1e-5f);
  }
}

TEST(FieldPresets, AlongAxisRunsUpTheSideAndUsesOneFixedDirectionOnTheCaps) {
  const TriangleMesh m = cylinder(32, 6, 1.0f, 3.0f);
  const Field f = preset_direction_field(m, FieldPreset::AlongAxis, V3(0, 0, 5));
  expect_unit_tangent(m, f);
  // Middle rings (not the cap rims, whose normals tilt): straight up.
  for (int i = 32; i < 4 * 32; ++i) EXPECT_LT(angle_deg(f[i], V3(0, 0, 1)), 1e-3);
  // Cap centres face the axis: both get the same fixed direction.
  const std::size_t top = m.vertices.size() - 1, bottom = top - 1;
  EXPECT_LT(angle_deg(f[top], f[bottom]), 1e-4);
}

TEST(FieldPresets, AlongACircularCurveMatchesAroundTheAxis) {
  const TriangleMesh m = cylinder(48, 10, 0.5f, 2.0f);
  Field circle;
  for (int k = 0; k <= 64; ++k)  // closed: the first point repeated
    circle.emplace_back(0.6f * float(std::cos(2 * M_PI * k / 64)), 0.6f * float(std::sin(2 * M_PI * k / 64)), 1.0f);
  const Field along = preset_direction_field(m, FieldPreset::AlongCurve, V3(0, 0, 1), circle);
  const Field around = preset_direction_field(m, FieldPreset::AroundAxis, V3(0, 0, 1));
  expect_unit_tangent(m, along);
  double worst = 0;
  for (std::size_t i = 0; i + 2 < m.vertices.size(); ++i) worst = std::max(worst, angle_deg(along[i], around[i]));
  // Corner tangents are blended along each segment, so the polyline's
  // 5.6-degree turns do not show as jumps.
  EXPECT_LT(worst, 1.0);  // measured: 0.39
}

TEST(FieldPresets, AlongAStraightCurveOnAPlaneIsTheCurveDirection) {
  const TriangleMesh m = grid(12, 9, 0.1f);
  const Field f = preset_direction_field(m, FieldPreset::AlongCurve, V3(0, 0, 1),
                                         {V3(-1, 0.3f, 0), V3(-1, 0.3f, 0), V3(2, 0.3f, 0)});
  for (const V3& t : f) EXPECT_LT(angle_deg(t, V3(1, 0, 0)), 1e-4);
}

TEST(FieldPresets, PolesOfASphereGetAFiniteTangent) {
  // Icosphere vertices 0 and 3 are antipodal: an axis through them puts two
  // vertices on the axis with normals along it, where both presets degenerate.
  const TriangleMesh m = icosphere(2.0f, 3);
  const V3 axis = m.vertices[0];
  for (FieldPreset p : {FieldPreset::AroundAxis, FieldPreset::AlongAxis}) {
    SCOPED_TRACE(int(p));
    const Field f = preset_direction_field(m, p, axis);
    expect_unit_tangent(m, f);
    EXPECT_LT(std::abs(f[0].dot(axis.normalized())), 1e-5f);
  }
}

TEST(FieldErrors, PresetsRejectBadAxesAndCurves) {
  const TriangleMesh m = icosphere(1.0f, 1);
  auto message = [&](FieldPreset p, const V3& axis, const Field& curve) {
    try {
      preset_direction_field(m, p, axis, curve);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_THAT(message(FieldPreset::AroundAxis, V3::Zero(), {}), HasSubstr("'axis' must be a finite, non-zero"));
  EXPECT_THAT(message(FieldPreset::AlongAxis, V3(NAN, 0, 1), {}), HasSubstr("'axis'"));
  EXPECT_THAT(message(FieldPreset::AlongCurve, V3(0, 0, 1), {}), HasSubstr("at least 2 points, got 0"));
  EXPECT_THAT(message(FieldPreset::AlongCurve, V3(0, 0, 1), {V3(0, 0, 0), V3(1, NAN, 0)}),
              HasSubstr("curve point 1 is not finite"));
  EXPECT_THAT(message(FieldPreset::AlongCurve, V3(0, 0, 1), {V3(1, 1, 1), V3(1, 1, 1)}),
              HasSubstr("the same point"));
}
