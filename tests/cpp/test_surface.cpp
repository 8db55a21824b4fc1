// Synthesis on subdivision surfaces: limit points against known surfaces and
// the closed-form vertex limit, derivatives against finite differences,
// ptex adjacency continuity, walks and neighbourhoods on flat surfaces (also
// across extraordinary vertices) against plain 2D grids, vertex charts (stars
// and valences, map/inverse identity, Jacobians against finite differences,
// chart samples against exact walks), coherent and
// multiscale synthesis (determinism across thread counts, coherence), the
// atlas gutters and limit mesh, bad inputs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "exsynth/errors.hpp"
#include "exsynth/surface.hpp"
#include "support/cancel.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"
#include "surface/charts.hpp"
#include "surface/methods.hpp"
#include "surface/texels.hpp"
#include "surface/walk.hpp"

using namespace exsynth;
using ::testing::HasSubstr;
using V3 = Eigen::Vector3f;
using V3d = Eigen::Vector3d;

namespace {

PolygonMesh cube() {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back(V3(i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f));
  const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& q : f) {
    m.face_sizes.push_back(4);
    for (int v : q) m.face_vertices.push_back(v);
  }
  return m;
}

/// A square pyramid: 4 triangles (3 ptex sub-faces each) + 1 quad.
PolygonMesh pyramid() {
  PolygonMesh m;
  m.vertices = {V3(-1, -1, 0), V3(1, -1, 0), V3(1, 1, 0), V3(-1, 1, 0), V3(0, 0, 1.5f)};
  m.face_sizes = {4, 3, 3, 3, 3};
  m.face_vertices = {0, 3, 2, 1, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
  return m;
}

/// An n x n grid of unit quads in the z = 0 plane, u along x, v along y.
PolygonMesh flat_grid(int n) {
  PolygonMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(V3(float(i), float(j), 0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.face_sizes.push_back(4);
      const int a = j * (n + 1) + i;
      for (int v : {a, a + 1, a + n + 2, a + n + 1}) m.face_vertices.push_back(v);
    }
  return m;
}

/// A flat disc of quads around a valence-5 centre (ring vertices of valence 3
/// and 4 too): every point of its limit surface lies in z = 0.
PolygonMesh flat_star() {
  PolygonMesh m;
  m.vertices.push_back(V3(0, 0, 0));
  const int ring = 10, rings = 4;
  for (int k = 1; k <= rings; ++k)
    for (int i = 0; i < ring; ++i) {
      const double a = 2 * M_PI * i / ring;
      m.vertices.push_back(V3(float(k * std::cos(a)), float(k * std::sin(a)), 0));
    }
  auto id = [&](int k, int i) { return 1 + (k - 1) * ring + (i % ring); };
  for (int q = 0; q < ring / 2; ++q) {
    m.face_sizes.push_back(4);
    for (int v : {0, id(1, 2 * q), id(1, 2 * q + 1), id(1, 2 * q + 2)}) m.face_vertices.push_back(v);
  }
  for (int k = 1; k < rings; ++k)
    for (int i = 0; i < ring; ++i) {
      m.face_sizes.push_back(4);
      for (int v : {id(k, i), id(k + 1, i), id(k + 1, i + 1), id(k, i + 1)}) m.face_vertices.push_back(v);
    }
  return m;
}

/// A closed cylinder-like tube (open ends) of quads around the z axis.
PolygonMesh tube(int around, int along, float radius, float length) {
  PolygonMesh m;
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < around; ++i) {
      const double a = 2 * M_PI * i / around;
      m.vertices.push_back(V3(float(radius * std::cos(a)), float(radius * std::sin(a)), length * j / along));
    }
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const int a = j * around + i, b = j * around + (i + 1) % around;
      m.face_sizes.push_back(4);
      for (int v : {a, b, b + around, a + around}) m.face_vertices.push_back(v);
    }
  return m;
}

std::vector<V3> constant_field(std::size_t n, V3 v) { return std::vector<V3>(n, v); }

}  // namespace

// ---- limit surface ----------------------------------------------------------

TEST(SurfaceLimit, FlatGridInteriorIsTheAffinePlane) {
  // Uniform cubic B-splines reproduce linear functions: inside a regular
  // grid the limit point of face (i, j) at (u, v) is (i + u, j + v, 0).
  const SubdivSurface s(flat_grid(6));
  for (int j = 1; j < 5; ++j)
    for (int i = 1; i < 5; ++i) {
      const int f = j * 6 + i;
      for (double u : {0.0, 0.3, 1.0})
        for (double v : {0.0, 0.7, 1.0}) {
          const LimitFrame lf = s.evaluate({f, u, v});
          EXPECT_NEAR((lf.position - V3d(i + u, j + v, 0)).norm(), 0.0, 1e-9);
          EXPECT_NEAR((lf.du - V3d(1, 0, 0)).norm(), 0.0, 1e-9);
          EXPECT_NEAR((lf.dv - V3d(0, 1, 0)).norm(), 0.0, 1e-9);
        }
    }
}

