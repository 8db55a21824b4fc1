#include "image/seam_cut.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "exsynth/parallel.hpp"
#include "image/max_flow.hpp"
#include "image/patch_refinement.hpp"

namespace exsynth::image {

SeamCutter::SeamCutter(const Image& colours, Coord lowest, Coord highest, const CoordinateSynthesisOptions& opt,
                       bool tileable, std::uint64_t seed)
    : colours_(colours), lo_(lowest), hi_(highest), opt_(opt), tileable_(tileable), seed_(seed) {}

float SeamCutter::pair_cost(Coord a, Coord b, int ex, int ey) const {
  const int W = colours_.width(), H = colours_.height(), C = colours_.channels();
  auto col = [&](int u, int v) { return colours_.data() + colours_.offset(std::clamp(u, 0, W - 1), std::clamp(v, 0, H - 1)); };
  auto norm = [&](const float* x, const float* y) {
    float d = 0.0f;
    for (int k = 0; k < C; ++k) d += (x[k] - y[k]) * (x[k] - y[k]);
    return std::sqrt(d);
  };
  // Source A = a's patch at both pixels (a, a + e), source B = b's (b - e, b);
  // with cut_radius r, over the (2r + 1)^2 pixels around each (the mean).
  const int r = opt_.cut_radius;
  float d = 0.0f;
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du)
      d += norm(col(a.u + du, a.v + dv), col(b.u - ex + du, b.v - ey + dv)) +
           norm(col(a.u + ex + du, a.v + ey + dv), col(b.u + du, b.v + dv));
  return r == 0 ? d : d / float((2 * r + 1) * (2 * r + 1));
}

long SeamCutter::index(const CoordImage& s, int x, int y) const {
  if (tileable_) {
    x = (x % s.width + s.width) % s.width;
    y = (y % s.height + s.height) % s.height;
  } else if (x < 0 || y < 0 || x >= s.width || y >= s.height) {
    return -1;
  }
  return long(y) * s.width + x;
}

double SeamCutter::energy(const CoordImage& s, const CoordImage& start) const {
  double e = 0.0;
  for (int y = 0; y < s.height; ++y) {
    double row = 0.0;
    for (int x = 0; x < s.width; ++x) {
      const Coord c = s.at(x, y);
      if (!(c == start.at(x, y))) row += opt_.cut_leave;
      for (auto [ex, ey] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const long q = index(s, x + ex, y + ey);
        if (q >= 0 && q != long(y) * s.width + x) row += pair_cost(c, s.s[std::size_t(q)], ex, ey);
      }
    }
    e += row;
  }
  return e;
}

int SeamCutter::edge(int size) const {
  // Tileable: at most size - 2, so a window and its border hold distinct pixels.
  return std::max(1, std::min(opt_.cut_window, tileable_ ? size - 2 : size));
}

std::vector<std::vector<SeamCutter::Window>> SeamCutter::windows(const CoordImage& s, int pass) const {
  // Starts and lengths along one axis, and each interval's class: 0, 1
  // alternating; a third class for the last interval of an odd count when
  // tileable (it touches the first across the wrap).
  auto axis = [&](int size) {
    const int w = edge(size), off = (pass % 2) * (w / 2);
    std::vector<std::pair<int, int>> iv;  // (start, length)
    if (tileable_) {
      const int n = (size + w - 1) / w;
      for (int j = 0; j < n; ++j) iv.push_back({off + j * w, std::min(w, size - j * w)});
    } else {
      std::vector<int> b{0};
      for (int x = off; x < size; x += w)
        if (x > 0) b.push_back(x);
      b.push_back(size);
      for (std::size_t j = 0; j + 1 < b.size(); ++j) iv.push_back({b[j], b[j + 1] - b[j]});
    }
    std::vector<int> cls(iv.size());
    for (std::size_t j = 0; j < iv.size(); ++j) cls[j] = int(j % 2);
    if (tileable_ && iv.size() % 2 == 1 && iv.size() > 1) cls.back() = 2;
    return std::pair{iv, cls};
  };
  const auto [ix, cx] = axis(s.width);
  const auto [iy, cy] = axis(s.height);
  std::vector<std::vector<Window>> out(9);
  for (std::size_t j = 0; j < iy.size(); ++j)
    for (std::size_t i = 0; i < ix.size(); ++i)
      out[std::size_t(cy[j] * 3 + cx[i])].push_back({ix[i].first, iy[j].first, ix[i].second, iy[j].second});
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& v) { return v.empty(); }), out.end());
  return out;
}

