#include "image/coordinate_synthesis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/rng.hpp"
#include "image/patch_refinement.hpp"
#include "image/seam_cut.hpp"
#include "search/kd_tree.hpp"

namespace exsynth::image {
namespace {

constexpr int kMaxCoherenceK = 16;
constexpr int kMaxCandidates = 1 + 9 * kMaxCoherenceK;
// Random streams of IndexRng (seed, pixel, stream): one per use and level.
constexpr std::uint64_t kInitStream = 1, kJitterStream = 100;
// Sub-pass order of the 2 x 2 interleaving (LH05 sec. 3.3): diagonal first.
constexpr int kSubPass[4][2] = {{0, 0}, {1, 1}, {1, 0}, {0, 1}};

/// One a trous step of the Gaussian stack: the 5-tap binomial kernel with
/// taps `h` apart, separable, clamped at the edges (no decimation, so every
/// exemplar position keeps its own vector at every level).
Image blur_a_trous(const Image& a, int h) {
  static constexpr float w[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
  const int W = a.width(), H = a.height(), C = a.channels();
  Image tmp(W, H, C), out(W, H, C);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      float* o = tmp.data() + tmp.offset(x, y);
      for (int t = 0; t < 5; ++t) {
        const float* s = a.data() + a.offset(std::clamp(x + (t - 2) * h, 0, W - 1), y);
        for (int c = 0; c < C; ++c) o[c] += w[t] * s[c];
      }
    }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      float* o = out.data() + out.offset(x, y);
      for (int t = 0; t < 5; ++t) {
        const float* s = tmp.data() + tmp.offset(x, std::clamp(y + (t - 2) * h, 0, H - 1));
        for (int c = 0; c < C; ++c) o[c] += w[t] * s[c];
      }
    }
  return out;
}

void check_coordinate_options(const CoordinateSynthesisOptions& o) {
  if (!(o.jitter >= 0 && o.jitter <= 4))
    throw InvalidInput("jitter must be between 0 and 4 (times the level spacing), got " + std::to_string(o.jitter));
  auto pow2 = [](int v) { return v >= 1 && (v & (v - 1)) == 0; };
  if (!pow2(o.jitter_from) || o.jitter_from > 1024)
    throw InvalidInput("jitter_from must be a power of two from 1 to 1024 (the finest jittered spacing), got " +
                       std::to_string(o.jitter_from));
  if (o.corrections < 0 || o.corrections > 16)
    throw InvalidInput("corrections must be between 0 and 16 passes per level, got " + std::to_string(o.corrections));
  if (o.coherence_k < 1 || o.coherence_k > kMaxCoherenceK)
    throw InvalidInput("coherence_k must be between 1 and " + std::to_string(kMaxCoherenceK) +
                       " for the coordinate method (1 = coherent candidates only), got " + std::to_string(o.coherence_k));
  if (!(o.coherence >= 0 && o.coherence <= 100))
    throw InvalidInput("coherence must be between 0 and 100 (0 = no bias to continuing patches), got " +
                       std::to_string(o.coherence));
  if (o.wide_below < 0 || o.wide_below > 1024)
    throw InvalidInput("wide_below must be between 0 and 1024 pixels of spacing, got " + std::to_string(o.wide_below));
  if (o.appearance_window < 1 || o.appearance_window > 15 || o.appearance_window % 2 == 0)
    throw InvalidInput("appearance_window must be odd, from 1 to 15 pixels, got " + std::to_string(o.appearance_window));
  if (o.appearance_dims < 1 || o.appearance_dims > 64)
    throw InvalidInput("appearance_dims must be between 1 and 64, got " + std::to_string(o.appearance_dims));
  if (o.refine_passes < 0 || o.refine_passes > 16)
    throw InvalidInput("refine_passes must be between 0 and 16 (0 = no patch refinement), got " +
                       std::to_string(o.refine_passes));
  if (o.refine_patch < 2 || o.refine_patch > 32)
    throw InvalidInput("refine_patch must be between 2 and 32 pixels, got " + std::to_string(o.refine_patch));
  if (o.refine_stride < 1 || o.refine_stride > o.refine_patch)
    throw InvalidInput("refine_stride must be between 1 and refine_patch (" + std::to_string(o.refine_patch) +
                       ") pixels, got " + std::to_string(o.refine_stride));
  if (o.refine_random < 0 || o.refine_random > 16)
    throw InvalidInput("refine_random must be between 0 and 16 probes per radius, got " +
                       std::to_string(o.refine_random));
  if (o.cut_passes < 0 || o.cut_passes > 16)
    throw InvalidInput("cut_passes must be between 0 and 16 (0 = no seam cuts), got " + std::to_string(o.cut_passes));
  if (o.cut_window < 4 || o.cut_window > 256)
    throw InvalidInput("cut_window must be between 4 and 256 pixels, got " + std::to_string(o.cut_window));
  if (o.cut_labels < 1 || o.cut_labels > 256)
    throw InvalidInput("cut_labels must be between 1 and 256 sources per window, got " + std::to_string(o.cut_labels));
  if (!(o.cut_leave >= 0 && o.cut_leave <= 1e6))
    throw InvalidInput("cut_leave must be between 0 and 1e6 (colour distance per pixel), got " +
                       std::to_string(o.cut_leave));
  if (o.cut_reach < 0 || o.cut_reach > 256)
    throw InvalidInput("cut_reach must be between 0 and 256 pixels (0 = the whole window), got " +
                       std::to_string(o.cut_reach));
  if (o.cut_radius < 0 || o.cut_radius > 4)
    throw InvalidInput("cut_radius must be between 0 and 4 pixels, got " + std::to_string(o.cut_radius));
  if (o.coarsest_spacing != 0 && (!pow2(o.coarsest_spacing) || o.coarsest_spacing > 1024))
    throw InvalidInput("coarsest_spacing must be 0 (automatic) or a power of two from 1 to 1024, got " +
                       std::to_string(o.coarsest_spacing));
}

void check_finite(const Image& img) {
  if (img.width() < 1 || img.height() < 1 || img.channels() < 1)
    throw InvalidInput("the exemplar is empty; give an image with at least one pixel and one channel");
  for (std::size_t i = 0; i < img.values().size(); ++i)
    if (!std::isfinite(img.values()[i])) {
      const std::size_t p = i / std::size_t(img.channels());
      throw InvalidInput("the exemplar has a non-finite value (NaN or Inf) at pixel (" +
                         std::to_string(p % std::size_t(img.width())) + ", " +
                         std::to_string(p / std::size_t(img.width())) + "); fix or clamp the image first");
    }
}

/// The exemplar scaled to magnitudes near 1 for the appearance analysis
/// (squared float distances overflow near 1e18); colours come from the
/// unscaled exemplar.
Image analysis_copy(const Image& img) {
  float m = 0.0f;
  for (float v : img.values()) m = std::max(m, std::abs(v));
  Image out = img;
  if (m > 0.0f && (m < 1.0f / 16 || m > 16.0f))
    for (float& v : out.values()) v /= m;
  return out;
}

}  // namespace

