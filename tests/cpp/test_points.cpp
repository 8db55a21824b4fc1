// Point-set geometry texture synthesis: the point-set surface, its field,
// the thin-plate spline, the pairing, and the synthesis end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>


#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/points.hpp"
#include "points/pairing.hpp"
#include "points/patch_solver.hpp"
#include "points/point_surface.hpp"
#include "points/sampling.hpp"
#include "points/tps.hpp"
#include "support/cancel.hpp"
#include "support/shapes.hpp"
#include "support/threads.hpp"

using namespace exsynth;
using V3 = Eigen::Vector3f;

namespace {

OrientedPoints sphere_points(float radius, int n) {
  // Fibonacci sphere: even, deterministic.
  OrientedPoints s;
  const double golden = 3.14159265358979 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1 - z * z), a = golden * i;
    const V3 d(float(r * std::cos(a)), float(r * std::sin(a)), float(z));
    s.positions.push_back(radius * d);
    s.normals.push_back(d);
  }
  return s;
}

OrientedPoints plane_points(int n, float step) {
  OrientedPoints s;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      s.positions.emplace_back(i * step, j * step, 0.0f);
      s.normals.push_back(V3::UnitZ());
    }
  return s;
}

// Brute-force twin of PointSurface::evaluate: every point, no cut-off.
points::SurfaceSample evaluate_all(const OrientedPoints& pts, const V3& x, float h) {
  double wsum = 0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double w = std::exp(-double((pts.positions[i] - x).squaredNorm()) / (double(h) * h));
    wsum += w;
    a += w * pts.positions[i].cast<double>();
    n += w * pts.normals[i].cast<double>();
  }
  points::SurfaceSample s;
  a /= wsum;
  n.normalize();
  s.f = float(n.dot(x.cast<double>() - a));
  s.normal = n.cast<float>();
  s.valid = true;
  return s;
}

PointTextureOptions small_options() {
  PointTextureOptions o;
  o.patch_size = 0.4;
  o.grid_resolution = 8;
  return o;
}

const PointExemplar& bumps_exemplar() {
  static const PointExemplar ex = make_point_exemplar("bumps", 3000.0, 0.35, 1);
  return ex;
}

}  // namespace

TEST(PointSurface, ProjectionConvergesOntoSphereAndPlane) {
  const OrientedPoints sphere = sphere_points(1.0f, 4000);
  const points::PointSurface s(sphere.positions, sphere.normals, 0.06f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1), rr(0.93f, 1.07f);
  for (int k = 0; k < 200; ++k) {
    const V3 d = V3(u(rng), u(rng), u(rng)).normalized();
    const points::Projection p = s.project(rr(rng) * d, 20, 1e-7f);
    ASSERT_TRUE(p.converged);
    EXPECT_NEAR(p.point.norm(), 1.0f, 3e-3f);
    EXPECT_GT(p.normal.dot(d), 0.999f);
  }
  const OrientedPoints plane = plane_points(30, 0.05f);
  const points::PointSurface ps(plane.positions, plane.normals, 0.1f);
  for (int k = 0; k < 50; ++k) {
    const V3 x(0.3f + 0.8f * (u(rng) + 1) / 2, 0.3f + 0.8f * (u(rng) + 1) / 2, 0.2f * u(rng));
    const points::Projection p = ps.project(x);
    ASSERT_TRUE(p.converged);
    EXPECT_NEAR(p.point.z(), 0.0f, 1e-5f);
    EXPECT_NEAR(p.point.x(), x.x(), 1e-5f);  // orthogonal: no sliding along the plane
  }
}