TEST(SurfaceLimit, VertexLimitsMatchTheClosedForm) {
  // Halstead et al. 1993: a vertex of valence n on an all-quad mesh has the
  // limit (n^2 v + 4 sum(edge neighbours) + sum(diagonal neighbours)) / (n (n + 5)).
  for (const PolygonMesh& m : {cube(), flat_star()}) {
    const SubdivSurface s(m);
    std::map<int, std::set<int>> edge_nb, diag_nb;
    std::size_t at = 0;
    for (int size : m.face_sizes) {
      for (int i = 0; i < 4; ++i) {
        const int v = m.face_vertices[at + i];
        edge_nb[v].insert(m.face_vertices[at + (i + 1) % 4]);
        edge_nb[v].insert(m.face_vertices[at + (i + 3) % 4]);
        diag_nb[v].insert(m.face_vertices[at + (i + 2) % 4]);
      }
      at += std::size_t(size);
    }
    at = 0;
    int checked = 0;
    for (int f = 0; f < int(m.face_sizes.size()); ++f, at += 4) {
      const int v = m.face_vertices[at];
      const int n = int(edge_nb[v].size());
      if (n != int(diag_nb[v].size())) continue;  // a boundary vertex
      // Interior test on the star: only vertices away from its outer rim.
      if (m.vertices[std::size_t(v)].norm() > 3.5f) continue;
      V3d want = double(n * n) * m.vertices[std::size_t(v)].cast<double>();
      for (int e : edge_nb[v]) want += 4.0 * m.vertices[std::size_t(e)].cast<double>();
      for (int d : diag_nb[v]) want += m.vertices[std::size_t(d)].cast<double>();
      want /= double(n * (n + 5));
      const LimitFrame lf = s.evaluate({s.first_ptex_face(f), 0.0, 0.0});
      EXPECT_NEAR((lf.position - want).norm(), 0.0, 1e-6) << "valence " << n;
      ++checked;
    }
    EXPECT_GT(checked, 3);
  }
}

TEST(SurfaceLimit, DerivativesMatchFiniteDifferencesOnQuadsAndSubFaces) {
  // Quads (regular and Gregory patches at the cube's valence-3 corners): to
  // 1e-5. Sub-faces of triangles: Bfr's derivatives sit up to 0.6 % from the
  // finite differences of its own positions (measured on this pyramid, the
  // same for steps 1e-2 .. 1e-6); walks correct with positions, so this
  // bounds only their convergence speed.
  for (const PolygonMesh& m : {cube(), pyramid()}) {
    const SubdivSurface s(m);
    const double e = 1e-5;
    for (int f = 0; f < s.ptex_face_count(); ++f) {
      const bool quad = m.face_sizes[std::size_t(s.control_face(f))] == 4;
      const double tol = quad ? 1e-5 : 2e-2;
      for (double u : {0.2, 0.55, 0.9})
        for (double v : {0.15, 0.45, 0.8}) {
          const LimitFrame lf = s.evaluate({f, u, v});
          const V3d fu = (s.evaluate({f, u + e, v}).position - s.evaluate({f, u - e, v}).position) / (2 * e);
          const V3d fv = (s.evaluate({f, u, v + e}).position - s.evaluate({f, u, v - e}).position) / (2 * e);
          EXPECT_NEAR((lf.du - fu).norm(), 0.0, tol * fu.norm()) << "face " << f << " at " << u << ", " << v;
          EXPECT_NEAR((lf.dv - fv).norm(), 0.0, tol * fv.norm()) << "face " << f << " at " << u << ", " << v;
        }
    }
  }
}

TEST(SurfaceLimit, CrossingAnEdgeLandsOnTheSameLimitPoint) {
  // Quads next to quads, sub-faces next to sub-faces and quads next to the
  // half-edges of triangles (the pyramid's base).
  for (const PolygonMesh& m : {cube(), pyramid(), flat_star()}) {
    const SubdivSurface s(m);
    int shared = 0;
    for (int f = 0; f < s.ptex_face_count(); ++f)
      for (int e = 0; e < 4; ++e)
        for (double t : {0.0, 0.3, 0.8}) {
          const SubdivSurface::EdgeCrossing c = s.cross_edge(f, e, t);
          if (c.face < 0) continue;
          ++shared;
          double u, v, u2, v2;
          surface::from_edge(e, t, 0, u, v);
          surface::from_edge(c.edge, c.t, 0, u2, v2);
          EXPECT_NEAR((s.evaluate({f, u, v}).position - s.evaluate({c.face, u2, v2}).position).norm(), 0.0, 1e-6)
              << "face " << f << " edge " << e << " t " << t;
          // And back.
          const SubdivSurface::EdgeCrossing back = s.cross_edge(c.face, c.edge, c.t);
          EXPECT_EQ(back.face, f);
          EXPECT_NEAR(back.t, t, 1e-12);
        }
    EXPECT_GT(shared, 0);
  }
}

TEST(SurfaceLimit, PtexFaceCountsAndAreas) {
  const SubdivSurface p(pyramid());
  EXPECT_EQ(p.ptex_face_count(), 1 + 4 * 3);
  const SubdivSurface g(flat_grid(4));
  const std::vector<double> a = g.ptex_face_areas();
  EXPECT_NEAR(a[5], 1.0, 1e-9);  // an interior face
}

// ---- walking and neighbourhoods ----------------------------------------------

TEST(SurfaceWalk, OnAFlatGridAWalkIsAStraightLineAcrossEdges) {
  const SubdivSurface s(flat_grid(8));
  SurfacePoint p{3 * 8 + 3, 0.5, 0.5};  // face (3, 3): centre at (3.5, 3.5)
  const V3d d(2.3, -1.4, 0);
  ASSERT_TRUE(s.walk(p, d));
  EXPECT_NEAR((s.evaluate(p).position - V3d(5.8, 2.1, 0)).norm(), 0.0, 1e-7);
  EXPECT_EQ(p.face, 2 * 8 + 5);
}

