// Vertex charts: stars of ptex faces around shared corners, the tabulated
// limit map of the regular star per valence, and the maps between face
// domains and charts (see charts.hpp).
#include "surface/charts.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "surface/walk.hpp"

namespace exsynth::surface {

namespace {

constexpr int kRings = 3;        // vertex rings of the synthetic star (faces up to ring 2 get exact patches)
constexpr int kCells = 16;       // table cells per unit of sector coordinates
constexpr int kMaxValence = 64;  // larger stars get no chart (walks instead)

/// The regular star of valence k (k sectors of kRings x kRings quads; on a
/// boundary k sectors between k + 1 rays spanning pi), laid out linearly:
/// vertex (a, b) of sector j at a ray_j + b ray_{j+1}.
PolygonMesh regular_star(int k, bool boundary, double opening) {
  PolygonMesh m;
  const int rays = boundary ? k + 1 : k;
  auto ray = [&](int r) { return Eigen::Vector2d(std::cos(r * opening), std::sin(r * opening)); };
  m.vertices.push_back(Eigen::Vector3f::Zero());
  // Ray vertices R(r, a), a = 1..kRings, then the inner vertices of each sector.
  for (int r = 0; r < rays; ++r)
    for (int a = 1; a <= kRings; ++a) {
      const Eigen::Vector2d p = a * ray(r);
      m.vertices.emplace_back(float(p.x()), float(p.y()), 0.0f);
    }
  const int inner0 = int(m.vertices.size());
  for (int j = 0; j < k; ++j)
    for (int b = 1; b <= kRings; ++b)
      for (int a = 1; a <= kRings; ++a) {
        const Eigen::Vector2d p = a * ray(j) + b * ray(j + 1);
        m.vertices.emplace_back(float(p.x()), float(p.y()), 0.0f);
      }
  auto vid = [&](int j, int a, int b) {
    if (a == 0 && b == 0) return 0;
    if (b == 0) return 1 + (j % rays) * kRings + (a - 1);
    if (a == 0) return 1 + ((j + 1) % rays) * kRings + (b - 1);
    return inner0 + (j * kRings + (b - 1)) * kRings + (a - 1);
  };
  for (int j = 0; j < k; ++j)
    for (int b = 0; b < kRings; ++b)
      for (int a = 0; a < kRings; ++a) {
        m.face_sizes.push_back(4);
        for (int v : {vid(j, a, b), vid(j, a + 1, b), vid(j, a + 1, b + 1), vid(j, a, b + 1)})
          m.face_vertices.push_back(v);
      }
  return m;
}

/// Sector tables of the regular star: its Catmull-Clark limit evaluated
/// (Bfr, as the real surface) on the star face and ring of every sector.
std::vector<SectorTable> star_tables(int k, bool boundary, double opening) {
  const PolygonMesh m = regular_star(k, boundary, opening);
  const SubdivSurface star(m);
  std::vector<SectorTable> out{std::size_t(k)};
  const int side = 2 * kCells + 1;
  for (int j = 0; j < k; ++j) {
    SectorTable& tab = out[std::size_t(j)];
    tab.cells = kCells;
    tab.ray0 = Eigen::Vector2d(std::cos(j * opening), std::sin(j * opening));
    const int next = boundary ? j + 1 : (j + 1) % k;  // the last sector ends on ray 0 exactly
    tab.ray1 = Eigen::Vector2d(std::cos(next * opening), std::sin(next * opening));
    const std::size_t nodes = std::size_t(side) * std::size_t(side);
    tab.y.resize(nodes);
    tab.ys.resize(nodes);
    tab.yt.resize(nodes);
    for (int jt = 0; jt < side; ++jt)
      for (int is = 0; is < side; ++is) {
        const double s = double(is) / kCells, t = double(jt) / kCells;
        const int a = std::min(int(s), 1), b = std::min(int(t), 1);
        const int face = star.first_ptex_face((j * kRings + b) * kRings + a);
        const LimitFrame lf = star.evaluate({face, s - a, t - b});
        const std::size_t at = std::size_t(jt * side + is);
        tab.y[at] = lf.position.head<2>();
        tab.ys[at] = lf.du.head<2>();
        tab.yt[at] = lf.dv.head<2>();
      }
    tab.linear = (!boundary && k == 4) || (boundary && k == 2);
    tab.to_linear << tab.ray0, tab.ray1;
    tab.to_linear = tab.to_linear.inverse().eval();
    // The rays are exact by symmetry; keep them exact in the table too.
    for (int i = 0; i < side; ++i) {
      const std::size_t r0 = std::size_t(i), r1 = std::size_t(i * side);
      tab.y[r0] = tab.ray0 * tab.ray0.dot(tab.y[r0]);
      tab.ys[r0] = tab.ray0 * tab.ray0.dot(tab.ys[r0]);
      tab.y[r1] = tab.ray1 * tab.ray1.dot(tab.y[r1]);
      tab.yt[r1] = tab.ray1 * tab.ray1.dot(tab.yt[r1]);
    }
  }
  for (SectorTable& tab : out) tab.build_inverse();
  return out;
}

}  // namespace

Eigen::Vector2d SectorTable::eval(double s, double t, Eigen::Matrix2d* jac) const {
  if (linear) {
    if (jac) *jac << ray0, ray1;
    return s * ray0 + t * ray1;
  }
  const int side = 2 * cells + 1;
  const double x = s * cells, z = t * cells, hc = 1.0 / cells;
  const int i = std::clamp(int(std::floor(x)), 0, 2 * cells - 1), j = std::clamp(int(std::floor(z)), 0, 2 * cells - 1);
  const double fx = x - i, fz = z - j;
  // Cubic Hermite basis (value at 0, value at 1, slope at 0, slope at 1) and derivatives.
  auto basis = [](double f, double* b, double* d) {
    const double f2 = f * f, f3 = f2 * f;
    b[0] = 2 * f3 - 3 * f2 + 1;
    b[1] = -2 * f3 + 3 * f2;
    b[2] = f3 - 2 * f2 + f;
    b[3] = f3 - f2;
    d[0] = 6 * f2 - 6 * f;
    d[1] = -6 * f2 + 6 * f;
    d[2] = 3 * f2 - 4 * f + 1;
    d[3] = 3 * f2 - 2 * f;
  };
  double bx[4], dx[4], bz[4], dz[4];
  basis(fx, bx, dx);
  basis(fz, bz, dz);
  Eigen::Vector2d v = Eigen::Vector2d::Zero(), vs = Eigen::Vector2d::Zero(), vt = Eigen::Vector2d::Zero();
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a) {
      const std::size_t n = std::size_t((j + b) * side + i + a);
      // node value, s-slope and t-slope terms of corner (a, b)
      v += bx[a] * bz[b] * y[n] + hc * (bx[2 + a] * bz[b] * ys[n] + bx[a] * bz[2 + b] * yt[n]);
      if (jac) {
        vs += dx[a] * bz[b] * y[n] + hc * (dx[2 + a] * bz[b] * ys[n] + dx[a] * bz[2 + b] * yt[n]);
        vt += bx[a] * dz[b] * y[n] + hc * (bx[2 + a] * dz[b] * ys[n] + bx[a] * dz[2 + b] * yt[n]);
      }
    }
  if (jac) {
    jac->col(0) = vs * cells;
    jac->col(1) = vt * cells;
  }
  return v;
}