TEST(PointSurface, ProjectionWithOneQueryEqualsStepsOfFreshEvaluations) {
  // project() reuses one wider radius query while it stays near its start;
  // the reference re-evaluates from scratch (a fresh k-d tree query) each step.
  const OrientedPoints sphere = sphere_points(1.0f, 3000);
  const float h = 0.08f;
  const points::PointSurface s(sphere.positions, sphere.normals, h);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1), rr(0.85f, 1.15f);  // most starts farther than the slack (h / 2)
  for (int k = 0; k < 100; ++k) {
    const V3 x0 = rr(rng) * V3(u(rng), u(rng), u(rng)).normalized();
    V3 x = x0;
    points::Projection ref;
    for (int it = 0; it < 5; ++it) {
      const points::SurfaceSample e = s.evaluate(x);
      ASSERT_TRUE(e.valid);
      x -= e.f * e.normal;
      ref.point = x;
    }
    ref.normal = s.evaluate(x).normal;  // not converged (tol 0): the normal where it ends
    const points::Projection p = s.project(x0, 5, 0.0f);
    EXPECT_LT((p.point - ref.point).norm(), 1e-5f) << "start " << x0.transpose();
    EXPECT_GT(p.normal.dot(ref.normal), 1 - 1e-5f);
  }
}

TEST(PointSurface, MatchesBruteForceAndExactSphereField) {
  const OrientedPoints sphere = sphere_points(1.0f, 3000);
  const float h = 0.08f;
  const points::PointSurface s(sphere.positions, sphere.normals, h);
  std::vector<V3> cells;
  for (int k = 0; k < 300; ++k) {
    const float a = 0.37f * k, b = 0.11f * k;
    const float r = 0.9f + 0.2f * float(k % 11) / 10.0f;
    cells.push_back(r * V3(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b)));
  }
  std::vector<float> f;
  std::vector<V3> n;
  points::PatchSolver::sample_field(s, cells, 0.5f, f, n);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const points::SurfaceSample ref = evaluate_all(sphere, cells[i], h);
    EXPECT_NEAR(f[i], ref.f, 2e-3f);  // the k-d tree's 3 h cut-off drops weights below e^-9
    EXPECT_GT(n[i].dot(ref.normal), 0.9999f);
    const float exact = cells[i].norm() - 1.0f;
    EXPECT_NEAR(f[i], exact, 0.01f) << "at radius " << cells[i].norm();
    EXPECT_GT(n[i].dot(cells[i].normalized()), 0.999f);
  }
}

TEST(ThinPlateSpline, InterpolatesPairsAndJacobianNormalsMatchFiniteDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> from, to;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Vector3d x(u(rng), u(rng), 0.3 * u(rng));
    from.push_back(x);
    to.push_back(x + 0.1 * Eigen::Vector3d(std::sin(3 * x.y()), std::cos(2 * x.x()), x.x() * x.y()));
  }
  const points::ThinPlateSpline tps(from, to);
  for (std::size_t i = 0; i < from.size(); ++i) {
    EXPECT_LT((tps.apply(from[i]) - to[i]).norm(), 1e-8);
    Eigen::Vector3d n1;
    EXPECT_LT((tps.apply(from[i], Eigen::Vector3d::UnitZ(), n1) - to[i]).norm(), 1e-5);
  }
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d x(0.8 * u(rng), 0.8 * u(rng), 0.2 * u(rng));
    const Eigen::Vector3d n = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const double e = 1e-5;
    const Eigen::Vector3d d1 = tps.apply(x + e * t1) - tps.apply(x - e * t1);
    const Eigen::Vector3d d2 = tps.apply(x + e * t2) - tps.apply(x - e * t2);
    const Eigen::Vector3d fd = d1.cross(d2).normalized();  // the warped tangent plane's normal
    EXPECT_GT(tps.transform_normal(x, n).dot(fd), 1 - 1e-6);
    Eigen::Vector3d n1;  // the vectorised (float) form gives the reference's point and normal
    EXPECT_LT((tps.apply(x, n, n1) - tps.apply(x)).norm(), 1e-5);
    EXPECT_LT((n1 - tps.transform_normal(x, n)).norm(), 1e-5);
  }
}