std::vector<Coord> SeamCutter::sources(const CoordImage& s, const Window& win) const {
  std::vector<std::pair<Coord, int>> count;
  for (int y = win.y0 - 1; y <= win.y0 + win.h; ++y)
    for (int x = win.x0 - 1; x <= win.x0 + win.w; ++x) {
      const long p = index(s, x, y);
      if (p < 0) continue;
      const Coord c = s.s[std::size_t(p)], off{c.u - x, c.v - y};
      auto at = std::find_if(count.begin(), count.end(), [&](const auto& e) { return e.first == off; });
      if (at == count.end()) count.push_back({off, 1});
      else ++at->second;
    }
  std::sort(count.begin(), count.end(), [](const auto& a, const auto& b) {
    if (a.second != b.second) return a.second > b.second;
    return a.first.v != b.first.v ? a.first.v < b.first.v : a.first.u < b.first.u;
  });
  std::vector<Coord> out;
  for (std::size_t k = 0; k < count.size() && int(k) < opt_.cut_labels; ++k) out.push_back(count[k].first);
  return out;
}

SeamCutter::Matches SeamCutter::matches(const CoordImage& s, StageProgress& progress) const {
  Matches m;
  if (!opt_.cut_matches) return m;
  const PatchRefiner refiner(colours_, lo_, hi_, opt_, tileable_, seed_);
  m.n = refiner.patch(s);
  m.xs = refiner.corners(s.width, m.n);
  m.ys = refiner.corners(s.height, m.n);
  refiner.match(s, m.nn, 0, progress);
  return m;
}

std::vector<std::pair<Coord, SeamCutter::Window>> SeamCutter::match_sources(const CoordImage& s, const Matches& m,
                                                                           const Window& win,
                                                                           const std::vector<Coord>& have) const {
  std::vector<std::pair<Coord, Window>> out;
  if (m.nn.empty()) return out;
  // A corner's position unwrapped into the window's range (tileable), or -1 when outside it.
  auto local = [&](int c, int x0, int w, int size) {
    if (tileable_) c = x0 + ((c - x0) % size + size) % size;
    return c >= x0 && c < x0 + w ? c : -1;
  };
  for (std::size_t gy = 0; gy < m.ys.size(); ++gy) {
    const int y = local(m.ys[gy], win.y0, win.h, s.height);
    if (y < 0) continue;
    for (std::size_t gx = 0; gx < m.xs.size(); ++gx) {
      const int x = local(m.xs[gx], win.x0, win.w, s.width);
      if (x < 0) continue;
      const Coord e = m.nn[gy * m.xs.size() + gx], off{e.u - x, e.v - y};
      if (std::find(have.begin(), have.end(), off) == have.end() &&
          std::find_if(out.begin(), out.end(), [&](const auto& o) { return o.first == off; }) == out.end())
        out.push_back({off, Window{x, y, m.n, m.n}});
    }
  }
  return out;
}