bool SectorTable::invert(const Eigen::Vector2d& target, double& s, double& t, bool exact) const {
  Eigen::Vector2d x = to_linear * target;
  if (linear) {
    s = x.x();
    t = x.y();
    return true;
  }
  if (!inverse.empty()) {
    // Bilinear in the inverse table (linear extrapolation past its range).
    const int n = int(std::lround(kInverseRange * cells)), side = n + 1;
    const double gx = x.x() * cells, gz = x.y() * cells;
    const int i = std::clamp(int(std::floor(gx)), 0, n - 1), j = std::clamp(int(std::floor(gz)), 0, n - 1);
    const double fx = gx - i, fz = gz - j;
    const std::size_t at = std::size_t(j * side + i);
    x = (1 - fz) * ((1 - fx) * inverse[at] + fx * inverse[at + 1]) +
        fz * ((1 - fx) * inverse[at + std::size_t(side)] + fx * inverse[at + std::size_t(side) + 1]);
    if (!exact) {
      s = x.x();
      t = x.y();
      return true;
    }
  }
  const double tol = 1e-12 * std::max(1.0, target.norm());
  for (int it = 0; it < 12; ++it) {
    Eigen::Matrix2d J;
    const Eigen::Vector2d r = eval(x.x(), x.y(), &J) - target;
    if (r.norm() < tol) {
      s = x.x();
      t = x.y();
      return true;
    }
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-300)) return false;
    x -= J.inverse() * r;
  }
  Eigen::Matrix2d J;
  if ((eval(x.x(), x.y(), &J) - target).norm() > 1e-9 * std::max(1.0, target.norm())) return false;
  s = x.x();
  t = x.y();
  return true;
}