TEST(Pairing, CoherenceAvoidsCrossings) {
  // Sources on a line; targets shifted by 0.5 with an alternating jitter:
  // nearest-first pairing alone crosses pairs, the coherence rounds do not.
  std::vector<points::PairPoint> src, dst;
  for (int i = 0; i < 16; ++i) {
    src.push_back({V3(float(i), 0, 0), V3::UnitZ(), 0});
    dst.push_back({V3(float(i) + 0.5f + ((i % 2) ? 0.35f : -0.35f), 0.2f, 0), V3::UnitZ(), 0});
  }
  auto crossings = [&](const std::vector<points::PointPair>& pairs) {
    int c = 0;
    for (std::size_t a = 0; a < pairs.size(); ++a)
      for (std::size_t b = a + 1; b < pairs.size(); ++b) {
        const float ds = src[pairs[a].source].p.x() - src[pairs[b].source].p.x();
        const float dt = dst[pairs[a].target].p.x() - dst[pairs[b].target].p.x();
        c += ds * dt < 0;
      }
    return c;
  };
  points::PairingOptions o;
  o.spacing = 1.0;
  o.max_distance = 2.0;
  o.w_l = 4.0;
  o.w_d = 4.0;
  o.coherence_radius = 2.0;
  o.iterations = 1;
  const auto greedy = points::greedy_pairs(src, dst, o);
  EXPECT_GT(crossings(greedy), 0) << "the test case must make plain greedy pairing cross";
  o.iterations = 4;
  const auto coherent = points::greedy_pairs(src, dst, o);
  EXPECT_EQ(crossings(coherent), 0);
  EXPECT_GE(coherent.size(), 12u);
}

// Brute-force twin of greedy_pairs with every target a candidate: the
// paper's cost c (Equation 2, positions in spacings) in round 0, c + g (its
// coherence, from the previous round's pairs) after, cheapest first.
std::vector<points::PointPair> greedy_pairs_by_hand(const std::vector<points::PairPoint>& src,
                                                    const std::vector<points::PairPoint>& dst,
                                                    const points::PairingOptions& o) {
  struct Cand { std::uint32_t s, t; double c, total; };
  std::vector<Cand> cands;
  for (std::uint32_t i = 0; i < src.size(); ++i)
    for (std::uint32_t j = 0; j < dst.size(); ++j) {
      const double d2 = double((dst[j].p - src[i].p).squaredNorm()), dot = double(src[i].n.dot(dst[j].n));
      const double dv = double(src[i].sigma) - double(dst[j].sigma);
      if (d2 > o.max_distance * o.max_distance * o.spacing * o.spacing || dot < o.min_normal_dot ||
          std::abs(dv) > o.max_variation)
        continue;
      const double c = o.w_p * d2 / (o.spacing * o.spacing) + o.w_n / 2 * (1 - dot) + o.w_v * dv * dv;
      cands.push_back({i, j, c, c});
    }
  auto accept = [&] {
    std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) {
      return float(a.total) != float(b.total) ? float(a.total) < float(b.total) : a.s != b.s ? a.s < b.s : a.t < b.t;
    });
    std::vector<char> us(src.size(), 0), ut(dst.size(), 0);
    std::vector<points::PointPair> out;
    for (const Cand& c : cands)
      if (!us[c.s] && !ut[c.t]) us[c.s] = ut[c.t] = 1, out.push_back({c.s, c.t, float(c.total)});
    return out;
  };
  std::vector<points::PointPair> pairs = accept();
  const double r = o.coherence_radius * o.spacing;
  for (int round = 1; round < o.iterations; ++round) {
    for (Cand& c : cands) {
      double wsum = 0, lsum = 0;
      Eigen::Vector3d dsum = Eigen::Vector3d::Zero();
      for (const auto& p : pairs) {
        const double dist2 = double((src[p.source].p - src[c.s].p).squaredNorm());
        if (p.source == c.s || dist2 > 4 * r * r) continue;
        const Eigen::Vector3d disp = (dst[p.target].p - src[p.source].p).cast<double>();
        const double w = std::exp(-dist2 / (r * r));
        wsum += w, lsum += w * disp.norm(), dsum += w * disp;
      }
      const Eigen::Vector3d d = (dst[c.t].p - src[c.s].p).cast<double>();
      const double dir = 1 - dsum.normalized().dot(d.normalized());
      c.total = c.c + (wsum > 0 ? o.w_l * std::abs(d.norm() - lsum / wsum) / o.spacing + o.w_d / 2 * dir : 0.0);
    }
    pairs = accept();
  }
  return pairs;
}

