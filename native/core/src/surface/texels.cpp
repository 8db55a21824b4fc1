#include "surface/texels.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "exsynth/parallel.hpp"
#include "surface/charts.hpp"
#include "surface/walk.hpp"

namespace exsynth::surface {

TexelGrid::TexelGrid(std::vector<int> resolution) : res(std::move(resolution)) {
  offset.resize(res.size() + 1, 0);
  for (std::size_t f = 0; f < res.size(); ++f) offset[f + 1] = offset[f] + std::size_t(res[f]) * std::size_t(res[f]);
  face_of.resize(size());
  for (std::size_t f = 0; f < res.size(); ++f)
    std::fill(face_of.begin() + std::ptrdiff_t(offset[f]), face_of.begin() + std::ptrdiff_t(offset[f + 1]), int(f));
}

std::size_t TexelGrid::texel(const SurfacePoint& p) const {
  const int r = res[std::size_t(p.face)];
  const int i = std::clamp(int(std::floor(p.u * r)), 0, r - 1);
  const int j = std::clamp(int(std::floor(p.v * r)), 0, r - 1);
  return offset[std::size_t(p.face)] + std::size_t(j) * std::size_t(r) + std::size_t(i);
}

SurfacePoint TexelGrid::centre(std::size_t t) const {
  const int f = face_of[t];
  const int r = res[std::size_t(f)];
  const std::size_t k = t - offset[std::size_t(f)];
  return {f, (double(k % std::size_t(r)) + 0.5) / r, (double(k / std::size_t(r)) + 0.5) / r};
}

TexelGrid TexelGrid::coarser() const {
  std::vector<int> r(res.size());
  for (std::size_t f = 0; f < res.size(); ++f) r[f] = std::max(1, res[f] / 2);
  return TexelGrid(std::move(r));
}

LimitFrame TexelFrames::approx(const SurfacePoint& p) const {
  // grid.texel and grid.centre in one (no integer division: walks call this
  // at every step).
  const int r = grid.res[std::size_t(p.face)];
  const int i = std::clamp(int(std::floor(p.u * r)), 0, r - 1);
  const int j = std::clamp(int(std::floor(p.v * r)), 0, r - 1);
  const std::size_t t = grid.offset[std::size_t(p.face)] + std::size_t(j) * std::size_t(r) + std::size_t(i);
  const SurfacePoint c{p.face, (i + 0.5) / r, (j + 0.5) / r};
  LimitFrame f;
  f.du = du[t].cast<double>();
  f.dv = dv[t].cast<double>();
  f.position = position[t].cast<double>() + f.du * (p.u - c.u) + f.dv * (p.v - c.v);
  return f;
}

TexelFrames build_texel_frames(const SubdivSurface& surface, TexelGrid grid,
                               const std::vector<Eigen::Vector3f>& field, ExecContext* ctx) {
  TexelFrames fr;
  fr.grid = std::move(grid);
  const std::size_t n = fr.grid.size();
  fr.position.resize(n);
  fr.du.resize(n);
  fr.dv.resize(n);
  fr.t1.resize(n);
  fr.t2.resize(n);
  std::vector<float> flat(field.size() * 3);
  for (std::size_t i = 0; i < field.size(); ++i)
    for (int k = 0; k < 3; ++k) flat[i * 3 + std::size_t(k)] = field[i][k];
  const SubdivSurface::VertexData data = surface.prepare_vertex_data(flat, 3);
  StageProgress progress(ctx, "surface frames", 0.0, 1.0, n);
  parallel_chunks(n, 4096, progress, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      const SurfacePoint p = fr.grid.centre(t);
      const LimitFrame lf = surface.evaluate(p);
      double v[3];
      surface.evaluate_data(data, p, v);
      const Eigen::Vector3d nrm = lf.du.cross(lf.dv).normalized();
      Eigen::Vector3d a(v[0], v[1], v[2]);
      a -= a.dot(nrm) * nrm;
      if (!(a.norm() > 1e-6)) a = lf.du;
      a.normalize();
      fr.position[t] = lf.position.cast<float>();
      fr.du[t] = lf.du.cast<float>();
      fr.dv[t] = lf.dv.cast<float>();
      fr.t1[t] = a.cast<float>();
      fr.t2[t] = nrm.cross(a).normalized().cast<float>();
    }
  });
  return fr;
}

// The cache is linear per texel (no need for short steps) and only
// piecewise smooth (loose tolerance, few corrections, slide along edges).
constexpr WalkParams kCachedWalk{1e-3, 1.0, 3, true};
// Walks that only need the texel they land in: 2 % of a step is far inside it.
constexpr WalkParams kLandingWalk{2e-2, 1.0, 2, true};