TEST(SurfaceWalk, AroundExtraordinaryVerticesOnAFlatDiscWalksStayStraight) {
  const SubdivSurface s(flat_star());
  int checked = 0;
  for (int f = 0; f < s.ptex_face_count(); ++f) {
    const LimitFrame c = s.evaluate({f, 0.3, 0.4});
    if (c.position.norm() > 1.5) continue;
    for (int k = 0; k < 8; ++k) {
      const double a = 2 * M_PI * k / 8 + 0.1;
      const V3d d = 0.9 * V3d(std::cos(a), std::sin(a), 0);
      SurfacePoint p{f, 0.3, 0.4};
      ASSERT_TRUE(s.walk(p, d));
      EXPECT_NEAR((s.evaluate(p).position - (c.position + d)).norm(), 0.0, 1e-6) << "face " << f << " dir " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(SurfaceWalk, WalksStopAtBoundaries) {
  const SubdivSurface s(flat_grid(3));
  SurfacePoint p{4, 0.5, 0.5};
  EXPECT_FALSE(s.walk(p, V3d(10, 0, 0)));
  EXPECT_NEAR(p.u, 1.0, 1e-12);
  EXPECT_EQ(s.neighbour(p.face, 1).face, -1);
}

TEST(SurfaceNeighbourhood, SampledAcrossFaceEdgesEqualsThePlainGrid) {
  // 8 texels per unit face; a 5 x 5 neighbourhood of a texel next to a
  // corner spreads over four faces and must land where a 2D grid puts it.
  const PolygonMesh m = flat_grid(6);
  const SubdivSurface s(m);
  const double a = 0.6;  // field at 0.6 rad from x
  const V3 dir(float(std::cos(a)), float(std::sin(a)), 0);
  surface::TexelGrid grid(std::vector<int>(std::size_t(s.ptex_face_count()), 8));
  const surface::TexelFrames fr = surface::build_texel_frames(s, grid, constant_field(m.vertices.size(), dir), nullptr);
  const int f = 2 * 6 + 2;
  const std::size_t t = grid.offset[std::size_t(f)] + 7 * 8 + 7;  // top-right texel of face (2, 2)
  const double h = 0.125;
  const V3d c = s.evaluate(grid.centre(t)).position;
  const V3d e1(std::cos(a), std::sin(a), 0), e2(-std::sin(a), std::cos(a), 0);
  // Walked from the centre (sample_points), and marched row by row as the
  // synthesis does (march_points, with the tight and the landing tolerance).
  // how == 3: through the vertex chart of the nearest corner (all in-chart here).
  const surface::VertexCharts charts(s);
  for (int how = 0; how < 4; ++how) {
    SurfacePoint pts[25];
    bool valid[25];
    surface::ChartStats stats;
    if (how == 0)
      surface::sample_points(s, fr, t, h, 2, pts, valid);
    else if (how < 3)
      surface::march_points(s, fr, grid.centre(t), h * fr.t1[t].cast<double>(), h * fr.t2[t].cast<double>(), 2,
                            how == 2, pts, valid);
    else
      surface::chart_points(s, fr, charts, grid.centre(t), fr.du[t].cast<double>(), fr.dv[t].cast<double>(),
                            h * fr.t1[t].cast<double>(), h * fr.t2[t].cast<double>(), 2, false, pts, valid, &stats);
    if (how == 3) EXPECT_EQ(stats.walked, 0u);
    std::set<int> faces;
    for (int k = 0; k < 25; ++k) {
      const int l = k % 5 - 2, mm = k / 5 - 2;
      ASSERT_TRUE(valid[k]);
      faces.insert(pts[k].face);
      EXPECT_NEAR((s.evaluate(pts[k]).position - (c + h * (l * e1 - mm * e2))).norm(), 0.0, 1e-6)
          << how << ": " << l << "," << mm;
    }
    EXPECT_GE(faces.size(), 3u);
  }
}

TEST(SurfaceNeighbourhood, SampledAtAnExtraordinaryVertexEqualsThePlainGrid) {
  // Same on the flat disc whose centre has valence 5 (cached first-order
  // walk: exact where the parametrisation is affine, within a small fraction
  // of the spacing near the extraordinary vertex).
  const PolygonMesh m = flat_star();
  const SubdivSurface s(m);
  surface::TexelGrid grid(std::vector<int>(std::size_t(s.ptex_face_count()), 16));
  const surface::TexelFrames fr =
      surface::build_texel_frames(s, grid, constant_field(m.vertices.size(), V3(1, 0, 0)), nullptr);
  const std::size_t t = grid.offset[0];  // texel (0, 0) of face 0: at the centre vertex
  const double h = 0.08;
  const V3d c = s.evaluate(grid.centre(t)).position;
  const V3d e1 = fr.t1[t].cast<double>(), e2 = fr.t2[t].cast<double>();
  EXPECT_NEAR(e2.dot(V3d(0, 0, 1).cross(e1)), 1.0, 1e-6);
  const surface::VertexCharts charts(s);
  ASSERT_EQ(charts.valence(charts.chart(0, 0)), 5);
  for (int how = 0; how < 4; ++how) {
    SurfacePoint pts[25];
    bool valid[25];
    surface::ChartStats stats;
    if (how == 0)
      surface::sample_points(s, fr, t, h, 2, pts, valid);
    else if (how < 3)
      surface::march_points(s, fr, grid.centre(t), h * e1, h * e2, 2, how == 2, pts, valid);
    else
      surface::chart_points(s, fr, charts, grid.centre(t), fr.du[t].cast<double>(), fr.dv[t].cast<double>(), h * e1,
                            h * e2, 2, false, pts, valid, &stats);
    if (how == 3) EXPECT_EQ(stats.walked, 0u);
    std::set<int> faces;
    for (int k = 0; k < 25; ++k) {
      const int l = k % 5 - 2, mm = k / 5 - 2;
      ASSERT_TRUE(valid[k]);
      faces.insert(pts[k].face);
      EXPECT_NEAR((s.evaluate(pts[k]).position - (c + h * (l * e1 - mm * e2))).norm(), 0.0, 0.05 * h)
          << how << ": " << l << "," << mm;
    }
    EXPECT_GE(faces.size(), 4u);  // around the valence-5 vertex
  }
}

TEST(SurfaceNeighbourhood, ChartJacobianMatchesFiniteDifferencesOnACurvedSurface) {
  // The sampling map (l, m) -> walked point: its derivative at the centre is
  // h (v1, -v2) (unit speed in the tangent frame), by finite differences of
  // exact walks on a cube's limit surface.
  const SubdivSurface s(cube());
  for (int f = 0; f < s.ptex_face_count(); ++f) {
    const SurfacePoint c{f, 0.35, 0.6};
    const LimitFrame lf = s.evaluate(c);
    const V3d t1 = lf.du.normalized(), t2 = lf.normal().cross(t1);
    const double e = 1e-4;
    for (const V3d& dir : {t1, V3d(-t2)}) {
      SurfacePoint a = c, b = c;
      s.walk(a, e * dir);
      s.walk(b, -e * dir);
      const V3d fd = (s.evaluate(a).position - s.evaluate(b).position) / (2 * e);
      EXPECT_NEAR((fd - dir).norm(), 0.0, 1e-3);
    }
  }
}


// ---- vertex charts ----------------------------------------------------------------

TEST(SurfaceCharts, StarsHaveTheValenceOfTheirCorner) {
  {  // cube: 8 corners of valence 3, every ptex corner in one
    const SubdivSurface s(cube());
    const surface::VertexCharts c(s);
    EXPECT_EQ(c.chart_count(), 8);
    for (int f = 0; f < s.ptex_face_count(); ++f)
      for (int q = 0; q < 4; ++q) {
        ASSERT_GE(c.chart(f, q), 0);
        EXPECT_EQ(c.valence(c.chart(f, q)), 3);
        EXPECT_FALSE(c.boundary(c.chart(f, q)));
      }
  }
  {  // pyramid: apex 4, base corners 3 (quad + 2 triangles), triangle centres 3,
     // triangle-triangle edge midpoints 4, the base's edge midpoints are
     // T-junctions (2 sub-faces meeting the quad's edge: a half-star)
    const SubdivSurface s(pyramid());
    const surface::VertexCharts c(s);
    std::map<std::pair<int, bool>, int> kinds;
    for (int i = 0; i < c.chart_count(); ++i) ++kinds[{c.valence(i), c.boundary(i)}];
    EXPECT_EQ(kinds[std::make_pair(4, false)], 1 + 4);
    EXPECT_EQ(kinds[std::make_pair(3, false)], 4 + 4);
    EXPECT_EQ(kinds[std::make_pair(2, true)], 4);
    EXPECT_EQ(c.chart_count(), 17);
  }
  {  // open 3 x 3 grid: interior 4, boundary edges 2 (half-stars), corners none
    const SubdivSurface s(flat_grid(3));
    const surface::VertexCharts c(s);
    std::map<std::pair<int, bool>, int> kinds;
    for (int i = 0; i < c.chart_count(); ++i) ++kinds[{c.valence(i), c.boundary(i)}];
    EXPECT_EQ(kinds[std::make_pair(4, false)], 4);
    EXPECT_EQ(kinds[std::make_pair(2, true)], 8);
    EXPECT_EQ(c.chart(0, 0), -1);
    // Every star of this small grid has a face at a corner without a chart
    // (the limit surface is not the regular layout there): none is used.
    for (int i = 0; i < c.chart_count(); ++i) EXPECT_FALSE(c.used(i));
    const SubdivSurface s6(flat_grid(6));
    const surface::VertexCharts c6(s6);
    EXPECT_GE(c6.chart(2 * 6 + 2, 2), 0);  // away from the corners
  }
}

TEST(SurfaceCharts, MapThenInverseIsTheIdentity) {
  // Every chart of meshes with valences 3 to 5, interior and boundary, quads
  // and sub-faces: face point -> chart -> face point, and chart point ->
  // face point -> chart point where it lands in the star.
  for (const PolygonMesh& m : {cube(), pyramid(), flat_star(), flat_grid(3)}) {
    const SubdivSurface s(m);
    const surface::VertexCharts c(s);
    int checked = 0, ring = 0;
    for (int i = 0; i < c.chart_count(); ++i) {
      for (int f : c.star_faces(i))
        for (double u : {0.0, 0.13, 0.5, 0.77, 1.0})
          for (double v : {0.0, 0.31, 0.5, 0.92, 1.0}) {
            const SurfacePoint p{f, u, v};
            const Eigen::Vector2d y = c.to_chart(i, p);
            SurfacePoint back;
            ASSERT_TRUE(c.from_chart(i, y, back)) << "chart " << i << " k " << c.valence(i) << " face " << f << " at " << u << ", " << v << " y " << y.transpose();
            // On a shared edge the inverse may name the neighbour: compare limit points.
            EXPECT_NEAR((s.evaluate(back).position - s.evaluate(p).position).norm(), 0.0, 1e-9)
                << "chart " << i << " face " << f << " at " << u << ", " << v;
            if (back.face == f) {
              EXPECT_NEAR(back.u, u, 1e-9);
              EXPECT_NEAR(back.v, v, 1e-9);
            }
            ++checked;
          }
      const std::vector<int> star = c.star_faces(i);
      for (int a = 0; a < 24; ++a)
        for (double rad : {0.2, 0.6, 0.95, 1.4}) {
          const Eigen::Vector2d y = rad * Eigen::Vector2d(std::cos(0.26 * a + 0.1), std::sin(0.26 * a + 0.1));
          SurfacePoint p;
          if (!c.from_chart(i, y, p)) continue;
          if (std::find(star.begin(), star.end(), p.face) == star.end()) {
            ++ring;  // in the ring (checked by the neighbourhood tests)
            continue;
          }
          EXPECT_NEAR((c.to_chart(i, p) - y).norm(), 0.0, 1e-9) << "chart " << i;
        }
    }
    EXPECT_GT(checked, 100);
    EXPECT_GT(ring, 0);
  }
}

TEST(SurfaceCharts, ChartJacobianMatchesFiniteDifferences) {
  // d y / d(u, v) of to_chart against central differences, at extraordinary
  // (cube, valence 3; star, valence 5) and regular corners.
  for (const PolygonMesh& m : {cube(), flat_star(), pyramid()}) {
    const SubdivSurface s(m);
    const surface::VertexCharts c(s);
    const double e = 1e-7;
    for (int i = 0; i < c.chart_count(); ++i)
      for (int f : c.star_faces(i))
        for (double u : {0.21, 0.52, 0.83})
          for (double v : {0.17, 0.46, 0.71}) {
            Eigen::Matrix2d J;
            c.to_chart(i, {f, u, v}, &J);
            const Eigen::Vector2d fu = (c.to_chart(i, {f, u + e, v}) - c.to_chart(i, {f, u - e, v})) / (2 * e);
            const Eigen::Vector2d fv = (c.to_chart(i, {f, u, v + e}) - c.to_chart(i, {f, u, v - e})) / (2 * e);
            EXPECT_NEAR((J.col(0) - fu).norm(), 0.0, 1e-6 * (1 + fu.norm()));
            EXPECT_NEAR((J.col(1) - fv).norm(), 0.0, 1e-6 * (1 + fv.norm()));
          }
  }
}

TEST(SurfaceCharts, SamplingJacobianIsTheTangentFrameOnACurvedSurface) {
  // The chart sampling map (l, m) -> S(from_chart(y + l tau_a - m tau_b)):
  // its derivative at the centre is (v1, -v2) per unit h, by central
  // differences, on the cube's limit surface (curved; valence-3 corners),
  // for texels all over each face.
  const PolygonMesh m = cube();
  const SubdivSurface s(m);
  const surface::VertexCharts charts(s);
  surface::TexelGrid grid(std::vector<int>(std::size_t(s.ptex_face_count()), 6));
  const surface::TexelFrames fr =
      surface::build_texel_frames(s, grid, constant_field(m.vertices.size(), V3(0.3f, 0.5f, 0.8f)), nullptr);
  const double h = 1e-5;
  for (std::size_t t = 0; t < grid.size(); ++t) {
    SurfacePoint pts[9];
    bool valid[9];
    surface::ChartStats stats;
    // The surface derivatives by central differences of the limit points:
    // Bfr's own derivatives sit up to 0.3 % off them a twelfth of a face
    // from the cube's valence-3 corners (its approximate irregular patches),
    // which is not the chart's doing.
    const SurfacePoint c = grid.centre(t);
    const double e = 1e-6;
    const V3d du = (s.evaluate({c.face, c.u + e, c.v}).position - s.evaluate({c.face, c.u - e, c.v}).position) / (2 * e);
    const V3d dv = (s.evaluate({c.face, c.u, c.v + e}).position - s.evaluate({c.face, c.u, c.v - e}).position) / (2 * e);
    surface::chart_points(s, fr, charts, c, du, dv, h * fr.t1[t].cast<double>(), h * fr.t2[t].cast<double>(), 1, false,
                          pts, valid, &stats);
    ASSERT_EQ(stats.walked, 0u);
    auto at = [&](int l, int mm) { return s.evaluate(pts[(mm + 1) * 3 + l + 1]).position; };
    const V3d dl = (at(1, 0) - at(-1, 0)) / (2 * h), dm = (at(0, 1) - at(0, -1)) / (2 * h);
    // (1e-3: v1, v2 lie in Bfr's tangent plane, tilted by the same 0.3 %.)
    EXPECT_NEAR((dl - fr.t1[t].cast<double>()).norm(), 0.0, 1e-3) << "texel " << t;
    EXPECT_NEAR((dm + fr.t2[t].cast<double>()).norm(), 0.0, 1e-3) << "texel " << t;
  }
}

TEST(SurfaceCharts, ChartSamplesMatchWalkedSamplesOnACurvedSurface) {
  // The brute-force twin: 5 x 5 neighbourhoods at one texel spacing through
  // the charts vs walked on the limit surface (exact Bfr walks), on the
  // cube and the pyramid (curved, valence 3 corners, sub-faces, T-junctions).
  for (const PolygonMesh& m : {cube(), pyramid()})
  for (int res : {8, 16, 32}) {
    const SubdivSurface s(m);
    const surface::VertexCharts charts(s);
    surface::TexelGrid grid(std::vector<int>(std::size_t(s.ptex_face_count()), res));
    const surface::TexelFrames fr =
        surface::build_texel_frames(s, grid, constant_field(m.vertices.size(), V3(0.3f, 0.5f, 0.8f)), nullptr);
    const double h = 1.0 / res * std::sqrt(s.ptex_face_areas()[0]);
    double sum = 0, worst = 0;
    int n = 0;
    surface::ChartStats stats;
    for (std::size_t t = 0; t < grid.size(); ++t) {
      SurfacePoint pts[25];
      bool valid[25];
      const V3d a = h * fr.t1[t].cast<double>(), b = h * fr.t2[t].cast<double>();
      surface::chart_points(s, fr, charts, grid.centre(t), fr.du[t].cast<double>(), fr.dv[t].cast<double>(), a, b, 2,
                            false, pts, valid, &stats);
      for (int k = 0; k < 25; ++k) {
        SurfacePoint w = grid.centre(t);
        s.walk(w, double(k % 5 - 2) * a - double(k / 5 - 2) * b);
        const double d = (s.evaluate(pts[k]).position - s.evaluate(w).position).norm() / h;
        sum += d;
        worst = std::max(worst, d);
        ++n;
      }
    }
    // Straight lines in a chart are not geodesics: on these strongly curved
    // surfaces (a face spans a quarter to a third of a turn) the difference
    // falls with the spacing (measured mean / worst, 8 -> 32 texels a face:
    // cube 0.19 / 0.94 -> 0.053 / 0.26, pyramid 0.24 / 4.3 -> 0.11 / 0.85;
    // before the chart samples were corrected in place (place_in_chart)
    // cube 0.18 / 0.92 -> 0.053 / 0.26, pyramid 0.25 / 2.3 -> 0.12 / 1.06).
    if (res == 32) {
      EXPECT_LT(sum / n, m.face_sizes.size() == 6 ? 0.07 : 0.15) << "mean distance / spacing";
      EXPECT_LT(worst, 1.5);
    }
    EXPECT_GT(double(stats.in_chart) / double(stats.in_chart + stats.walked), 0.9);
    std::printf("chart vs walk, %d texels a face: mean %.4f, worst %.4f of the spacing; %.1f %% in chart\n", res, sum / n, worst,
                100.0 * double(stats.in_chart) / double(stats.in_chart + stats.walked));
  }
}

// ---- orientation -----------------------------------------------------------

TEST(SurfaceField, SmoothFieldIsUnitTangentAndFollowsTheAxisOnATube) {
  const PolygonMesh m = tube(12, 6, 1.0f, 3.0f);
  const std::vector<V3> f = smooth_surface_field(m, V3(0, 0, 1));
  ASSERT_EQ(f.size(), m.vertices.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    EXPECT_NEAR(f[i].norm(), 1.0f, 1e-5f);
    EXPECT_GT(std::abs(f[i].z()), 0.99f);
  }
  EXPECT_THROW(smooth_surface_field(m, V3(0, 0, 0)), InvalidInput);
}

// ---- synthesis ----------------------------------------------------------------

namespace {

SurfaceSynthesisOptions small_options(SurfaceMethod method) {
  SurfaceSynthesisOptions o;
  o.method = method;
  o.face_resolution = 8;
  o.seed = 7;
  return o;
}

/// Mean squared difference of texels horizontally adjacent inside faces vs
/// across face edges, on a flat grid whose faces tile the plane.
std::pair<double, double> inside_vs_across(const SurfaceTexture& t, int n, int r) {
  auto px = [&](int gx, int gy, int c) {
    const int f = (gy / r) * n + gx / r;
    return t.texels[(t.face_offset[std::size_t(f)] + std::size_t((gy % r) * r + gx % r)) * std::size_t(t.channels) + c];
  };
  double in = 0, across = 0;
  int nin = 0, nacross = 0;
  for (int gy = 0; gy < n * r; ++gy)
    for (int gx = 0; gx + 1 < n * r; ++gx) {
      double d = 0;
      for (int c = 0; c < t.channels; ++c) d += std::pow(px(gx, gy, c) - px(gx + 1, gy, c), 2);
      if ((gx + 1) % r == 0) {
        across += d;
        ++nacross;
      } else {
        in += d;
        ++nin;
      }
    }
  return {in / nin, across / nacross};
}

}  // namespace

TEST(SurfaceSynthesis, CoherentIsDeterministicCoherentAndSeamless) {
  const PolygonMesh m = flat_grid(4);
  const SubdivSurface s(m);
  const Image ex = exsynth::testing::disc_texture(40, 40, 3, 5);
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Coherent);
  o.field = constant_field(m.vertices.size(), V3(1, 0, 0));
  const SurfaceTexture a = exsynth::testing::on_threads(1, [&] { return synthesize_surface(s, ex, o); });
  const SurfaceTexture b = exsynth::testing::on_threads(8, [&] { return synthesize_surface(s, ex, o); });
  EXPECT_EQ(a.texels, b.texels);
  EXPECT_EQ(a.source, b.source);
  ASSERT_EQ(a.texel_count(), 16u * 64u);
  ASSERT_EQ(a.texels.size(), a.texel_count() * 3);
  // Coherence: most texels continue a neighbour's source (Ashikhmin).
  int continued = 0;
  for (std::size_t f = 0; f < 16; ++f)
    for (int j = 0; j < 8; ++j)
      for (int i = 1; i < 8; ++i) {
        const std::size_t t = a.face_offset[f] + std::size_t(j * 8 + i);
        continued += std::abs(a.source[t * 2] - a.source[(t - 1) * 2] - 1.0f) < 0.3f &&
                     std::abs(a.source[t * 2 + 1] - a.source[(t - 1) * 2 + 1]) < 0.3f;
      }
  EXPECT_GT(continued, 16 * 8 * 7 / 2);
  // Face borders: texel differences across them no larger than inside faces.
  const auto [in, across] = inside_vs_across(a, 4, 8);
  EXPECT_LT(across, 1.5 * in + 1e-4) << in << " vs " << across;
  // Another seed gives another texture.
  o.seed = 8;
  EXPECT_NE(synthesize_surface(s, ex, o).texels, a.texels);
}

TEST(SurfaceSynthesis, MultiscaleIsDeterministicForAnyThreadCount) {
  const PolygonMesh m = flat_grid(3);
  const SubdivSurface s(m);
  const Image ex = exsynth::testing::disc_texture(32, 32, 2, 9);
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Multiscale);
  o.field = constant_field(m.vertices.size(), V3(1, 0, 0));
  const SurfaceTexture one = exsynth::testing::on_threads(1, [&] { return synthesize_surface(s, ex, o); });
  const SurfaceTexture many = exsynth::testing::on_threads(8, [&] { return synthesize_surface(s, ex, o); });
  EXPECT_EQ(one.texels, many.texels);
  EXPECT_EQ(one.source, many.source);
  ASSERT_EQ(one.texels.size(), 9u * 64u * 2u);
  // Every texel is the exemplar pixel nearest to its (float) source.
  for (std::size_t t = 0; t < one.texel_count(); ++t) {
    const int x = int(std::floor(one.source[t * 2] + 0.5f)), y = int(std::floor(one.source[t * 2 + 1] + 0.5f));
    EXPECT_FLOAT_EQ(one.texels[t * 2], ex.at(x, y, 0));
  }
  EXPECT_GE(surface::multiscale_levels(ex, surface::TexelGrid(std::vector<int>(9, 8)), o), 2);
}

TEST(SurfaceSynthesis, TexelDensitySetsFaceResolutions) {
  const SubdivSurface s(flat_grid(4));
  SurfaceSynthesisOptions o;
  o.texels_per_unit = 10;
  const std::vector<int> r = surface_face_resolutions(s, o);
  EXPECT_EQ(r[5], 10);  // interior unit face
}

TEST(SurfaceSynthesis, CancelStopsTheJob) {
  const PolygonMesh m = flat_grid(2);
  const SubdivSurface s(m);
  ExecContext ctx;
  ctx.cancel();
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Coherent);
  EXPECT_THROW(synthesize_surface(s, exsynth::testing::disc_texture(16, 16, 3, 1), o, &ctx), Cancelled);
}