TEST(Pairing, MatchesTheBruteForcePaperCostAndCoherence) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<points::PairPoint> src, dst;
  for (int i = 0; i < 24; ++i) {
    const V3 p(float(i % 6), float(i / 6), 0.0f);
    src.push_back({p + 0.2f * V3(u(rng), u(rng), u(rng)), V3(0.3f * u(rng), 0.3f * u(rng), 1).normalized(),
                   0.05f + 0.04f * u(rng)});
    dst.push_back({p + V3(0.4f, 0.1f, 0) + 0.3f * V3(u(rng), u(rng), u(rng)),
                   V3(0.3f * u(rng), 0.3f * u(rng), 1).normalized(), 0.05f + 0.04f * u(rng)});
  }
  points::PairingOptions o;
  o.spacing = 0.8;
  o.max_distance = 2.5;
  o.max_variation = 0.06;
  o.candidates = 100;  // every target within reach, as the brute force
  o.w_n = 3, o.w_v = 30, o.w_l = 9, o.w_d = 7;  // Table 1's height field
  std::vector<std::vector<points::PointPair>> rounds;
  for (int iterations : {1, 2, 3}) {
    o.iterations = iterations;
    const auto fast = points::greedy_pairs(src, dst, o), slow = greedy_pairs_by_hand(src, dst, o);
    rounds.push_back(slow);
    ASSERT_GE(slow.size(), 12u) << "the thresholds must leave most points paired";
    ASSERT_EQ(fast.size(), slow.size()) << iterations << " rounds";
    for (std::size_t k = 0; k < fast.size(); ++k) {
      EXPECT_EQ(fast[k].source, slow[k].source) << iterations << " rounds, pair " << k;
      EXPECT_EQ(fast[k].target, slow[k].target) << iterations << " rounds, pair " << k;
      EXPECT_NEAR(fast[k].cost, slow[k].cost, 1e-4f * (1 + slow[k].cost));
    }
  }
  auto same = [](const std::vector<points::PointPair>& a, const std::vector<points::PointPair>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (a[k].source != b[k].source || a[k].target != b[k].target) return false;
    return true;
  };
  EXPECT_FALSE(same(rounds[0], rounds[1])) << "the case must make the coherence change the pairing";
}

TEST(PointTexturePresets, CarryTheRowsOfThePapersTable1) {
  struct Row { const char* name; double w_n, w_v, w_l, w_d; };
  for (const Row& row : {Row{"heightfield", 3, 30, 9, 7}, Row{"bumps", 3, 30, 9, 7}, Row{"chainmail", 1, 10, 8, 6},
                         Row{"weave", 2, 15, 6, 5}, Row{"flowers", 2, 2, 6, 6}}) {
    const PointTextureOptions o = point_texture_preset(row.name);
    EXPECT_EQ(o.w_p, 1.0) << row.name;
    EXPECT_EQ(o.w_n, row.w_n) << row.name;
    EXPECT_EQ(o.w_v, row.w_v) << row.name;
    EXPECT_EQ(o.w_l, row.w_l) << row.name;
    EXPECT_EQ(o.w_d, row.w_d) << row.name;
  }
}

