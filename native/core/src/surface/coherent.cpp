// Coherent synthesis on the surface (Ying et al. 2001, §5; Ashikhmin 2001):
// every texel keeps the float exemplar coordinate it was copied from;
// candidates are the sources of already synthesized texels within the
// neighbourhood radius, displaced by their tangent-plane offset.
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

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

struct Neighbourhood {
  std::vector<SurfacePoint> points;
  std::vector<char> valid;
  std::vector<std::size_t> texel;
  std::vector<Eigen::Vector2d> offset;  // tangent-plane offset of the texel centre, in exemplar pixels
};

/// Samples around texel t; each sample snaps to the texel it lands in, and
/// its offset is corrected by the (first-order) vector from the landing
/// point to that texel's centre, projected on (v1, -v2).
void gather(const SubdivSurface& surface, const TexelFrames& fr, std::size_t t, double h, int r, Neighbourhood& nb) {
  const int n = (2 * r + 1) * (2 * r + 1);
  bool valid[128];
  sample_points(surface, fr, t, h, r, nb.points.data(), valid);
  const Eigen::Vector3d a = fr.t1[t].cast<double>(), b = fr.t2[t].cast<double>();
  for (int k = 0; k < n; ++k) {
    nb.valid[std::size_t(k)] = valid[k];
    if (!valid[k]) continue;
    const SurfacePoint& p = nb.points[std::size_t(k)];
    const std::size_t q = fr.grid.texel(p);
    const SurfacePoint c = fr.grid.centre(q);
    const Eigen::Vector3d to_centre = fr.du[q].cast<double>() * (c.u - p.u) + fr.dv[q].cast<double>() * (c.v - p.v);
    const int l = k % (2 * r + 1) - r, m = k / (2 * r + 1) - r;
    nb.texel[std::size_t(k)] = q;
    nb.offset[std::size_t(k)] = Eigen::Vector2d(l + to_centre.dot(a) / h, m - to_centre.dot(b) / h);
  }
}

}  // namespace

void run_coherent(const SubdivSurface& surface, const TexelFrames& fr, const Image& ex,
                  const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx) {
  const int r = opt.coherent_radius;
  const int n = (2 * r + 1) * (2 * r + 1);
  const int C = ex.channels();
  const double h = out.sample_spacing;
  const bool wrap = opt.tileable_exemplar;
  const std::size_t count = fr.grid.size();
  const std::vector<std::size_t> order = synthesis_order(surface, fr.grid);
  std::vector<char> done(count, 0);
  out.texels.assign(count * std::size_t(C), 0.0f);
  out.source.assign(count * 2, 0.0f);

  Neighbourhood nb;
  nb.points.resize(std::size_t(n));
  nb.valid.resize(std::size_t(n));
  nb.texel.resize(std::size_t(n));
  nb.offset.resize(std::size_t(n));
  std::vector<Eigen::Vector2d> cands;
  std::vector<float> value(static_cast<std::size_t>(C));
  const double W = ex.width(), H = ex.height();
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

  StageProgress progress(ctx, "coherent synthesis", 0.0, 1.0, count);
  for (std::size_t k = 0; k < count; ++k) {
    if ((k & 2047) == 0) {
      progress.check();
      if (k) progress.advance(2048);
    }
    const std::size_t t = order[k];
    gather(surface, fr, t, h, r, nb);
    cands.clear();
    for (int s = 0; s < n; ++s) {
      if (!nb.valid[std::size_t(s)] || !done[nb.texel[std::size_t(s)]]) continue;
      const std::size_t q = nb.texel[std::size_t(s)];
      Eigen::Vector2d c(out.source[q * 2] - nb.offset[std::size_t(s)].x(),
                        out.source[q * 2 + 1] - nb.offset[std::size_t(s)].y());
      if (!inside(c)) continue;
      bool seen = false;
      for (const auto& o : cands) seen = seen || (o - c).squaredNorm() < 0.0625;
      if (!seen) cands.push_back(c);
    }
    Eigen::Vector2d best;
    if (cands.empty()) {
      IndexRng rng(opt.seed, t);
      best = Eigen::Vector2d(rng.uniform() * (W - 1), rng.uniform() * (H - 1));
    } else {
      double best_d = std::numeric_limits<double>::infinity();
      for (const auto& c : cands) {
        double d = 0;
        for (int s = 0; s < n && d < best_d; ++s) {
          if (!nb.valid[std::size_t(s)]) continue;
          const std::size_t q = nb.texel[std::size_t(s)];
          if (!done[q] || q == t) continue;
          sample_exemplar(ex, c.x() + nb.offset[std::size_t(s)].x(), c.y() + nb.offset[std::size_t(s)].y(), wrap,
                          value.data());
          const float* tq = out.texels.data() + q * std::size_t(C);
          for (int ch = 0; ch < C; ++ch) d += double(value[std::size_t(ch)] - tq[ch]) * (value[std::size_t(ch)] - tq[ch]);
        }
        if (d < best_d) {
          best_d = d;
          best = c;
        }
      }
    }
    sample_exemplar(ex, best.x(), best.y(), wrap, out.texels.data() + t * std::size_t(C));
    out.source[t * 2] = float(best.x());
    out.source[t * 2 + 1] = float(best.y());
    done[t] = 1;
  }
}

}  // namespace exsynth::surface