TEST(SurfaceSynthesis, CancelInEveryStage) {
  // Every stage of both methods (the multiscale levels' frames, landing
  // tables, exemplar indices, coarsest brute force and tree passes) sees a
  // cancel made inside it.
  const PolygonMesh m = flat_grid(2);
  const SubdivSurface s(m);
  const Image ex = exsynth::testing::disc_texture(32, 32, 3, 5);
  for (SurfaceMethod method : {SurfaceMethod::Coherent, SurfaceMethod::Multiscale}) {
    SurfaceSynthesisOptions o = small_options(method);
    o.field = constant_field(m.vertices.size(), V3(1, 0, 0));
    const auto job = [&](ExecContext* ctx) { synthesize_surface(s, ex, o, ctx); };
    const auto log = exsynth::testing::stages_of(job);
    ASSERT_GE(log.names.size(), 3u);
    if (method == SurfaceMethod::Multiscale) {
      EXPECT_THAT(log.names, ::testing::Contains(::testing::HasSubstr("coarsest")));
      EXPECT_THAT(log.names, ::testing::Contains(::testing::HasSubstr("level 0 frames")));
    }
    for (const std::string& stage : log.names) {
      const auto outcome = exsynth::testing::cancel_in_stage(job, stage);
      EXPECT_TRUE(outcome.threw_cancelled) << stage;
      EXPECT_EQ(outcome.stage_at_throw, stage);
    }
  }
}