TEST(Sampling, ExactCountEvenAndOnTheSurface) {
  const TriangleMesh sphere = exsynth::testing::icosphere(1.0f, 4);
  const points::SurfaceSamples s = points::sample_surface(sphere, 2000, 7, nullptr);
  ASSERT_EQ(s.points.size(), 2000u);
  const search::PointIndex index(s.points.positions);
  std::size_t idx[2];
  float d2[2];
  double min_d = 1e9;
  for (const V3& p : s.points.positions) {
    EXPECT_NEAR(p.norm(), 1.0f, 0.01f);
    index.knn(p, 2, idx, d2);
    min_d = std::min(min_d, std::sqrt(double(d2[1])));
  }
  // Blue noise: no two samples much closer than the packing radius (uniform random would give ~0.001).
  const double r_max = std::sqrt(points::surface_area(sphere) / (2 * std::sqrt(3.0) * 2000));
  EXPECT_GT(min_d, 0.4 * r_max);
}

TEST(PointTexture, CoversTheAreaAtTheExemplarDensity) {
  const PointExemplar& ex = bumps_exemplar();
  const PointTextureResult r = synthesize_points(ex, 2.0, 1.5, small_options());
  ASSERT_GT(r.points.size(), 0u);
  EXPECT_GT(r.patches, 20u);
  EXPECT_GT(r.pairs, 0u);
  // Density per cell of a 8 x 6 grid of 0.25 x 0.25 against the exemplar's
  // own count in cells of the same size (its box, 4 x 4 cells).
  auto counts = [](const std::vector<V3>& pts, double w, double d) {
    const int nx = int(std::lround(w / 0.25)), ny = int(std::lround(d / 0.25));
    std::vector<int> c(std::size_t(nx) * ny, 0);
    for (const V3& p : pts)
      if (p.x() >= 0 && p.y() >= 0 && p.x() < w && p.y() < d) ++c[std::size_t(int(p.y() / 0.25)) * nx + int(p.x() / 0.25)];
    return c;
  };
  const std::vector<int> ref = counts(ex.points.positions, 1.0, 1.0);
  double mean = 0;
  for (int c : ref) mean += c;
  mean /= double(ref.size());
  for (const V3& p : r.points.positions) {
    ASSERT_GE(p.x(), 0.0f);
    ASSERT_LE(p.x(), 2.0f + 0.05f);
    ASSERT_GE(p.y(), 0.0f);
  }
  const std::vector<int> out = counts(r.points.positions, 2.0, 1.5);
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_GT(out[i], 0.6 * mean) << "cell " << i << " (a hole?)";
    EXPECT_LT(out[i], 1.4 * mean) << "cell " << i << " (doubled points?)";
  }
}

TEST(PointTexture, SeamsAreBounded) {
  // Normal jumps between neighbouring output points against the same
  // statistic in the exemplar: a seam would show as a heavy tail.
  const PointExemplar& ex = bumps_exemplar();
  const PointTextureResult r = synthesize_points(ex, 1.5, 1.5, small_options());
  auto p99 = [&](const OrientedPoints& pts, double spacing) {
    const search::PointIndex index(pts.positions);
    std::vector<float> jump;
    std::vector<std::pair<std::size_t, float>> near;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      index.radius(pts.positions[i], float(1.5 * spacing), near);
      for (const auto& [j, d2] : near)
        if (j > i) jump.push_back(1.0f - pts.normals[i].dot(pts.normals[j]));
    }
    std::sort(jump.begin(), jump.end());
    return jump[jump.size() * 99 / 100];
  };
  const double s = r.spacing;
  const float ref = p99(ex.points, s), out = p99(r.points, s);
  EXPECT_LT(out, 3.0f * ref + 0.02f) << "exemplar p99 " << ref;
  // Heights stay within the exemplar's range (no point thrown off the texture).
  float zlo = 1e9f, zhi = -1e9f;
  for (const V3& p : ex.points.positions) {
    zlo = std::min(zlo, p.z());
    zhi = std::max(zhi, p.z());
  }
  for (const V3& p : r.points.positions) {
    EXPECT_GT(p.z(), zlo - 0.03f);
    EXPECT_LT(p.z(), zhi + 0.03f);
  }
}

