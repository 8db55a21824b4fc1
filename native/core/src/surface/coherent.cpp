// Coherent synthesis on the surface (Ying et al. 2001, §5; Ashikhmin 2001):
// every texel keeps the float exemplar coordinate it was copied from;
// candidates are the sources of already synthesized texels within the
// neighbourhood radius, displaced by their tangent-plane offset.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <limits>

#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"
#include "surface/methods.hpp"
#include "surface/walk.hpp"

namespace exsynth::surface {

std::vector<std::size_t> synthesis_order(const SubdivSurface& surface, const TexelGrid& grid) {
  const int nf = surface.ptex_face_count();
  std::vector<int> entry_edge(std::size_t(nf), -2);  // -2 = not reached, -1 = seed face
  std::vector<int> faces;
  faces.reserve(std::size_t(nf));
  std::deque<int> queue;
  for (int seed = 0; seed < nf; ++seed) {
    if (entry_edge[std::size_t(seed)] != -2) continue;
    entry_edge[std::size_t(seed)] = -1;
    queue.push_back(seed);
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      faces.push_back(f);
      for (int e = 0; e < 4; ++e) {
        const SubdivSurface::Neighbour nb = surface.neighbour(f, e);
        if (nb.face < 0 || entry_edge[std::size_t(nb.face)] != -2) continue;
        entry_edge[std::size_t(nb.face)] = nb.edge;
        queue.push_back(nb.face);
      }
    }
  }
  std::vector<std::size_t> order;
  order.reserve(grid.size());
  for (int f : faces) {
    const int r = grid.res[std::size_t(f)];
    const int e = std::max(entry_edge[std::size_t(f)], 0);
    for (int row = 0; row < r; ++row)
      for (int col = 0; col < r; ++col) {
        double u, v;
        from_edge(e, (col + 0.5) / r, (row + 0.5) / r, u, v);
        order.push_back(grid.texel({f, u, v}));
      }
  }
  return order;
}

namespace {

/// The exemplar pixel nearest to float (x, y): texels copy pixels, never
/// blends of them (bilinear lookups of the drifting float coordinates blurred
/// the result: window distance 0.74 vs 0.28 for the 2D synthesis on a flat grid).
inline const float* nearest_pixel(const Image& ex, double x, double y, bool wrap) {
  const int w = ex.width(), h = ex.height();
  int xi = int(std::floor(x + 0.5)), yi = int(std::floor(y + 0.5));
  if (wrap) {
    xi = ((xi % w) + w) % w;
    yi = ((yi % h) + h) % h;
  } else {
    xi = std::clamp(xi, 0, w - 1);
    yi = std::clamp(yi, 0, h - 1);
  }
  return ex.data() + ex.offset(xi, yi);
}

void nearest_exemplar(const Image& ex, double x, double y, bool wrap, float* out) {
  const float* p = nearest_pixel(ex, x, y, wrap);
  std::copy(p, p + ex.channels(), out);
}

/// Per texel, its (2r+1)^2 - 1 neighbours (the centre left out): the texel
/// each sample lands in (-1 past a boundary) and that texel's offset in
/// exemplar pixels: the chord between the two centres on (v1, -v2) / h
/// (see below). Built in parallel
/// before the (sequential) synthesis.
struct NeighbourTable {
  int per = 0;
  std::vector<std::int32_t> texel;
  std::vector<Eigen::Vector2f> offset;
  ChartStats stats;
};

NeighbourTable neighbour_table(const SubdivSurface& surface, const TexelFrames& fr, const VertexCharts* charts, double h,
                               int r, ExecContext* ctx) {
  const int n = (2 * r + 1) * (2 * r + 1);
  NeighbourTable tab;
  tab.per = n - 1;
  const std::size_t count = fr.grid.size();
  tab.texel.resize(count * std::size_t(tab.per));
  tab.offset.resize(count * std::size_t(tab.per));
  StageProgress progress(ctx, "surface neighbourhoods", 0.0, 1.0, count);
  std::atomic<std::uint64_t> in_chart{0}, walked{0};
  parallel_chunks(count, 1024, progress, [&](std::size_t b, std::size_t e) {
    ChartStats stats;
    SurfacePoint pts[kMaxSamples];
    bool valid[kMaxSamples];
    for (std::size_t t = b; t < e; ++t) {
      const Eigen::Vector3d a = fr.t1[t].cast<double>(), bb = fr.t2[t].cast<double>();
      neighbourhood_points(surface, fr, charts, fr.grid.centre(t), t, h, r, pts, valid, &stats);
      std::size_t at = t * std::size_t(tab.per);
      for (int k = 0; k < n; ++k) {
        const int l = k % (2 * r + 1) - r, m = k / (2 * r + 1) - r;
        if (l == 0 && m == 0) continue;
        if (!valid[k]) {
          tab.texel[at++] = -1;
          continue;
        }
        const std::size_t q = fr.grid.texel(pts[k]);
        // The offset between the two texel centres themselves (their cached
        // limit positions, in t's tangent frame), not (l, m) corrected from
        // the landing point: the landing point is only within the walk's
        // (or chart's) tolerance of h (l v1 - m v2), and that error, copied
        // from texel to texel, made the float sources of a patch drift apart
        // by fractions of a pixel, so its texels rounded to different pixels
        // (on small faces and triangles' sub-faces; exact on the flat grid).
        // Where the surface curves so much within the neighbourhood that
        // the chord is more than a texel from the walked offset (a sample
        // around a tight bend), the walked offset, corrected to the centre
        // to first order, as before.
        const Eigen::Vector3d chord = (fr.position[q] - fr.position[t]).cast<double>();
        Eigen::Vector2d off(chord.dot(a) / h, -chord.dot(bb) / h);
        if ((off - Eigen::Vector2d(l, m)).squaredNorm() > 1.0) {
          const SurfacePoint& p = pts[k];
          const SurfacePoint c = fr.grid.centre(q);
          const Eigen::Vector3d to_centre =
              fr.du[q].cast<double>() * (c.u - p.u) + fr.dv[q].cast<double>() * (c.v - p.v);
          off = Eigen::Vector2d(l + to_centre.dot(a) / h, m - to_centre.dot(bb) / h);
        }
        tab.texel[at] = std::int32_t(q);
        tab.offset[at++] = off.cast<float>();
      }
    }
    in_chart += stats.in_chart;
    walked += stats.walked;
  });
  tab.stats.in_chart = in_chart;
  tab.stats.walked = walked;
  return tab;
}

}  // namespace