CoordinateSolver::CoordinateSolver(const Image& exemplar, const CoordinateSynthesisOptions& opt, bool tileable,
                                   std::uint64_t seed, ExecContext* ctx, double lo, double hi)
    : exemplar_(exemplar), opt_(opt), tileable_(tileable), seed_(seed) {
  check_coordinate_options(opt);
  check_finite(exemplar);
  const int W = exemplar.width(), H = exemplar.height(), C = exemplar.channels();
  // A window larger than the exemplar shrinks to the largest odd size that fits.
  int n = std::min(opt.appearance_window, std::min(W, H));
  if (n % 2 == 0) --n;
  scaled_ = analysis_copy(exemplar);
  const Image& scaled = scaled_;
  std::vector<float> ch_lo(std::size_t(C), 0.0f), ch_hi(std::size_t(C), 1.0f);
  // pca_variance 1: keep appearance_dims components (LH06 keep 8 of 5 x 5 x 3).
  // The index's own k-coherence sets (8 one-pixel shifts re-ranked per
  // tree hit) took ~0.5 s CPU at 128^2 under load, 4x the whole synthesis;
  // build_similar's are coarser and ~10x cheaper.
  index_ = std::make_unique<solid::ExemplarIndex>(scaled, n, 1.0, opt.appearance_dims, 0, 2, ch_lo, ch_hi, ctx,
                                                  "image: appearance space", lo, lo + 0.5 * (hi - lo));
  lo_u_ = index_->lo();
  lo_v_ = index_->lo();
  hi_u_ = lo_u_ + (W - n);
  hi_v_ = lo_v_ + (H - n);

  build_similar(ctx, lo + 0.5 * (hi - lo), lo + 0.8 * (hi - lo));
  StageProgress progress(ctx, "image: appearance stack", lo + 0.8 * (hi - lo), hi, 1);
  const auto& coeffs = index_->coefficients();
  const int D = int(coeffs.cols());
  Image a(W, H, D);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float* row = coeffs.row(index_->clamped_index(x, y)).data();
      std::copy(row, row + D, a.data() + a.offset(x, y));
    }
  int coarsest = opt.coarsest_spacing;
  if (coarsest == 0) {
    coarsest = 1;
    while (coarsest * 2 <= std::min(hi_u_ - lo_u_ + 1, hi_v_ - lo_v_ + 1) / 3) coarsest *= 2;
  }
  stack_.push_back(std::move(a));
  stack_spacing_.push_back(1);
  for (int h = 1; h < coarsest; h *= 2) {
    progress.check();
    stack_.push_back(blur_a_trous(stack_.back(), h));
    stack_spacing_.push_back(h * 2);
  }
  progress.advance();
}