TEST(PointTexture, DeterministicWhateverTheThreadCount) {
  const PointExemplar& ex = bumps_exemplar();
  PointTextureOptions o = small_options();
  o.seed = 11;
  const PointTextureResult a = exsynth::testing::on_threads(1, [&] { return synthesize_points(ex, 1.0, 1.0, o); });
  const PointTextureResult b = exsynth::testing::on_threads(8, [&] { return synthesize_points(ex, 1.0, 1.0, o); });
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(a.points.positions[i], b.points.positions[i]) << i;
    ASSERT_EQ(a.points.normals[i], b.points.normals[i]) << i;
  }
  o.seed = 12;
  const PointTextureResult c = synthesize_points(ex, 1.0, 1.0, o);
  EXPECT_FALSE(c.points.size() == a.points.size() &&
               std::equal(a.points.positions.begin(), a.points.positions.end(), c.points.positions.begin()));
}

TEST(PointTexture, BadInputsSayWhatToChange) {
  const PointExemplar& good = bumps_exemplar();
  PointExemplar no_normals = good;
  no_normals.points.normals.clear();
  EXPECT_THROW(synthesize_points(no_normals, 1, 1, small_options()), InvalidInput);
  PointExemplar nan = good;
  nan.points.positions[5].x() = std::nanf("");
  EXPECT_THROW(synthesize_points(nan, 1, 1, small_options()), InvalidInput);
  PointExemplar empty;
  EXPECT_THROW(synthesize_points(empty, 1, 1, small_options()), InvalidInput);
  PointExemplar off_box = good;
  off_box.box_min = {5, 5};
  off_box.box_max = {6, 6};
  EXPECT_THROW(synthesize_points(off_box, 1, 1, small_options()), InvalidInput);
  PointTextureOptions big = small_options();
  big.patch_size = 1.6;
  try {
    synthesize_points(good, 1, 1, big);
    FAIL() << "a patch larger than the exemplar must be refused";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("lower the patch size"), std::string::npos) << e.what();
  }
  PointTextureOptions tight = small_options();
  tight.memory_budget = 1 << 20;
  EXPECT_THROW(synthesize_points(good, 50, 50, tight), OverBudget);
  EXPECT_THROW(synthesize_points(good, 0, 1, small_options()), InvalidInput);
  EXPECT_THROW(make_point_exemplar("moss"), InvalidInput);
  ExecContext ctx;
  ctx.cancel();
  EXPECT_THROW(synthesize_points(good, 1, 1, small_options(), &ctx), Cancelled);
}

TEST(PointTexture, BuiltInExemplarsHavePaddingAndDensity) {
  for (const char* name : {"chainmail", "weave", "flowers"}) {
    const PointExemplar ex = make_point_exemplar(name, 2000.0, 0.3, 0);
    ASSERT_GT(ex.points.size(), 500u) << name;
    float xmin = 1e9f, xmax = -1e9f;
    for (const V3& p : ex.points.positions) {
      xmin = std::min(xmin, p.x());
      xmax = std::max(xmax, p.x());
    }
    EXPECT_LT(xmin, -0.2f) << name << ": geometry extends past the box (padding)";
    EXPECT_GT(xmax, 1.2f) << name;
    EXPECT_NO_THROW(validate_exemplar(ex, name));
  }
}