// ---- atlas and limit mesh ---------------------------------------------------------

TEST(SurfaceAtlas, GuttersCopyTheNeighbouringFaces) {
  const PolygonMesh m = flat_grid(3);
  const SubdivSurface s(m);
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Coherent);
  o.field = constant_field(m.vertices.size(), V3(1, 0, 0));
  const SurfaceTexture t = synthesize_surface(s, exsynth::testing::disc_texture(24, 24, 3, 2), o);
  const SurfaceAtlas a = build_surface_atlas(s, t, 2);
  const int f = 4, right = 5, top = 7;  // centre face, its +u and +v neighbours
  for (int j = 0; j < 8; ++j)
    for (int c = 0; c < 3; ++c) {
      // Column 8 of face f's tile (first gutter column) = column 0 of the right face.
      EXPECT_FLOAT_EQ(a.image.at(a.tile_origin[f][0] + 8, a.tile_origin[f][1] + j, c),
                      t.texels[(t.face_offset[right] + std::size_t(j * 8)) * 3 + c]);
      EXPECT_FLOAT_EQ(a.image.at(a.tile_origin[f][0] + j, a.tile_origin[f][1] + 8, c),
                      t.texels[(t.face_offset[top] + std::size_t(j)) * 3 + c]);
      // Inside: the texel itself.
      EXPECT_FLOAT_EQ(a.image.at(a.tile_origin[f][0] + 3, a.tile_origin[f][1] + j, c),
                      t.texels[(t.face_offset[f] + std::size_t(j * 8 + 3)) * 3 + c]);
    }
  const Eigen::Vector2f uv = a.uv(t, {f, 0.5, 0.5});
  EXPECT_NEAR(uv.x() * a.image.width(), a.tile_origin[f][0] + 4, 1e-3);
  EXPECT_NEAR((1 - uv.y()) * a.image.height(), a.tile_origin[f][1] + 4, 1e-3);
}