// k-coherence sets: for each valid position, the k - 1 positions on the
// even grid whose appearance vectors are nearest (nanoflann, eps 1) among
// those whose appearance windows overlap it by at most half (near-copies of
// itself would add no choice).
void CoordinateSolver::build_similar(ExecContext* ctx, double lo, double hi) {
  const int k = opt_.coherence_k - 1;
  if (k <= 0) return;
  const auto& coeffs = index_->coefficients();
  const int D = int(coeffs.cols()), vw = hi_u_ - lo_u_ + 1, vh = hi_v_ - lo_v_ + 1;
  std::vector<Coord> grid;
  for (int v = lo_v_; v <= hi_v_; v += 2)
    for (int u = lo_u_; u <= hi_u_; u += 2) grid.push_back({u, v});
  search::RowMatrixXf points(Eigen::Index(grid.size()), D);
  for (std::size_t g = 0; g < grid.size(); ++g) points.row(Eigen::Index(g)) = coeffs.row(index_->index_of(grid[g].u, grid[g].v));
  const search::KdTree tree(points);
  const int half = std::max(index_->n() / 2, 1);
  const std::size_t want = std::min(grid.size(), std::size_t(k + 4 * half * half / 4 + 4));
  similar_.assign(std::size_t(vw) * vh * k, Coord{lo_u_, lo_v_});
  StageProgress progress(ctx, "image: k-coherence sets", lo, hi, std::size_t(vh));
  parallel_chunks(std::size_t(vh), 4, progress, [&](std::size_t begin, std::size_t end) {
    std::vector<Eigen::Index> idx(want);
    std::vector<float> d2(want);
    for (std::size_t r = begin; r < end; ++r)
      for (int a = 0; a < vw; ++a) {
        const Coord c{lo_u_ + a, lo_v_ + int(r)};
        const std::size_t got = tree.knn(coeffs.row(index_->index_of(c.u, c.v)).data(), want, idx.data(), d2.data(), 1.0f);
        Coord* out = similar_.data() + (r * std::size_t(vw) + std::size_t(a)) * std::size_t(k);
        int taken = 0;
        for (std::size_t t = 0; t < got && taken < k; ++t) {
          const Coord g = grid[std::size_t(idx[t])];
          if (std::abs(g.u - c.u) < half && std::abs(g.v - c.v) < half) continue;
          out[taken++] = g;
        }
        for (; taken < k; ++taken) out[taken] = c;  // tiny exemplars: no other window
      }
  });
}