double SeamCutter::expand(CoordImage& s, const CoordImage& start, const Window& win, Coord alpha,
                          const Window* seed) const {
  // The padded window (one-pixel border), row-major; positions unwrapped.
  const int pw = win.w + 2, ph = win.h + 2;
  const std::size_t n = std::size_t(pw) * ph;
  std::vector<long> pix(n);
  std::vector<Coord> cur(n), cand(n);
  std::vector<int> node(n, -1);
  std::vector<double> e0, e1;
  std::vector<unsigned char> near(n, 1);
  for (int j = 0; j < ph; ++j)
    for (int i = 0; i < pw; ++i) {
      const std::size_t k = std::size_t(j) * pw + i;
      pix[k] = index(s, win.x0 - 1 + i, win.y0 - 1 + j);
      if (pix[k] >= 0) cur[k] = cand[k] = s.s[std::size_t(pix[k])];
    }
  if (opt_.cut_reach > 0) {
    // Only pixels within cut_reach (Chebyshev) of a pixel already on alpha
    // may take it: a region grows by at most cut_reach per move.
    std::vector<unsigned char> on(n, 0), rows(n, 0);
    for (int j = 0; j < ph; ++j)
      for (int i = 0; i < pw; ++i) {
        const std::size_t k = std::size_t(j) * pw + i;
        const int x = win.x0 - 1 + i, y = win.y0 - 1 + j;
        on[k] = pix[k] >= 0 && (cur[k] == Coord{x + alpha.u, y + alpha.v} ||
                                (seed && x >= seed->x0 && y >= seed->y0 && x < seed->x0 + seed->w && y < seed->y0 + seed->h));
      }
    const int r = opt_.cut_reach;
    for (int j = 0; j < ph; ++j)
      for (int i = 0; i < pw; ++i) {
        unsigned char a = 0;
        for (int t = std::max(0, i - r); t <= std::min(pw - 1, i + r) && !a; ++t) a = on[std::size_t(j) * pw + t];
        rows[std::size_t(j) * pw + i] = a;
      }
    for (int j = 0; j < ph; ++j)
      for (int i = 0; i < pw; ++i) {
        unsigned char a = 0;
        for (int t = std::max(0, j - r); t <= std::min(ph - 1, j + r) && !a; ++t) a = rows[std::size_t(t) * pw + i];
        near[std::size_t(j) * pw + i] = a;
      }
  }
  int nodes = 0;
  for (int j = 0; j < ph; ++j)
    for (int i = 0; i < pw; ++i) {
      const std::size_t k = std::size_t(j) * pw + i;
      if (pix[k] < 0 || !near[k]) continue;
      const int x = win.x0 - 1 + i, y = win.y0 - 1 + j;
      const bool inside = i >= 1 && j >= 1 && i <= win.w && j <= win.h;
      const Coord c{x + alpha.u, y + alpha.v};
      if (inside && valid(c) && !(c == cur[k])) {
        cand[k] = c;
        node[k] = nodes++;
      }
    }
  if (nodes == 0) return 0.0;
  e0.assign(std::size_t(nodes), 0.0);
  e1.assign(std::size_t(nodes), 0.0);
  MaxFlow flow(nodes);
  auto leave = [&](std::size_t k, Coord c) { return c == start.s[std::size_t(pix[k])] ? 0.0 : opt_.cut_leave; };
  for (std::size_t k = 0; k < n; ++k)
    if (node[k] >= 0) {
      e0[std::size_t(node[k])] += leave(k, cur[k]);
      e1[std::size_t(node[k])] += leave(k, cand[k]);
    }
  // Every 4-neighbour pair (k, m = k + (ex, ey)) of the padded window whose
  // pixels both exist, as f(k, m, ex, ey).
  auto for_each_pair = [&](auto&& f) {
    for (int j = 0; j < ph; ++j)
      for (int i = 0; i < pw; ++i)
        for (auto [ex, ey] : {std::pair{1, 0}, std::pair{0, 1}}) {
          if (i + ex >= pw || j + ey >= ph) continue;
          const std::size_t k = std::size_t(j) * pw + i, m = std::size_t(j + ey) * pw + std::size_t(i + ex);
          if (pix[k] >= 0 && pix[m] >= 0) f(k, m, ex, ey);
        }
  };
  // Pairs with at least one node; x = 1 means "takes alpha".
  for_each_pair([&](std::size_t k, std::size_t m, int ex, int ey) {
    if (node[k] < 0 && node[m] < 0) return;
    const double A = pair_cost(cur[k], cur[m], ex, ey);
    if (node[k] >= 0 && node[m] >= 0) {
      const double B = pair_cost(cur[k], cand[m], ex, ey), C = pair_cost(cand[k], cur[m], ex, ey),
                   D = pair_cost(cand[k], cand[m], ex, ey);
      // A + (C - A) x_k + (D - C) x_m + (B + C - A - D) (1 - x_k) x_m; the
      // last coefficient is >= 0 (the seam cost is a metric) up to rounding.
      e1[std::size_t(node[k])] += C - A;
      e1[std::size_t(node[m])] += D - C;
      flow.add_edge(node[k], node[m], std::max(B + C - A - D, 0.0), 0.0);
    } else if (node[k] >= 0) {
      e1[std::size_t(node[k])] += pair_cost(cand[k], cur[m], ex, ey) - A;
    } else {
      e1[std::size_t(node[m])] += pair_cost(cur[k], cand[m], ex, ey) - A;
    }
  });
  // Unary terms: x = 1 costs e1 (cut source -> i when i is on the sink side), x = 0 costs e0.
  for (int v = 0; v < nodes; ++v) {
    const double d = e1[std::size_t(v)] - e0[std::size_t(v)];
    if (d > 0) flow.add_terminal(v, d, 0.0);
    else if (d < 0) flow.add_terminal(v, 0.0, -d);
  }
  flow.solve();
  // The move's change of E, evaluated directly on the pairs and pixels it touches.
  std::vector<Coord> next = cur;
  bool moved = false;
  for (std::size_t k = 0; k < n; ++k)
    if (node[k] >= 0 && !flow.source_side(node[k])) next[k] = cand[k], moved = true;
  if (!moved) return 0.0;
  double delta = 0.0;
  for (std::size_t k = 0; k < n; ++k)
    if (node[k] >= 0) delta += leave(k, next[k]) - leave(k, cur[k]);
  for_each_pair([&](std::size_t k, std::size_t m, int ex, int ey) {
    if (next[k] == cur[k] && next[m] == cur[m]) return;
    delta += double(pair_cost(next[k], next[m], ex, ey)) - double(pair_cost(cur[k], cur[m], ex, ey));
  });
  if (!(delta < 0.0)) return 0.0;
  for (std::size_t k = 0; k < n; ++k)
    if (node[k] >= 0) s.s[std::size_t(pix[k])] = next[k];
  return delta;
}