TEST(SurfaceAtlas, LimitMeshOfAClosedSurfaceIsClosedAndOnTheLimit) {
  const PolygonMesh m = pyramid();
  const SubdivSurface s(m);
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Coherent);
  o.face_resolution = 4;
  const SurfaceTexture t = synthesize_surface(s, exsynth::testing::disc_texture(16, 16, 1, 2), o);
  const SurfaceAtlas a = build_surface_atlas(s, t, 1);
  const LimitMesh lm = surface_limit_mesh(s, t, a, 3);
  EXPECT_EQ(lm.quads.size(), std::size_t(s.ptex_face_count() - 1) * 9 + 36);  // the base quad: 6 x 6
  EXPECT_EQ(lm.corner_uvs.size(), lm.quads.size() * 4);
  std::map<std::pair<int, int>, int> edges;
  for (const auto& q : lm.quads)
    for (int k = 0; k < 4; ++k) edges[{std::min(q[k], q[(k + 1) % 4]), std::max(q[k], q[(k + 1) % 4])}]++;
  for (const auto& [e, n] : edges) EXPECT_EQ(n, 2);
  const long euler = long(lm.vertices.size()) - long(edges.size()) + long(lm.quads.size());
  EXPECT_EQ(euler, 2);
  const LimitFrame lf = s.evaluate({3, 1.0 / 3, 2.0 / 3});  // a triangle's sub-face
  double best = 1e9;
  for (const auto& v : lm.vertices) best = std::min(best, (v.cast<double>() - lf.position).norm());
  EXPECT_LT(best, 1e-6);
  // Displacement moves vertices along the normal by scale * (value - mid).
  const LimitMesh d = surface_limit_mesh(s, t, a, 3, 0, 0.1, 0.0);
  double moved = 0;
  for (std::size_t i = 0; i < d.vertices.size(); ++i) moved = std::max(moved, double((d.vertices[i] - lm.vertices[i]).norm()));
  EXPECT_GT(moved, 0.01);
  EXPECT_LE(moved, 0.1 + 1e-5);
}