Coord CoordinateSolver::clamp(Coord c) const {
  // Wrapped into the valid range, not clamped: clamping pinned every child
  // and jittered coordinate past the edge to one row or column, a smear
  // (sharpness 0.80-0.89 at 64^2 exemplars); wrapping makes a seam that the
  // corrections then repair or keep.
  const int nu = hi_u_ - lo_u_ + 1, nv = hi_v_ - lo_v_ + 1;
  return {lo_u_ + ((c.u - lo_u_) % nu + nu) % nu, lo_v_ + ((c.v - lo_v_) % nv + nv) % nv};
}

bool CoordinateSolver::valid(Coord c) const {
  return c.u >= lo_u_ && c.u <= hi_u_ && c.v >= lo_v_ && c.v <= hi_v_;
}

bool CoordinateSolver::neighbour(const CoordImage& s, int x, int y, int dx, int dy, int& nx, int& ny) const {
  nx = x + dx;
  ny = y + dy;
  if (tileable_) {
    nx = (nx % s.width + s.width) % s.width;
    ny = (ny % s.height + s.height) % s.height;
    return true;
  }
  return nx >= 0 && ny >= 0 && nx < s.width && ny < s.height;
}

CoordImage CoordinateSolver::initial(int width, int height) const {
  CoordImage s{width, height, std::vector<Coord>(std::size_t(width) * height)};
  const std::uint64_t nu = std::uint64_t(hi_u_ - lo_u_ + 1), nv = std::uint64_t(hi_v_ - lo_v_ + 1);
  for (std::size_t p = 0; p < s.s.size(); ++p) {
    IndexRng rng(seed_, p, kInitStream);
    s.s[p] = {lo_u_ + int(rng.below(nu)), lo_v_ + int(rng.below(nv))};
  }
  return s;
}

CoordImage CoordinateSolver::upsample(const CoordImage& parent, int width, int height, int level) const {
  const int h = spacing(level);
  CoordImage s{width, height, std::vector<Coord>(std::size_t(width) * height)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Coord p = parent.at(std::min(x / 2, parent.width - 1), std::min(y / 2, parent.height - 1));
      s.at(x, y) = clamp({p.u + h * (x & 1), p.v + h * (y & 1)});
    }
  return s;
}

void CoordinateSolver::jitter(CoordImage& s, int level) const {
  const int h = spacing(level);
  if (h < opt_.jitter_from || opt_.jitter <= 0) return;
  const double amp = h * opt_.jitter;
  for (std::size_t p = 0; p < s.s.size(); ++p) {
    IndexRng rng(seed_, p, kJitterStream + std::uint64_t(level));
    const int du = int(std::floor(amp * (2.0 * rng.uniform() - 1.0) + 0.5));
    const int dv = int(std::floor(amp * (2.0 * rng.uniform() - 1.0) + 0.5));
    s.s[p] = clamp({s.s[p].u + du, s.s[p].v + dv});
  }
}

std::vector<Coord> CoordinateSolver::candidates(const CoordImage& s, int x, int y, int level) const {
  std::vector<Coord> out{s.at(x, y)};
  if (opt_.exhaustive) {
    for (int v = lo_v_; v <= hi_v_; ++v)
      for (int u = lo_u_; u <= hi_u_; ++u) out.push_back({u, v});
    return out;
  }
  const int h = spacing(level);
  auto add = [&](Coord c) {
    if (!valid(c)) return;  // a patch that would run off the exemplar is no candidate
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  };
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      int nx, ny;
      if ((dx == 0 && dy == 0) || !neighbour(s, x, y, dx, dy, nx, ny)) continue;
      const Coord q = s.at(nx, ny);
      add({q.u - h * dx, q.v - h * dy});
      const Coord* sim = similar(q);
      for (int i = 0; i + 1 < opt_.coherence_k; ++i) add({sim[i].u - h * dx, sim[i].v - h * dy});
    }
  return out;
}