void SeamCutter::run(CoordImage& s, ExecContext* ctx, double lo, double hi, std::vector<double>* energy) const {
  if (opt_.cut_passes <= 0 || s.s.empty()) return;
  // Tileable images under 3 pixels across: a window would hold its own border.
  if (tileable_ && (s.width < 3 || s.height < 3)) return;
  std::size_t match_rows = 0;  // the match advances once per row of patch corners
  if (opt_.cut_matches) {
    const PatchRefiner refiner(colours_, lo_, hi_, opt_, tileable_, seed_);
    match_rows = refiner.corners(s.height, refiner.patch(s)).size();
  }
  std::size_t total = 0;
  for (int pass = 0; pass < opt_.cut_passes; ++pass) {
    for (const auto& cls : windows(s, pass)) total += cls.size();
    total += match_rows;
  }
  StageProgress progress(ctx, "image: seam cuts", lo, hi, total);
  const CoordImage start = s;
  for (int pass = 0; pass < opt_.cut_passes; ++pass) {
    const Matches m = matches(s, progress);
    for (const auto& cls : windows(s, pass)) {
      // Windows of one class never touch: each reads its own pixels and a
      // border no other window of the class writes.
      parallel_chunks(cls.size(), 1, progress, [&](std::size_t begin, std::size_t end) {
        for (std::size_t w = begin; w < end; ++w) {
          const std::vector<Coord> alphas = sources(s, cls[w]);
          for (const Coord& alpha : alphas) expand(s, start, cls[w], alpha);
          for (const auto& [alpha, footprint] : match_sources(s, m, cls[w], alphas))
            expand(s, start, cls[w], alpha, &footprint);
        }
      });
    }
    if (energy) energy->push_back(this->energy(s, start) / double(s.s.size()));
  }
}

}  // namespace exsynth::image