void SectorTable::build_inverse() {
  to_linear << ray0, ray1;
  to_linear = to_linear.inverse().eval();
  inverse.clear();
  if (linear) return;
  const int n = int(std::lround(kInverseRange * cells)), side = n + 1;
  std::vector<Eigen::Vector2d> nodes(std::size_t(side) * std::size_t(side));
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const Eigen::Vector2d lin(double(i) / cells, double(j) / cells);
      double s = lin.x(), t = lin.y();
      // Exact (Newton) inverse at the node; its linear guess where Newton fails (far outside).
      if (!invert(ray0 * lin.x() + ray1 * lin.y(), s, t, true)) {
        s = lin.x();
        t = lin.y();
      }
      nodes[std::size_t(j * side + i)] = Eigen::Vector2d(s, t);
    }
  inverse = std::move(nodes);
}

VertexCharts::VertexCharts(const SubdivSurface& surface) : surface_(surface) {
  const int np = surface.ptex_face_count();
  corner_chart_.assign(std::size_t(np) * 4, -1);
  corner_sector_.assign(std::size_t(np) * 4, -1);
  std::vector<char> seen(std::size_t(np) * 4, 0);
  // Crossings are taken just inside the edge: at an n-gon's edge midpoint
  // cross_edge may pick either sub-face for the end point itself.
  constexpr double inset = 1e-7, eps = 1e-5;
  // Clockwise neighbour of star face (f, q): across its s-edge (ptex edge q)
  // at the corner's end (t = 0); counter-clockwise: across its t-edge (edge
  // q - 1) at t = 1. -1 = the star ends (boundary or T-junction).
  auto cw = [&](std::pair<int, int> fq) -> std::pair<int, int> {
    const SubdivSurface::EdgeCrossing c = surface.cross_edge(fq.first, fq.second, inset);
    if (c.face < 0 || std::abs(c.t - 1) > eps) return {-1, -1};
    return {c.face, (c.edge + 1) % 4};
  };
  // Also the crossing's scale (sub-face parameter per quad parameter).
  auto ccw = [&](std::pair<int, int> fq, double& scale) -> std::pair<int, int> {
    const SubdivSurface::EdgeCrossing c = surface.cross_edge(fq.first, (fq.second + 3) % 4, 1 - inset);
    if (c.face < 0 || std::abs(c.t) > eps) return {-1, -1};
    scale = c.scale;
    return {c.face, c.edge};
  };
  std::vector<std::pair<int, int>> ring;
  std::vector<double> scales;
  for (int f = 0; f < np; ++f)
    for (int q = 0; q < 4; ++q) {
      if (seen[std::size_t(f) * 4 + std::size_t(q)]) continue;
      // Find the clockwise end (a boundary) or go round once (interior).
      std::pair<int, int> start{f, q};
      bool closed = false;
      for (int step = 0; step <= kMaxValence; ++step) {
        const std::pair<int, int> prev = cw(start);
        if (prev.first < 0) break;
        if (prev == std::make_pair(f, q)) {
          closed = true;
          start = {f, q};
          break;
        }
        start = prev;
      }
      ring.clear();
      scales.clear();
      std::pair<int, int> cur = start;
      double scale = 1;
      for (int step = 0; step < kMaxValence + 1; ++step) {
        ring.push_back(cur);
        scales.push_back(scale);
        double cross = 1;
        cur = ccw(cur, cross);
        scale /= cross;  // equal lengths along the shared edge in the chart
        if (cur.first < 0 || cur == start) break;
      }
      const double least = *std::min_element(scales.begin(), scales.end());
      const bool interior = closed && cur == start;
      for (const auto& fq : ring) seen[std::size_t(fq.first) * 4 + std::size_t(fq.second)] = 1;
      const int k = int(ring.size());
      // Interior valence 2 and one boundary face would give a degenerate
      // (flat-angle) sector; such corners walk instead.
      if (k > kMaxValence || (interior && k < 3) || (!interior && k < 2)) continue;
      Star st;
      st.first = int(star_.size());
      st.k = k;
      st.boundary = !interior;
      st.opening = (interior ? 2 * M_PI : M_PI) / k;
      auto& tabs = tables_[{k, st.boundary}];
      if (!tabs) tabs = std::make_unique<std::vector<SectorTable>>(star_tables(k, st.boundary, st.opening));
      st.tables = tabs.get();
      const int id = int(charts_.size());
      for (int j = 0; j < k; ++j) {
        star_.push_back({ring[std::size_t(j)].first, ring[std::size_t(j)].second, scales[std::size_t(j)] / least});
        const std::size_t at = std::size_t(ring[std::size_t(j)].first) * 4 + std::size_t(ring[std::size_t(j)].second);
        corner_chart_[at] = id;
        corner_sector_[at] = j;
      }
      charts_.push_back(st);
    }
  // A star face with a corner that has no chart (one face on a boundary, an
  // inner valence 2) is not where the regular star's limit map says: the
  // open grid's corner faces put chart samples up to half a texel from the
  // walked ones (multiscale flat-plane score 0.527 vs 0.480 walking). Such
  // stars walk instead.
  std::vector<char> drop(charts_.size(), 0);
  for (std::size_t c = 0; c < charts_.size(); ++c)
    for (int j = 0; j < charts_[c].k; ++j) {
      const int f = star_[std::size_t(charts_[c].first + j)].face;
      for (int q = 0; q < 4; ++q) drop[c] = drop[c] || corner_chart_[std::size_t(f) * 4 + std::size_t(q)] < 0;
    }
  for (std::size_t c = 0; c < charts_.size(); ++c) charts_[c].unused = drop[c] != 0;
}