namespace {

/// Candidates closer than this (squared, exemplar pixels) count as one.
constexpr double kSameCandidate2 = 0.25;

/// The per-texel step of the coherent method over a built neighbour table.
class CoherentSolver {
 public:
  CoherentSolver(const NeighbourTable& tab, const Image& ex, const SurfaceSynthesisOptions& opt, SurfaceTexture& out,
                 std::vector<char>& done)
      : tab_(tab), ex_(ex), opt_(opt), out_(out), done_(done), C_(ex.channels()) {}

  /// Per-thread buffers.
  struct Scratch {
    std::vector<Eigen::Vector2d> cands;
    std::vector<int> known;  // neighbour slots already synthesized
    std::vector<float> value;
  };

  /// The best source for texel t given the texels synthesized so far.
  Eigen::Vector2d choose(std::size_t t, Scratch& s) const {
    const int per = tab_.per;
    const std::int32_t* nb = tab_.texel.data() + t * std::size_t(per);
    const Eigen::Vector2f* off = tab_.offset.data() + t * std::size_t(per);
    const double W = ex_.width(), H = ex_.height();
    const bool wrap = opt_.tileable_exemplar;
    auto inside = [&](Eigen::Vector2d& c) {
      if (wrap) {
        c.x() = std::fmod(c.x(), W);
        if (c.x() < 0) c.x() += W;
        c.y() = std::fmod(c.y(), H);
        if (c.y() < 0) c.y() += H;
        return true;
      }
      return c.x() >= 0 && c.y() >= 0 && c.x() <= W - 1 && c.y() <= H - 1;
    };
    s.value.resize(std::size_t(C_));
    s.known.clear();
    s.cands.clear();
    for (int j = 0; j < per; ++j) {
      if (nb[j] < 0 || std::size_t(nb[j]) == t || !done_[std::size_t(nb[j])]) continue;
      // Later passes: every neighbour is known; the texel's own source competes too.
      s.known.push_back(j);
      const std::size_t q = std::size_t(nb[j]);
      Eigen::Vector2d c(out_.source[q * 2] - off[j].x(), out_.source[q * 2 + 1] - off[j].y());
      if (!inside(c)) continue;
      bool seen = false;
      for (const auto& o : s.cands) seen = seen || (o - c).squaredNorm() < kSameCandidate2;
      if (!seen) s.cands.push_back(c);
    }
    if (done_[t]) s.cands.emplace_back(out_.source[t * 2], out_.source[t * 2 + 1]);
    if (s.cands.empty()) {
      IndexRng rng(opt_.seed, t);
      return Eigen::Vector2d(double(rng.below(std::uint64_t(W))), double(rng.below(std::uint64_t(H))));
    }
    Eigen::Vector2d best = s.cands[0];
    double best_d = std::numeric_limits<double>::infinity();
    for (const auto& c : s.cands) {
      double d = 0;
      for (std::size_t i = 0; i < s.known.size() && d < best_d; ++i) {
        const int j = s.known[i];
        // (The pixel read in place: copying it out was a third of this loop.)
        const float* px = nearest_pixel(ex_, c.x() + off[j].x(), c.y() + off[j].y(), wrap);
        const float* tq = out_.texels.data() + std::size_t(nb[j]) * std::size_t(C_);
        for (int ch = 0; ch < C_; ++ch) d += double(px[ch] - tq[ch]) * (px[ch] - tq[ch]);
      }
      if (d < best_d) {
        best_d = d;
        best = c;
      }
    }
    return best;
  }