float CoordinateSolver::distance(const CoordImage& s, int x, int y, Coord c, int level) const {
  const Image& a = appearance(level);
  const int h = spacing(level), D = a.channels(), r = h <= opt_.wide_below ? 2 : 1;
  float d = 0.0f;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      int nx, ny;
      if (!neighbour(s, x, y, dx, dy, nx, ny)) continue;
      const Coord q = s.at(nx, ny);
      const float* syn = a.data() + a.offset(q.u, q.v);
      const float* ex = a.data() + a.offset(std::clamp(c.u + h * dx, 0, a.width() - 1),
                                            std::clamp(c.v + h * dy, 0, a.height() - 1));
      for (int k = 0; k < D; ++k) d += (ex[k] - syn[k]) * (ex[k] - syn[k]);
    }
  return d;
}

void CoordinateSolver::correct_pixel(const CoordImage& prev, CoordImage& out, int x, int y, int level,
                                     double& sum) const {
  const Image& a = appearance(level);
  const int h = spacing(level), D = a.channels(), W = a.width(), H = a.height();
  // The pixel's neighbourhood, gathered once: appearance at the neighbours' coordinates.
  const int r = h <= opt_.wide_below ? 2 : 1;
  float nb[25 * 64];
  int off[25][2], m = 0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      int nx, ny;
      if (!neighbour(prev, x, y, dx, dy, nx, ny)) continue;
      const Coord q = prev.at(nx, ny);
      std::copy_n(a.data() + a.offset(q.u, q.v), D, nb + m * D);
      off[m][0] = h * dx;
      off[m][1] = h * dy;
      ++m;
    }
  // D = 8 (the default appearance_dims) compiles to whole 8-float blocks.
  auto dist = [&](Coord c, float bound) {
    float d = 0.0f;
    for (int i = 0; i < m && d < bound; ++i) {
      const float* ex = a.data() + a.offset(std::clamp(c.u + off[i][0], 0, W - 1), std::clamp(c.v + off[i][1], 0, H - 1));
      const float* syn = nb + i * D;
      if (D == 8) {
        float e = 0.0f;
        for (int k = 0; k < 8; ++k) e += (ex[k] - syn[k]) * (ex[k] - syn[k]);
        d += e;
      } else {
        for (int k = 0; k < D; ++k) d += (ex[k] - syn[k]) * (ex[k] - syn[k]);
      }
    }
    return d;
  };
  Coord best = prev.at(x, y);
  bool own_coherent = false;
  for (int dy = -1; dy <= 1 && !own_coherent; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      int nx, ny;
      if ((dx == 0 && dy == 0) || !neighbour(prev, x, y, dx, dy, nx, ny)) continue;
      const Coord q = prev.at(nx, ny);
      if (Coord{q.u - h * dx, q.v - h * dy} == best) {
        own_coherent = true;
        break;
      }
    }
  float best_d = dist(best, std::numeric_limits<float>::infinity()) *
                 (own_coherent ? 1.0f / (1.0f + float(opt_.coherence)) : 1.0f);
  // Coherence bias (Ashikhmin 2001, Hertzmann et al. 2001's kappa): a
  // candidate that continues a neighbour's patch wins unless another is
  // better by the factor (1 + coherence).
  const float favour = 1.0f / (1.0f + float(opt_.coherence));
  // Neighbours in one patch propose the same candidate: each is scored once
  // (the first proposal decides whether it counts as coherent).
  Coord tried[kMaxCandidates];
  int n_tried = 0;
  tried[n_tried++] = best;
  auto consider = [&](Coord c, bool coherent) {
    if (!valid(c)) return;
    if (!opt_.exhaustive) {
      for (int i = 0; i < n_tried; ++i)
        if (tried[i] == c) return;
      tried[n_tried++] = c;
    }
    const float scale = coherent ? favour : 1.0f;
    const float d = dist(c, best_d / scale) * scale;
    if (d < best_d) best_d = d, best = c;
  };
  if (opt_.exhaustive) {
    for (int v = lo_v_; v <= hi_v_; ++v)
      for (int u = lo_u_; u <= hi_u_; ++u) consider({u, v}, false);
  } else {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int nx, ny;
        if ((dx == 0 && dy == 0) || !neighbour(prev, x, y, dx, dy, nx, ny)) continue;
        const Coord q = prev.at(nx, ny);
        consider({q.u - h * dx, q.v - h * dy}, true);
        const Coord* sim = similar(q);
        for (int i = 0; i + 1 < opt_.coherence_k; ++i) consider({sim[i].u - h * dx, sim[i].v - h * dy}, false);
      }
  }
  out.at(x, y) = best;
  sum += best_d;
}