// ---- bad inputs -------------------------------------------------------------

TEST(SurfaceErrors, BadMeshesAreRefusedWithAReason) {
  auto expect_refused = [](const PolygonMesh& m, const char* words) {
    try {
      SubdivSurface s(m);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr(words));
    }
  };
  PolygonMesh none;
  none.vertices = {V3(0, 0, 0)};
  expect_refused(none, "no faces");
  expect_refused(PolygonMesh{}, "no vertices");
  PolygonMesh fin = flat_grid(2);
  // Three faces on one edge (0, 1): a fin below the first face.
  fin.vertices.push_back(V3(0, 0, -1));
  fin.vertices.push_back(V3(1, 0, -1));
  const int a = int(fin.vertices.size()) - 2;
  fin.face_sizes.push_back(4);
  for (int v : {1, 0, a, a + 1}) fin.face_vertices.push_back(v);
  fin.face_sizes.push_back(4);
  for (int v : {0, 1, a + 1, a}) fin.face_vertices.push_back(v);
  expect_refused(fin, "non-manifold");
  PolygonMesh flipped = flat_grid(2);
  std::swap(flipped.face_vertices[1], flipped.face_vertices[3]);
  expect_refused(flipped, "inconsistently oriented");
  PolygonMesh zero = flat_grid(2);
  zero.vertices.push_back(V3(5, 0, 0));
  zero.vertices.push_back(V3(6, 0, 0));
  zero.vertices.push_back(V3(7, 0, 0));
  zero.face_sizes.push_back(3);
  for (int v : {9, 10, 11}) zero.face_vertices.push_back(v);
  expect_refused(zero, "zero area");
  PolygonMesh range = flat_grid(1);
  range.face_vertices[2] = 99;
  expect_refused(range, "out of range");
  PolygonMesh nan = flat_grid(1);
  nan.vertices[0].x() = NAN;
  expect_refused(nan, "not finite");
}