  void set(std::size_t t, const Eigen::Vector2d& src) {
    nearest_exemplar(ex_, src.x(), src.y(), opt_.tileable_exemplar, out_.texels.data() + t * std::size_t(C_));
    out_.source[t * 2] = float(src.x());
    out_.source[t * 2 + 1] = float(src.y());
    done_[t] = 1;
  }

 private:
  const NeighbourTable& tab_;
  const Image& ex_;
  const SurfaceSynthesisOptions& opt_;
  SurfaceTexture& out_;
  std::vector<char>& done_;
  int C_;
};

/// Texels in waves by their position in the face map, (i mod 3) + 3 (j mod
/// 3), each in synthesis order: the passes after the first (every neighbour
/// known) search a wave's texels in parallel against the waves before it.
std::vector<std::vector<std::size_t>> texel_waves(const TexelGrid& g, const std::vector<std::size_t>& order) {
  std::vector<std::vector<std::size_t>> w(9);
  for (std::size_t t : order) {
    const int f = g.face_of[t], r = g.res[std::size_t(f)];
    const std::size_t k = t - g.offset[std::size_t(f)];
    w[std::size_t(int(k % std::size_t(r)) % 3 + 3 * (int(k / std::size_t(r)) % 3))].push_back(t);
  }
  return w;
}

}  // namespace

void run_coherent(const SubdivSurface& surface, const TexelFrames& fr, const VertexCharts* charts, const Image& ex,
                  const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx) {
  const int C = ex.channels();
  const std::size_t count = fr.grid.size();
  const NeighbourTable tab = neighbour_table(surface, fr, charts, out.sample_spacing, opt.coherent_radius, ctx);
  add_stats(out, tab.stats);
  const std::vector<std::size_t> order = synthesis_order(surface, fr.grid);
  std::vector<char> done(count, 0);
  out.texels.assign(count * std::size_t(C), 0.0f);
  out.source.assign(count * 2, 0.0f);
  CoherentSolver solver(tab, ex, opt, out, done);

  const int passes = std::max(1, opt.coherent_passes);
  StageProgress progress(ctx, "coherent synthesis", 0.0, 1.0, count * std::size_t(passes));
  // Pass 1, in synthesis order: each texel sees the ones before it (causal;
  // the same waves here left 1/9 of the texels random and every other texel
  // seeing few neighbours: flat-plane window distance 0.76 vs 0.29).
  CoherentSolver::Scratch scratch;
  for (std::size_t i = 0; i < count; ++i) {
    if ((i & 4095) == 0) progress.check();
    solver.set(order[i], solver.choose(order[i], scratch));
  }
  progress.advance(count);
  // Later passes: all neighbours known; in parallel waves (deterministic:
  // a wave reads only the waves before it and the previous pass). Flat-plane
  // window distance (5 seeds) 0.290 both with the waves and in synthesis order.
  const std::vector<std::vector<std::size_t>> waves = texel_waves(fr.grid, order);
  std::vector<Eigen::Vector2d> next;
  for (int pass = 1; pass < passes; ++pass)
    for (const std::vector<std::size_t>& wave : waves) {
      next.resize(wave.size());
      parallel_chunks(wave.size(), 1024, progress, [&](std::size_t b, std::size_t e) {
        CoherentSolver::Scratch s;
        for (std::size_t i = b; i < e; ++i) next[i] = solver.choose(wave[i], s);
      });
      for (std::size_t i = 0; i < wave.size(); ++i) solver.set(wave[i], next[i]);
    }
}

}  // namespace exsynth::surface