TEST(PointTextureOnMesh, StaysWithinTheTextureHeightAndFollowsTheField) {
  // Ridges along x (height varies along y) laid on a flat target mesh with
  // the field along world Y: the ridges must run along Y, so the output's
  // normals tilt in X, not in Y.
  const int n = 48;
  std::vector<float> h(std::size_t(n) * n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) h[std::size_t(r) * n + c] = float(0.08 * std::sin(2 * 3.14159265 * r / 8.0));
  const PointExemplar ex = height_field_exemplar(h, n, n, 0.0625, 400.0, 8, 0);  // 2 x 2 box, 0.5 padding
  TriangleMesh plane;
  const int m = 8;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= m; ++i) plane.vertices.emplace_back(float(i) / m * 3.0f, float(j) / m * 3.0f, 0.0f);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int a = j * (m + 1) + i;
      plane.faces.emplace_back(a, a + 1, a + m + 2);
      plane.faces.emplace_back(a, a + m + 2, a + m + 1);
    }
  std::vector<V3> field(plane.vertices.size(), V3::UnitY());
  PointTextureOptions o;
  o.patch_size = 1.0;
  o.grid_resolution = 8;
  const PointTextureResult r = synthesize_points_on_mesh(ex, plane, field, 1.0, o);
  ASSERT_GT(r.points.size(), 1000u);
  double nx = 0, ny = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    EXPECT_LT(std::abs(r.points.positions[i].z()), 0.08f + 0.1f);
    nx += std::abs(r.points.normals[i].x());
    ny += std::abs(r.points.normals[i].y());
  }
  EXPECT_GT(nx, 3.0 * ny) << "ridges should run along the field (Y)";
  // A curved target: a sphere, points within the texture height of it.
  const TriangleMesh sphere = exsynth::testing::icosphere(3.0f, 3);
  std::vector<V3> around(sphere.vertices.size());
  for (std::size_t i = 0; i < around.size(); ++i) around[i] = V3::UnitZ().cross(sphere.vertices[i]);
  const PointTextureResult s = synthesize_points_on_mesh(ex, sphere, around, 1.5, o);
  ASSERT_GT(s.points.size(), 1000u);
  for (const V3& p : s.points.positions) EXPECT_NEAR(p.norm(), 3.0f, 1.5f * 0.08f + 0.1f);
}

TEST(PointsToMesh, ASphereComesBackAsItsSurface) {
  const OrientedPoints sphere = sphere_points(1.0f, 6000);
  const TriangleMesh m = points_to_mesh(sphere);
  ASSERT_GT(m.faces.size(), 1000u);
  for (const V3& v : m.vertices) EXPECT_NEAR(v.norm(), 1.0f, 0.03f);
  // Counter-clockwise seen from outside: positive enclosed volume, about the ball's.
  EXPECT_NEAR(enclosed_volume(m), 4.0 / 3.0 * 3.14159265 * 1.0, 0.15);
  OrientedPoints bad = sphere;
  bad.normals.pop_back();
  EXPECT_THROW(points_to_mesh(bad), InvalidInput);
}

TEST(PointTextureOnMesh, EveryStageCancels) {
  // A curved target's stages (the target's sampling included, which had no
  // check before) each stop on a cancel made inside them.
  const PointExemplar& ex = bumps_exemplar();
  const TriangleMesh sphere = exsynth::testing::icosphere(0.5f, 2);  // ~3 exemplar areas: a lean test
  std::vector<V3> around(sphere.vertices.size());
  for (std::size_t i = 0; i < around.size(); ++i) around[i] = V3::UnitZ().cross(sphere.vertices[i]);
  const PointTextureOptions o = small_options();
  exsynth::testing::expect_every_stage_cancels(
      [&](ExecContext* ctx) { synthesize_points_on_mesh(ex, sphere, around, 1.0, o, ctx); }, 4);
}