TEST(SurfaceErrors, BadSynthesisInputsAreRefusedBeforeAllocating) {
  const PolygonMesh m = flat_grid(2);
  const SubdivSurface s(m);
  SurfaceSynthesisOptions o;
  try {
    synthesize_surface(s, exsynth::testing::disc_texture(4, 4, 3, 1), o);
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("smaller than the 5x5 neighbourhood"));
  }
  o.method = SurfaceMethod::Multiscale;
  EXPECT_THROW(synthesize_surface(s, exsynth::testing::disc_texture(8, 8, 3, 1), o), InvalidInput);
  SurfaceSynthesisOptions big;
  big.face_resolution = 512;
  big.memory_budget = 1 << 20;
  try {
    synthesize_surface(s, exsynth::testing::disc_texture(16, 16, 3, 1), big);
    ADD_FAILURE();
  } catch (const OverBudget& e) {
    EXPECT_THAT(e.what(), HasSubstr("texels"));
  }
  SurfaceSynthesisOptions field;
  field.field = constant_field(3, V3(1, 0, 0));
  EXPECT_THROW(synthesize_surface(s, exsynth::testing::disc_texture(16, 16, 3, 1), field), InvalidInput);
  SurfaceSynthesisOptions res;
  res.face_resolution = 0;
  EXPECT_THROW(synthesize_surface(s, exsynth::testing::disc_texture(16, 16, 3, 1), res), InvalidInput);
}

TEST(SurfaceSynthesis, SettingsBeyondTheirLimitsAreRefusedNotClamped) {
  const PolygonMesh m = flat_grid(4);
  const SubdivSurface s(m);
  const Image ex = exsynth::testing::disc_texture(40, 40, 3, 5);
  const auto message = [&](const SurfaceSynthesisOptions& o) {
    try {
      synthesize_surface(s, ex, o);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  SurfaceSynthesisOptions o = small_options(SurfaceMethod::Coherent);
  o.texels_per_unit = 1e12;  // was clamped to 512 texels a face edge, silently
  EXPECT_NE(message(o).find("over max_face_resolution 512; give texels_per_unit at most"), std::string::npos)
      << message(o);
  o = small_options(SurfaceMethod::Coherent);
  o.exemplar_scale = 1e9;  // 40 px / 5 px neighbourhood: at most 8
  EXPECT_NE(message(o).find("give exemplar_scale at most 8"), std::string::npos) << message(o);
  o.exemplar_scale = 8;
  EXPECT_EQ(message(o), "accepted");
  o = small_options(SurfaceMethod::Coherent);
  o.field = constant_field(m.vertices.size(), V3::Zero());
  EXPECT_NE(message(o).find("field is zero everywhere"), std::string::npos) << message(o);
}