std::vector<int> VertexCharts::star_faces(int chart) const {
  const Star& st = charts_[std::size_t(chart)];
  std::vector<int> out;
  for (int j = 0; j < st.k; ++j) out.push_back(star_[std::size_t(st.first + j)].face);
  return out;
}

Eigen::Vector2d VertexCharts::to_chart(int chart, const SurfacePoint& p, Eigen::Matrix2d* jac) const {
  int q = 0;
  while (q < 3 && corner_chart_[std::size_t(p.face) * 4 + std::size_t(q)] != chart) ++q;
  const Star& st = charts_[std::size_t(chart)];
  const int sector = corner_sector_[std::size_t(p.face) * 4 + std::size_t(q)];
  // Corner-local coordinates: corner q at the origin, s along ptex edge q.
  const double sigma = star_[std::size_t(st.first + sector)].scale;
  double s, t;
  to_edge(q, p.u, p.v, s, t);  // (along ptex edge q, inward)
  Eigen::Matrix2d dst;
  const Eigen::Vector2d y = table(st, sector).eval(sigma * s, sigma * t, jac ? &dst : nullptr);
  if (jac) {
    dst *= sigma;
    // d(s, t) / d(u, v) of the rotation by q quarter turns.
    static const double rot[4][4] = {{1, 0, 0, 1}, {0, 1, -1, 0}, {-1, 0, 0, -1}, {0, -1, 1, 0}};
    Eigen::Matrix2d R;
    R << rot[q][0], rot[q][1], rot[q][2], rot[q][3];
    *jac = dst * R;
  }
  return y;
}