bool walk_cached(const SubdivSurface& surface, const TexelFrames& frames, SurfacePoint& p,
                 const Eigen::Vector3d& d, bool landing_only) {
  return walk_surface([&](const SurfacePoint& q) { return frames.approx(q); },
                      [&](int f, int e, double t) { return surface.cross_edge(f, e, t); }, p, d,
                      landing_only ? kLandingWalk : kCachedWalk);
}

void sample_points(const SubdivSurface& surface, const TexelFrames& frames, std::size_t t, double h, int r,
                   SurfacePoint* out, bool* valid) {
  const SurfacePoint c = frames.grid.centre(t);
  const Eigen::Vector3d a = frames.t1[t].cast<double>() * h, b = frames.t2[t].cast<double>() * h;
  int k = 0;
  for (int m = -r; m <= r; ++m)
    for (int l = -r; l <= r; ++l, ++k) {
      SurfacePoint p = c;
      valid[k] = (l == 0 && m == 0) ? true : walk_cached(surface, frames, p, double(l) * a - double(m) * b);
      out[k] = p;
    }
}

void march_points(const SubdivSurface& surface, const TexelFrames& frames, const SurfacePoint& c,
                  const Eigen::Vector3d& a, const Eigen::Vector3d& b, int r, bool landing_only, SurfacePoint* out,
                  bool* valid) {
  const int side = 2 * r + 1;
  auto march_row = [&](SurfacePoint start, bool ok, int m) {
    out[(m + r) * side + r] = start;
    valid[(m + r) * side + r] = ok;
    for (int dir : {1, -1}) {
      SurfacePoint q = start;
      bool inside = ok;
      for (int i = 1; i <= r; ++i) {
        inside = walk_cached(surface, frames, q, double(dir) * a, landing_only) && inside;
        out[(m + r) * side + r + dir * i] = q;
        valid[(m + r) * side + r + dir * i] = inside;
      }
    }
  };
  march_row(c, true, 0);
  for (int dir : {1, -1}) {
    SurfacePoint start = c;
    bool inside = true;
    for (int m = 1; m <= r; ++m) {
      inside = walk_cached(surface, frames, start, -double(dir) * b, landing_only) && inside;
      march_row(start, inside, dir * m);
    }
  }
}

namespace {
/// Chart units a neighbourhood may span (r (|tau_a| + |tau_b|)) before it is
/// marched whole: the star face is about one unit, its ring reaches two.
constexpr double kChartReach = 2.0;

/// A chart sample whose tangent-plane offset from the centre is further
/// than this (in steps) from the asked one is corrected (below).
constexpr double kChartTolerance = 0.1;
constexpr int kChartCorrections = 2;

/// Sample at 3D tangent offset d = l a - m b from c (position pc, chart
/// coordinate y0), placed through the chart, then corrected: the
/// chart's straight lines are not the surface's where the real star differs
/// from the regular one (a triangle's sub-faces: kite angles of 45-135
/// degrees laid out as 60 or 90 degree sectors; on a triangulated flat plane
/// the uncorrected samples sat 0.19 steps from the plane grid on average, up
/// to 1.6 steps). The correction: quasi-Newton steps in the chart on the
/// residual d - (P(p) - pc) in the (a, b) basis, starting from the chart
/// steps ta, tb (at most kChartCorrections). False where the chart ends
/// (the sample is then marched); where the correction does not converge (strongly curved stars,
/// where the chord from the centre is no longer the walked offset) the best
/// iterate is kept.
bool place_in_chart(const VertexCharts& charts, const TexelFrames& frames, int chart, int hint,
                    const Eigen::Vector3d& pc, const Eigen::Vector2d& y0, const Eigen::Vector3d& d,
                    const Eigen::Vector2d& ta, const Eigen::Vector2d& tb, const Eigen::Vector3d& a,
                    const Eigen::Vector3d& b, bool landing_only, SurfacePoint& p) {
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm();
  double best = std::numeric_limits<double>::infinity();
  // T maps a change of the offset, in (a, b) steps, to a chart step: the
  // chart steps at the centre first, then Broyden-updated from the iterates
  // (the real distortion at the sample can be twice the centre's, where a
  // fixed T converges slowly or not at all).
  Eigen::Matrix2d T;
  T << ta, tb;
  const Eigen::Vector2d want(d.dot(a) / a2, d.dot(b) / b2);
  const Eigen::Vector2d y_start = y0 + want.x() * ta + want.y() * tb;
  Eigen::Vector2d yi = y_start, y_prev, f_prev;
  const double step2 = 2.0 * (ta.squaredNorm() + tb.squaredNorm());
  SurfacePoint q = p;
  for (int it = 0; it <= kChartCorrections; ++it) {
    if (!charts.from_chart(chart, yi, q, !landing_only, hint)) return it > 0;
    const Eigen::Vector3d off = frames.approx(q).position - pc;
    const Eigen::Vector2d f(off.dot(a) / a2, off.dot(b) / b2);
    const Eigen::Vector2d res = want - f;
    const double err = res.squaredNorm();
    if (err < best) {
      best = err;
      p = q;
    }
    if (err <= kChartTolerance * kChartTolerance) break;
    if (it > 0) {
      const Eigen::Vector2d df = f - f_prev, dy = yi - y_prev;
      const double n2 = df.squaredNorm();
      if (n2 > 1e-12) T += ((dy - T * df) * df.transpose()) / n2;
    }
    y_prev = yi;
    f_prev = f;
    yi += T * res;
    // A correction of more than two steps is not the chart's distortion (a
    // tight bend: the chord is not the walked offset there).
    if ((yi - y_start).squaredNorm() > step2) break;
  }
  return true;
}
}  // namespace