double CoordinateSolver::correct(CoordImage& s, int level, StageProgress& progress) const {
  double total = 0.0;
  for (const auto& sp : kSubPass) {
    const CoordImage prev = s;  // pixels of one sub-pass read only this snapshot: any thread order gives one result
    const int rows = (s.height - sp[1] + 1) / 2;
    std::vector<double> row_sum(std::size_t(std::max(rows, 0)), 0.0);
    parallel_chunks(std::size_t(std::max(rows, 0)), 8, progress, [&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        const int y = sp[1] + 2 * int(r);
        double sum = 0.0;
        for (int x = sp[0]; x < s.width; x += 2) correct_pixel(prev, s, x, y, level, sum);
        row_sum[r] = sum;
      }
    });
    for (double v : row_sum) total += v;  // in row order: the same sum on any thread count
  }
  return total / double(std::max<std::size_t>(s.s.size(), 1));
}

CoordImage CoordinateSolver::synthesize(int width, int height, ExecContext* ctx, double lo, double hi,
                                        std::vector<double>* energy) const {
  const std::size_t L = std::size_t(levels());
  std::vector<int> ws(L), hs(L);
  ws[L - 1] = width;
  hs[L - 1] = height;
  for (std::size_t l = L - 1; l-- > 0;) ws[l] = (ws[l + 1] + 1) / 2, hs[l] = (hs[l + 1] + 1) / 2;
  // Progress shares by pixel count (each level has ~4x its parent's pixels).
  double remaining = 0.0;
  for (std::size_t l = 0; l < L; ++l) remaining += double(ws[l]) * hs[l];
  const int passes = std::max(opt_.corrections, 0);
  CoordImage s;
  // The patch refinement's and the seam cuts' shares of the progress: about what they cost.
  const double cut_lo = opt_.cut_passes > 0 ? lo + 0.6 * (hi - lo) : hi;
  const double levels_hi = opt_.refine_passes > 0 ? lo + 0.6 * (cut_lo - lo) : cut_lo;
  double at = lo;
  for (std::size_t l = 0; l < L; ++l) {
    const double pixels = double(ws[l]) * hs[l];
    const double next = at + (levels_hi - at) * pixels / remaining;
    remaining -= pixels;
    StageProgress progress(ctx, "image: level " + std::to_string(l + 1) + "/" + std::to_string(L) + " (coordinates)", at,
                           next, std::size_t(std::max(passes, 1)) * 2 * std::size_t(hs[l]));
    if (l == 0) {
      s = initial(ws[0], hs[0]);
    } else {
      s = upsample(s, ws[l], hs[l], int(l));
      jitter(s, int(l));
    }
    for (int pass = 0; pass < passes; ++pass) {
      const double e = correct(s, int(l), progress);
      if (energy) energy->push_back(e);
    }
    at = next;
  }
  PatchRefiner(scaled_, lowest(), highest(), opt_, tileable_, seed_).run(s, ctx, levels_hi, cut_lo, energy);
  SeamCutter(scaled_, lowest(), highest(), opt_, tileable_, seed_).run(s, ctx, cut_lo, hi, energy);
  return s;
}