int VertexCharts::sector_of(int chart, int face) const {
  for (int q = 0; q < 4; ++q)
    if (corner_chart_[std::size_t(face) * 4 + std::size_t(q)] == chart) return corner_sector_[std::size_t(face) * 4 + std::size_t(q)];
  return 0;
}

bool VertexCharts::from_chart(int chart, const Eigen::Vector2d& y, SurfacePoint& out, bool exact,
                              int sector_hint) const {
  const Star& st = charts_[std::size_t(chart)];
  // The sector whose rays y lies between (the rays are straight in the
  // chart): from the hint towards the side y falls on.
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  int sector = std::clamp(sector_hint, 0, st.k - 1);
  const double on_ray = 1e-12 * y.norm();  // round-off: on the ray counts as inside
  for (int step = 0;; ++step) {
    if (step > st.k) return false;
    const SectorTable& tab = table(st, sector);
    if (cross(tab.ray0, y) < -on_ray) {
      if (sector == 0 && st.boundary) return false;  // past the boundary
      sector = sector == 0 ? st.k - 1 : sector - 1;
    } else if (cross(tab.ray1, y) > on_ray) {
      if (sector == st.k - 1 && st.boundary) return false;
      sector = sector == st.k - 1 ? 0 : sector + 1;
    } else {
      break;
    }
  }
  double s, t;
  if (!table(st, sector).invert(y, s, t, exact)) return false;
  // Round-off at the star face's sides stays on them.
  auto snap = [](double x) { return x < 0 ? 0.0 : (x > 1 && x < 1 + 1e-9 ? 1.0 : (x > 2 && x < 2 + 1e-9 ? 2.0 : x)); };
  s = snap(s);
  t = snap(t);
  if (s > 2 || t > 2) return false;  // past the ring
  const StarFace& sf = star_[std::size_t(st.first + sector)];
  const int face = sf.face, q = sf.corner;
  if (sf.scale != 1) {  // a quad among sub-faces covers its whole sector
    from_edge(q, s / sf.scale, t / sf.scale, out.u, out.v);
    out.u = std::clamp(out.u, 0.0, 1.0);
    out.v = std::clamp(out.v, 0.0, 1.0);
    out.face = face;
    return true;
  }
  if (s > 1 && t > 1) return false;  // beyond the star face's far corner
  if (s <= 1 && t <= 1) {
    from_edge(q, s, t, out.u, out.v);
    out.face = face;
    return true;
  }
  // Into the ring face across local edge 1 (s = 1) or 2 (t = 1).
  const int local = s > 1 ? 1 : 2;
  double along, inward;
  to_edge(local, s, t, along, inward);
  const SubdivSurface::EdgeCrossing c = surface_.cross_edge(face, (q + local) % 4, std::clamp(along, 0.0, 1.0));
  const double d = -inward * c.scale;
  if (c.face < 0 || d > 1) return false;
  SurfacePoint p{c.face, 0, 0};
  from_edge(c.edge, c.t, d, p.u, p.v);
  p.u = std::clamp(p.u, 0.0, 1.0);
  p.v = std::clamp(p.v, 0.0, 1.0);
  out = p;
  return true;
}

}  // namespace exsynth::surface