void chart_points(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts& charts,
                  const SurfacePoint& c, const Eigen::Vector3d& du, const Eigen::Vector3d& dv,
                  const Eigen::Vector3d& a, const Eigen::Vector3d& b, int r, bool landing_only, SurfacePoint* out,
                  bool* valid, ChartStats* stats) {
  const int chart = charts.chart(c.face, VertexCharts::nearest_corner(c.u, c.v));
  if (chart < 0) {
    march_points(surface, frames, c, a, b, r, landing_only, out, valid);
    if (stats) stats->walked += std::uint64_t((2 * r + 1) * (2 * r + 1));
    return;
  }
  Eigen::Matrix2d jac;
  const Eigen::Vector2d y0 = charts.to_chart(chart, c, &jac);
  // Parameter steps of a and b (least squares [du dv] x = d), into the chart.
  Eigen::Matrix<double, 3, 2> G;
  G << du, dv;
  const Eigen::Matrix2d gtg = G.transpose() * G;
  const Eigen::Matrix2d to_param = gtg.inverse();
  const Eigen::Vector2d ta = jac * (to_param * (G.transpose() * a));
  const Eigen::Vector2d tb = jac * (to_param * (G.transpose() * b));
  // A neighbourhood far larger than the star and its ring (coarse levels)
  // is marched whole without trying the chart.
  if (double(r) * (ta.norm() + tb.norm()) > kChartReach) {
    march_points(surface, frames, c, a, b, r, landing_only, out, valid);
    if (stats) stats->walked += std::uint64_t((2 * r + 1) * (2 * r + 1));
    return;
  }
  const int hint = charts.sector_of(chart, c.face);
  const Eigen::Vector3d pc = frames.approx(c).position;
  SurfacePoint marched[kMaxSamples];
  bool marched_valid[kMaxSamples];
  bool have_march = false;
  std::uint64_t walked = 0;
  int k = 0;
  for (int m = -r; m <= r; ++m)
    for (int l = -r; l <= r; ++l, ++k) {
      if (l == 0 && m == 0) {
        out[k] = c;
        valid[k] = true;
        continue;
      }
      SurfacePoint p = c;
      if (place_in_chart(charts, frames, chart, hint, pc, y0, double(l) * a - double(m) * b, ta, tb, a, b,
                         landing_only, p)) {
        out[k] = p;
        valid[k] = true;
        continue;
      }
      // Past the chart: the marched sample (the whole neighbourhood marched once).
      if (!have_march) {
        march_points(surface, frames, c, a, b, r, landing_only, marched, marched_valid);
        have_march = true;
      }
      out[k] = marched[k];
      valid[k] = marched_valid[k];
      ++walked;
    }
  if (stats) {
    stats->walked += walked;
    stats->in_chart += std::uint64_t(k) - walked;
  }
}

void sample_exemplar(const Image& ex, double x, double y, bool wrap, float* out) {
  const int w = ex.width(), h = ex.height(), c = ex.channels();
  if (wrap) {
    x = std::fmod(x, double(w));
    if (x < 0) x += w;
    y = std::fmod(y, double(h));
    if (y < 0) y += h;
  } else {
    x = std::clamp(x, 0.0, double(w - 1));
    y = std::clamp(y, 0.0, double(h - 1));
  }
  const int x0 = std::min(int(x), w - 1), y0 = std::min(int(y), h - 1);
  const int x1 = wrap ? (x0 + 1) % w : std::min(x0 + 1, w - 1);
  const int y1 = wrap ? (y0 + 1) % h : std::min(y0 + 1, h - 1);
  const float fx = float(x - x0), fy = float(y - y0);
  const float* p00 = ex.data() + ex.offset(x0, y0);
  const float* p10 = ex.data() + ex.offset(x1, y0);
  const float* p01 = ex.data() + ex.offset(x0, y1);
  const float* p11 = ex.data() + ex.offset(x1, y1);
  for (int k = 0; k < c; ++k)
    out[k] = (1 - fy) * ((1 - fx) * p00[k] + fx * p10[k]) + fy * ((1 - fx) * p01[k] + fx * p11[k]);
}

}  // namespace exsynth::surface