Image CoordinateSolver::colours(const CoordImage& s) const {
  const int C = exemplar_.channels();
  Image out(s.width, s.height, C);
  for (std::size_t p = 0; p < s.s.size(); ++p) {
    const float* src = exemplar_.data() + exemplar_.offset(s.s[p].u, s.s[p].v);
    std::copy_n(src, C, out.data() + p * std::size_t(C));
  }
  return out;
}

Image synthesize_coordinates(const Image& exemplar, const ImageSynthesisOptions& opt, ExecContext* ctx,
                             std::vector<double>* energy) {
  for (const auto& [name, v] : {std::pair<const char*, int>{"width", opt.width}, {"height", opt.height}})
    if (v < 1 || v > kMaxImageSize)
      throw InvalidInput(std::string(name) + " must be between 1 and " + std::to_string(kMaxImageSize) +
                         " pixels, got " + std::to_string(v));
  if (opt.max_exemplar_size < 0 || opt.max_exemplar_size > (1 << 16))
    throw InvalidInput("max_exemplar_size must be between 0 and 65536 pixels (0 = full resolution), got " +
                       std::to_string(opt.max_exemplar_size));
  check_coordinate_options(opt.coordinates);
  check_finite(exemplar);
  StageProgress prepare(ctx, "image: preparing the exemplar", 0.0, 0.0, 1);
  // Working resolution as the optimiser's (large exemplars halved until they fit).
  Image working;
  const Image* ex = &exemplar;
  if (opt.max_exemplar_size > 0 && std::max(exemplar.width(), exemplar.height()) > opt.max_exemplar_size) {
    working = downsample(exemplar, Boundary::Clamp);
    while (std::max(working.width(), working.height()) > opt.max_exemplar_size) working = downsample(working, Boundary::Clamp);
    ex = &working;
  }
  prepare.check();
  {
    // Peak: the index's windows (n^2 C floats per pixel) and coefficients,
    // the appearance stack (8 floats per pixel per level, ~log2(edge)
    // levels), and per output pixel two coordinate images and the colours
    // (the patch refinement: one more coordinate image and gathered colours;
    // the seam cuts: the synthesis's coordinates kept, and the matches).
    const double n = opt.coordinates.appearance_window, px = double(ex->pixel_count());
    const double levels = std::log2(std::max(2, std::min(ex->width(), ex->height()))) + 1;
    const double bytes = 4.0 * px * (n * n * ex->channels() + 8.0 * (levels + 2)) +
                         double(opt.width) * opt.height * (16.0 + 4.0 * ex->channels()) *
                             (opt.coordinates.refine_passes > 0 || opt.coordinates.cut_passes > 0 ? 2.0 : 1.0);
    check_memory_budget(bytes, opt.memory_budget,
                        "image synthesis of " + std::to_string(opt.width) + "x" + std::to_string(opt.height) +
                            " from a " + std::to_string(ex->width()) + "x" + std::to_string(ex->height()) +
                            " working exemplar",
                        "lower max_exemplar_size or the output size, or raise the memory budget");
  }
  const CoordinateSolver solver(*ex, opt.coordinates, opt.tileable, opt.seed, ctx, 0.0, 0.15);
  const CoordImage s = solver.synthesize(opt.width, opt.height, ctx, 0.15, 1.0, energy);
  return solver.colours(s);
}

}  // namespace exsynth::image

namespace exsynth {

namespace {

const std::vector<std::string> kImageMethodNames{"coordinates", "optimization"};

}  // namespace

const std::vector<std::string>& image_method_names() { return kImageMethodNames; }
const char* default_image_method_name() {
  return kImageMethodNames[std::size_t(ImageSynthesisOptions{}.method)].c_str();
}
ImageMethod image_method_from_name(const std::string& name) {
  for (std::size_t i = 0; i < kImageMethodNames.size(); ++i)
    if (kImageMethodNames[i] == name) return ImageMethod(i);
  throw InvalidInput("method must be 'coordinates' or 'optimization', got '" + name + "'");
}

}  // namespace exsynth