TEST(PointTextureOnMesh, TheEstimateIsNearWhatTheSynthesisMakes) {
  // A 9 x 9 plane under a height-field exemplar: the estimate before any work
  // against the real run's patches and points.
  const int n = 48;
  std::vector<float> h(std::size_t(n) * n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) h[std::size_t(r) * n + c] = float(0.05 * std::sin(2 * 3.14159265 * c / 8.0));
  const PointExemplar ex = height_field_exemplar(h, n, n, 0.0625, 400.0, 8, 0);
  const TriangleMesh plane = exsynth::testing::icosphere(2.0f, 3);
  std::vector<V3> around(plane.vertices.size());
  for (std::size_t i = 0; i < around.size(); ++i) around[i] = V3::UnitZ().cross(plane.vertices[i]);
  PointTextureOptions o;
  o.patch_size = 1.0;
  o.grid_resolution = 8;
  std::size_t inside = 0;
  for (const V3& p : ex.points.positions)
    inside += p.x() >= ex.box_min.x() && p.x() <= ex.box_max.x() && p.y() >= ex.box_min.y() && p.y() <= ex.box_max.y();
  const double density = double(inside) / ((ex.box_max - ex.box_min).prod());
  const double area = points::surface_area(plane), scale = 1.0;
  const PointTextureEstimate e = estimate_points_on_mesh(density, area, scale, o);
  const PointTextureResult r = synthesize_points_on_mesh(ex, plane, around, scale, o);
  EXPECT_GT(double(r.patches), 0.6 * e.patches);
  EXPECT_LT(double(r.patches), 1.4 * e.patches);
  EXPECT_GT(double(r.points.size()), 0.6 * e.points);
  EXPECT_LT(double(r.points.size()), 1.4 * e.points);
  EXPECT_DOUBLE_EQ(e.seconds, e.points * kPointSecondsPerPoint);
  // The default scale gives the default output size, whatever the area.
  const double s = default_points_scale(density, area);
  EXPECT_NEAR(estimate_points_on_mesh(density, area, s, o).points, kDefaultPointsOnMesh, 1e-6 * kDefaultPointsOnMesh);
  EXPECT_THROW(default_points_scale(density, 0.0), InvalidInput);
}

TEST(PointTextureOnMesh, ImpossibleSizesAreNamedWithoutOverflow) {
  // A scale of 1e-12 asks for ~1e25 points: refused by the budget with a
  // saturated count (an int64 conversion here was undefined behaviour).
  const PointExemplar& ex = bumps_exemplar();
  const TriangleMesh sphere = exsynth::testing::icosphere(1.0f, 2);
  std::vector<V3> around(sphere.vertices.size());
  for (std::size_t i = 0; i < around.size(); ++i) around[i] = V3::UnitZ().cross(sphere.vertices[i]);
  try {
    synthesize_points_on_mesh(ex, sphere, around, 1e-12, small_options());
    FAIL() << "expected OverBudget";
  } catch (const OverBudget& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("e+"), std::string::npos) << m;
    EXPECT_EQ(m.find("-9223372036854775808"), std::string::npos) << m;
    EXPECT_NE(m.find("raise the scale"), std::string::npos) << m;
  }
  EXPECT_EQ(format_count(1e30), "1e+30");
  EXPECT_EQ(format_count(437361.0), "437361");
  EXPECT_EQ(format_count(std::numeric_limits<double>::infinity()), "infinitely many");
  EXPECT_EQ(format_bytes(1e40).find("TiB") != std::string::npos, true);
  // An all-zero field gives no direction.
  const std::vector<V3> zero(sphere.vertices.size(), V3::Zero());
  EXPECT_THROW(synthesize_points_on_mesh(ex, sphere, zero, 1.0, small_options()), InvalidInput);
  // A patch smaller than two point spacings holds no points.
  PointTextureOptions tiny = small_options();
  tiny.patch_size = 1e-9;
  try {
    synthesize_points(ex, 1.0, 1.0, tiny);
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("less than two of the exemplar's point spacings"), std::string::npos) << e.what();
  }
}

TEST(PointsToMesh, ASpacingTooSmallForTheIndexRangeIsRefused) {
  const OrientedPoints pts = sphere_points(1.0f, 200);
  try {
    points_to_mesh(pts, 1e-9);
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("give a spacing of at least"), std::string::npos) << e.what();
  }
}
