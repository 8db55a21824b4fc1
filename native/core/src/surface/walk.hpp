#pragma once
// Walking over the limit surface from face to face (private). Templated on
// the evaluator so the same stepping runs on exact Bfr evaluations (tests,
// coarse levels) and on the per-texel first-order cache the synthesis uses
// (about 50x cheaper, first-order exact inside a texel).
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "exsynth/surface.hpp"

namespace exsynth::surface {

/// Ptex edge e as (t along the edge, counter-clockwise; s inward distance).
inline void to_edge(int e, double u, double v, double& t, double& s) {
  switch (e) {
    case 0: t = u; s = v; break;
    case 1: t = v; s = 1 - u; break;
    case 2: t = 1 - u; s = 1 - v; break;
    default: t = 1 - v; s = u; break;
  }
}
inline void from_edge(int e, double t, double s, double& u, double& v) {
  switch (e) {
    case 0: u = t; v = s; break;
    case 1: u = 1 - s; v = t; break;
    case 2: u = 1 - t; v = 1 - s; break;
    default: u = s; v = 1 - t; break;
  }
}

/// Largest parameter step per iteration: keeps the linearisation local on
/// strongly curved faces (a quarter of the face).
constexpr double kMaxParamStep = 0.25;

/// See SubdivSurface::walk. `eval(p)` returns a LimitFrame; `cross(f, e, t)`
/// a SubdivSurface::EdgeCrossing.
struct WalkParams {
  double rel_tol = 1e-9;              ///< stop when the rest is below rel_tol |d|
  double max_step = kMaxParamStep;    ///< largest parameter step per iteration
  int max_corrections = 32;           ///< see below
  /// Slide along an edge just crossed instead of crossing it back: the
  /// cache's frames differ slightly on the two sides of an edge, so a walk
  /// nearly along it would bounce between the faces. (Exact frames agree.)
  bool slide = false;
};

template <class Eval, class Crossing>
bool walk_surface(Eval&& eval, Crossing&& cross, SurfacePoint& p, Eigen::Vector3d d, const WalkParams& wp = {}) {
  const double len0 = d.norm();
  if (!(len0 > 0)) return true;
  // Converged when the rest is below tol, or after a few corrections (steps
  // with less than 1 % of the walk left, or following a whole in-face step):
  // the texel cache is only piecewise smooth, so near a face edge its
  // residual need not fall below tol and would bounce between the faces.
  const double tol = wp.rel_tol * len0;
  int corrections = 0, stalled = 0;
  int entry = -1;  // the edge p sits on after a crossing: do not bounce back through it
  LimitFrame f = eval(p);
  for (int it = 0; it < 96 && corrections < wp.max_corrections; ++it) {
    Eigen::Vector3d n = f.du.cross(f.dv);
    const double nn = n.norm();
    if (!(nn > 0)) return true;
    n /= nn;
    const double len = d.norm();
    if (len < tol) return true;
    Eigen::Vector3d dt = d - d.dot(n) * n;
    const double tl = dt.norm();
    if (!(tl > 0)) return true;
    dt *= len / tl;
    // Least-squares parameter step [du dv] x = dt.
    const double a = f.du.dot(f.du), b = f.du.dot(f.dv), c = f.dv.dot(f.dv);
    const double det = a * c - b * b;
    if (!(det > 0)) return true;
    const double r0 = f.du.dot(dt), r1 = f.dv.dot(dt);
    double x0 = (c * r0 - b * r1) / det, x1 = (a * r1 - b * r0) / det;
    const double m = std::max(std::abs(x0), std::abs(x1));
    if (wp.slide && entry >= 0) {
      // Inward component across the entry edge (e0: +v, e1: -u, e2: -v, e3: +u);
      // an outward one would only re-cross: slide along the edge instead.
      double& w = (entry == 0 || entry == 2) ? x1 : x0;
      const double inward = (entry == 0 || entry == 3) ? w : -w;
      if (inward < 0) w = 0;
    }
    bool whole = true;
    if (m > wp.max_step) {
      x0 *= wp.max_step / m;
      x1 *= wp.max_step / m;
      whole = false;
    }
    double lam = 1.0;
    int exit = -1;
    auto consider = [&](double t, int e) {
      if (t < lam) { lam = std::max(t, 0.0); exit = e; }
    };
    if (x0 > 0) consider((1 - p.u) / x0, 1);
    if (x0 < 0) consider(-p.u / x0, 3);
    if (x1 > 0) consider((1 - p.v) / x1, 2);
    if (x1 < 0) consider(-p.v / x1, 0);
    if (lam <= 0 && ++stalled > 8) return true;  // circling a vertex the cache cannot resolve
    SurfacePoint q{p.face, std::clamp(p.u + lam * x0, 0.0, 1.0), std::clamp(p.v + lam * x1, 0.0, 1.0)};
    bool inside = true;
    if (exit >= 0) {
      double t, s;
      to_edge(exit, q.u, q.v, t, s);
      const SubdivSurface::EdgeCrossing nb = cross(q.face, exit, t);
      if (nb.face < 0) {
        inside = false;
      } else {
        double u2, v2;
        from_edge(nb.edge, nb.t, 0, u2, v2);
        q = SurfacePoint{nb.face, std::clamp(u2, 0.0, 1.0), std::clamp(v2, 0.0, 1.0)};
        entry = nb.edge;
      }
    } else if (entry >= 0) {
      double t, s;
      to_edge(entry, q.u, q.v, t, s);
      if (s > 1e-12) entry = -1;  // left the edge
    }
    if ((exit < 0 && whole) || len < 1e-2 * len0) ++corrections;
    const LimitFrame g = eval(q);
    d = dt - (g.position - f.position);
    p = q;
    f = g;
    if (!inside) return false;
  }
  return true;
}

}  // namespace exsynth::surface
