// Multiscale synthesis on the surface (Ying et al. 2001, §4; Wei & Levoy
// 2000): Gaussian pyramids of the exemplar and of every face map, brute force
// at the coarsest level, then per finer level the coarser level's sources
// upsampled and two passes with current + coarse neighbourhoods.
//
// Departures (measured in docs/surface.md): the passes with the current
// level run in 3x3 waves of texels searched in parallel (deterministic
// whatever the thread count; close to the paper's scanline order in
// quality), and add coherent candidates (Ashikhmin / Hertzmann) to the
// k-d tree's and, at the coarsest level, to the brute force's;
// candidates are exemplar pixels whose whole neighbourhood is inside the
// exemplar; Wei & Levoy's pass with the coarse
// neighbourhood alone is replaced by coordinate upsampling (Lefebvre &
// Hoppe 2005); the random pick among near-best matches (knn_tolerance) is
// off by default except at the coarsest level (kCoarsestTolerance); sources are float exemplar coordinates shifted by the
// chords between texel centres, as the coherent method's (sheared texel
// grids, as on triangles' sub-faces, keep their sub-pixel offsets).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "search/nanoflann_compat.hpp"

#include "exsynth/parallel.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/rng.hpp"
#include "search/pca.hpp"
#include "surface/methods.hpp"
#include "surface/walk.hpp"

namespace exsynth::surface {

int multiscale_levels(const Image& ex, const TexelGrid&, const SurfaceSynthesisOptions& opt) {
  if (opt.levels > 0) return opt.levels;
  // Down to an exemplar of 16 to 31 pixels a side (the coarsest level is a
  // brute-force search over all its pixels), at most 5 levels. Face maps
  // stop halving at one texel: their coarse levels are then sampled more
  // densely than they are stored, which the nearest-texel reads allow.
  int levels = 1;
  const int side = std::min(ex.width(), ex.height());
  while (levels < 5 && (side >> levels) >= std::max(opt.fine_neighborhood, 16)) ++levels;
  return levels;
}

namespace {

using search::RowMatrixXf;
/// A texel's source: float exemplar coordinates (pixel centres at integers).
/// Texels read the nearest pixel; the fraction carries a patch's sub-pixel
/// offsets across texels, as in the coherent method.
using Source = Eigen::Vector2f;

/// Texels of one face map go in kWaveModulus^2 waves (see waves()).
constexpr int kWaveModulus = 3;
/// Full brute-force passes at the coarsest level after the causal one (see run()).
constexpr int kCoarsestFullPasses = 1;
/// Coherent candidates re-ranked by their exact distance (see search_texel).
constexpr std::size_t kCoherentExact = 4;
/// nanoflann's approximation: matches within (1 + eps) of the true nearest in
/// the tree's metric. The k-d tree queries were 41 % of a multiscale run at
/// eps 0; eps 2 left the flat-plane score unchanged (0.480, 5 seeds).
constexpr float kSearchEps = 2.0f;
/// The coarsest level's brute force picks at random among its knn nearest
/// within (1 + this) of the best (at least; knn_tolerance if larger), the
/// paper's 0.1. With the exact nearest, small inputs let two seeds grow the
/// same texture: worst pair of seeds 4-23 sharing 0.995 of its texels (32^2
/// exemplar, 4 x 4 plane, 8 texels a face), 0.959 (24^2); now 0.425 /
/// 0.221. The flat plane (48^2, 16 texels a face, 20 seeds, 400 windows)
/// scored 0.359 without it, 0.349 with 0.1, 0.354 with 0.15 (worst share
/// 0.240), 0.376 with 0.2, and 0.350 with 0.1 at every level (knn_tolerance).
constexpr double kCoarsestTolerance = 0.1;

struct Layout {
  int fine_r = 0, coarse_r = 0;  // radii; 0 / -1 = unused
  bool fine = false, coarse = false;
  std::vector<float> fine_w, coarse_w;  // sqrt of the Gaussian weights
  int channels = 0;
  int dims() const {
    const int nf = fine ? (2 * fine_r + 1) * (2 * fine_r + 1) : 0;
    const int nc = coarse ? (2 * coarse_r + 1) * (2 * coarse_r + 1) : 0;
    return (nf + nc) * channels;
  }
};

std::vector<float> gaussian_sqrt_weights(int r) {
  std::vector<float> w;
  const double sigma = std::max(1.0, r / 1.5);
  for (int m = -r; m <= r; ++m)
    for (int l = -r; l <= r; ++l) w.push_back(float(std::exp(-(l * l + m * m) / (4 * sigma * sigma))));
  return w;
}

class MultiscaleSolver {
 public:
  MultiscaleSolver(const SubdivSurface& s, const TexelFrames& fr, const VertexCharts* charts, const Image& ex,
                   const SurfaceSynthesisOptions& o, double h, ExecContext* ctx)
      : surface_(s), frames_(fr), charts_(charts), opt_(o), h_(h), ctx_(ctx), C_(ex.channels()) {
    levels_ = multiscale_levels(ex, fr.grid, o);
    PyramidOptions po;
    po.levels = levels_;
    po.boundary = o.tileable_exemplar ? Boundary::Wrap : Boundary::Clamp;
    ex_ = gaussian_pyramid(ex, po, ctx);
    grids_.push_back(fr.grid);
    for (int l = 1; l < levels_; ++l) grids_.push_back(grids_.back().coarser());
    values_.resize(std::size_t(levels_));
    src_.resize(std::size_t(levels_));
  }

  void run(SurfaceTexture& out) {
    const int top = levels_ - 1;
    init_random(top);
    prepare_level(top);
    {
      const Layout lay = layout(Pass::Coarsest);
      StageProgress progress(ctx_, "multiscale level " + std::to_string(top) + " exemplar", 0.0, 1.0, 1);
      const std::unique_ptr<PassIndex> ix = pass_index(top, lay, false, progress);
      run_brute_pass(top, lay, *ix, true, 100);
      // Full passes after the causal one: with whole-pixel sources 0.341 /
      // 0.331 / 0.326 for 1 / 2 / 3 (flat plane, 10 seeds); with float
      // sources 0.353 / 0.348 for 1 / 2 (20 seeds), but the second took
      // +23 % CPU on the cow at 73 k texels with a 128^2 exemplar (52 k
      // coarsest texels, one a ptex face, against 256 pixels).
      for (int k = 0; k < kCoarsestFullPasses; ++k) run_brute_pass(top, lay, *ix, false, 101 + std::uint64_t(k));
    }
    for (int l = top - 1; l >= 0; --l) {
      prepare_level(l);
      init_level(l);
      const std::string name = "multiscale level " + std::to_string(l);
      const Layout full = layout(Pass::Full);
      // Pass 1: the coarser level's sources upsampled (Wei & Levoy's pass
      // with the coarse neighbourhood alone picked every texel on its own
      // and left the next passes to grow patches from noise: flat-plane
      // window distance 0.466 with it, 0.397 upsampled, 10 seeds).
      upsample_level(l);
      StageProgress progress2(ctx_, name + " exemplar", 0.0, 1.0, 1);
      const std::unique_ptr<PassIndex> ix = pass_index(l, full, true, progress2);
      run_tree_pass(l, full, *ix, 4 * std::uint64_t(l) + 1, name + " pass 2");
      run_tree_pass(l, full, *ix, 4 * std::uint64_t(l) + 2, name + " pass 2");
    }
    add_stats(out, stats_);
    out.texels = values_[0];
    const std::size_t n = grids_[0].size();
    out.source.resize(n * 2);
    for (std::size_t t = 0; t < n; ++t) {
      out.source[t * 2] = src_[0][t].x();
      out.source[t * 2 + 1] = src_[0][t].y();
    }
  }

 private:
  enum class Pass { Coarsest, Full };

  /// Coarsest level: current-level neighbourhood only (brute force). Finer
  /// levels: current + coarse.
  Layout layout(Pass pass) const {
    Layout lay;
    lay.channels = C_;
    lay.fine = true;
    lay.coarse = pass != Pass::Coarsest;
    lay.fine_r = opt_.fine_neighborhood / 2;
    lay.coarse_r = opt_.coarse_neighborhood / 2;
    lay.fine_w = gaussian_sqrt_weights(lay.fine_r);
    lay.coarse_w = gaussian_sqrt_weights(lay.coarse_r);
    return lay;
  }

  double spacing(int level) const { return h_ * double(1 << level); }

  /// The pixel (y W + x) nearest to source c at level l; wraps c into the
  /// exemplar when tileable, else -1 when it reads outside.
  int pixel_of(int l, Source& c) const {
    const Image& e = ex_[std::size_t(l)];
    const int W = e.width(), H = e.height();
    if (opt_.tileable_exemplar) {
      c.x() -= float(W) * std::floor((c.x() + 0.5f) / float(W));
      c.y() -= float(H) * std::floor((c.y() + 0.5f) / float(H));
    }
    const int x = std::clamp(int(std::floor(c.x() + 0.5f)), -1, W), y = std::clamp(int(std::floor(c.y() + 0.5f)), -1, H);
    return x < 0 || y < 0 || x >= W || y >= H ? -1 : y * W + x;
  }

  static Source source_of(int pixel, int W) { return Source(float(pixel % W), float(pixel / W)); }

  void set_texel(int l, std::size_t t, Source c) {
    const int pixel = pixel_of(l, c);
    src_[std::size_t(l)][t] = c;
    const Image& e = ex_[std::size_t(l)];
    const float* p = e.data() + std::size_t(pixel) * std::size_t(C_);
    std::copy(p, p + C_, values_[std::size_t(l)].begin() + std::ptrdiff_t(t * std::size_t(C_)));
  }

  /// Offset of texel q from texel t at level l in exemplar pixels: the chord
  /// between their centres in t's frame (as the coherent method's offsets),
  /// or the sample's (dl, dm) where the two are more than a pixel apart (a
  /// sample stopped at a boundary, a tight bend).
  Eigen::Vector2f offset(int l, std::size_t t, std::size_t q, int dl, int dm) const {
    const Eigen::Vector3f c = lpos_[q] - lpos_[t];
    const float h = float(spacing(l));
    const Eigen::Vector2f o(c.dot(lt1_[t]) / h, -c.dot(lt2_[t]) / h);
    const Eigen::Vector2f lm = Eigen::Vector2f(float(dl), float(dm));
    return (o - lm).squaredNorm() > 1.0f ? lm : o;
  }

  void init_random(int l) {
    const std::size_t n = grids_[std::size_t(l)].size();
    values_[std::size_t(l)].assign(n * std::size_t(C_), 0.0f);
    src_[std::size_t(l)].assign(n, Source::Zero());
    const Image& e = ex_[std::size_t(l)];
    for (std::size_t t = 0; t < n; ++t) {
      IndexRng rng(opt_.seed, t, 1000 + std::uint64_t(l));
      set_texel(l, t, source_of(int(rng.below(std::uint64_t(e.width()) * std::uint64_t(e.height()))), e.width()));
    }
  }

  /// Level l from level l + 1's sources: texel t takes the fine coordinate
  /// at its offset from the coarser texel its centre falls in (coordinate
  /// upsampling, Lefebvre & Hoppe 2005; coarse pixel X covers fine pixels
  /// 2X and 2X + 1, centred at 2X + 0.5).
  void upsample_level(int l) {
    const TexelGrid& g = grids_[std::size_t(l)];
    const TexelGrid& gc = grids_[std::size_t(l + 1)];
    const int W = ex_[std::size_t(l)].width(), H = ex_[std::size_t(l)].height();
    const double hf = spacing(l);
    for (std::size_t t = 0; t < g.size(); ++t) {
      const SurfacePoint p = g.centre(t);
      const std::size_t tc = gc.texel(p);
      const SurfacePoint pc = gc.centre(tc);
      const std::size_t f0 = frames_.grid.texel(p);
      const Eigen::Vector3f chord = (frames_.approx(p).position - frames_.approx(pc).position).cast<float>();
      const double ox = chord.dot(frames_.t1[f0]) / hf, oy = -chord.dot(frames_.t2[f0]) / hf;
      const Source& sc = src_[std::size_t(l + 1)][tc];
      Source c(float(2.0 * sc.x() + 0.5 + ox), float(2.0 * sc.y() + 0.5 + oy));
      if (!opt_.tileable_exemplar) {
        c.x() = std::clamp(c.x(), 0.0f, float(W - 1));
        c.y() = std::clamp(c.y(), 0.0f, float(H - 1));
      }
      set_texel(l, t, c);
    }
  }

  void init_level(int l) {
    const std::size_t n = grids_[std::size_t(l)].size();
    values_[std::size_t(l)].assign(n * std::size_t(C_), 0.0f);
    src_[std::size_t(l)].assign(n, Source::Zero());
  }

  void exemplar_feature(int l, int x, int y, const Layout& lay, float* out) const {
    const bool wrap = opt_.tileable_exemplar;
    float* o = out;
    if (lay.fine) {
      const Image& e = ex_[std::size_t(l)];
      int k = 0;
      for (int m = -lay.fine_r; m <= lay.fine_r; ++m)
        for (int i = -lay.fine_r; i <= lay.fine_r; ++i, ++k) {
          sample_exemplar(e, x + i, y + m, wrap, o);
          for (int c = 0; c < C_; ++c) o[c] *= lay.fine_w[std::size_t(k)];
          o += C_;
        }
    }
    if (lay.coarse) {
      const Image& e = ex_[std::size_t(l + 1)];
      int k = 0;
      for (int m = -lay.coarse_r; m <= lay.coarse_r; ++m)
        for (int i = -lay.coarse_r; i <= lay.coarse_r; ++i, ++k) {
          // Pixel floor(x / 2) of the coarser level, as a surface texel
          // reads the coarser texel its centre falls in: fine texels 2I and
          // 2I + 1 share coarse texel I on the surface, so pixels 2X and
          // 2X + 1 share coarse pixel X here (bilinear reads at x / 2 put
          // the two sides half a pixel apart and blurred the match).
          sample_exemplar(e, std::floor(0.5 * x) + i, std::floor(0.5 * y) + m, wrap, o);
          for (int c = 0; c < C_; ++c) o[c] *= lay.coarse_w[std::size_t(k)];
          o += C_;
        }
    }
  }

  /// A landing-table entry of a sample that stopped at a boundary (it reads
  /// the texel where it stopped, but gives no coherent candidate), and back.
  static std::int32_t past_boundary(std::int32_t q) { return -1 - q; }
  static std::size_t landed(std::int32_t e) { return std::size_t(e < 0 ? -1 - e : e); }

  /// The texels of level `lv` the (2r+1)^2 samples at spacing hh around each
  /// texel of level l land in: walked once per level (in parallel) and read
  /// by every pass (the walks are most of the work on fine meshes, where
  /// coarse neighbourhoods cross many faces). Past a boundary a sample keeps
  /// the texel where its walk stopped.
  std::vector<std::int32_t> landing_table(int l, int lv, int r, double hh) {
    const int per = (2 * r + 1) * (2 * r + 1);
    const TexelGrid& g = grids_[std::size_t(l)];
    const TexelGrid& to = grids_[std::size_t(lv)];
    std::vector<std::int32_t> tab(g.size() * std::size_t(per));
    StageProgress progress(ctx_, "surface neighbourhoods, level " + std::to_string(l), 0.0, 1.0, g.size());
    std::atomic<std::uint64_t> in_chart{0}, walked{0};
    parallel_chunks(g.size(), 512, progress, [&](std::size_t b, std::size_t e) {
      ChartStats stats;
      for (std::size_t t = b; t < e; ++t) {
        const SurfacePoint p = g.centre(t);
        const std::size_t t0 = frames_.grid.texel(p);
        SurfacePoint pts[kMaxSamples];
        bool valid[kMaxSamples];
        neighbourhood_points(surface_, frames_, charts_, p, t0, hh, r, pts, valid, &stats);
        std::int32_t* row = tab.data() + t * std::size_t(per);
        for (int k = 0; k < per; ++k) {
          const std::int32_t q = std::int32_t(to.texel(pts[k]));
          row[k] = valid[k] ? q : past_boundary(q);
        }
      }
      in_chart += stats.in_chart;
      walked += stats.walked;
    });
    stats_.in_chart += in_chart;
    stats_.walked += walked;
    return tab;
  }

  void gather(const std::int32_t* landing, int lv, int r, const std::vector<float>& w, float*& o,
              const std::vector<char>* visited = nullptr) const {
    const std::vector<float>& vals = values_[std::size_t(lv)];
    const int per = (2 * r + 1) * (2 * r + 1);
    for (int k = 0; k < per; ++k) {
      const std::size_t tq = landed(landing[k]);
      const float* v = vals.data() + tq * std::size_t(C_);
      const bool known = !visited || (*visited)[tq];
      for (int c = 0; c < C_; ++c) o[c] = known ? v[c] * w[std::size_t(k)] : std::numeric_limits<float>::quiet_NaN();
      o += C_;
    }
  }

  /// visited: only those current-level texels count (others NaN: causal).
  void target_feature(int l, std::size_t t, const Layout& lay, float* out,
                      const std::vector<char>* visited = nullptr) const {
    float* o = out;
    const int nf = (2 * lay.fine_r + 1) * (2 * lay.fine_r + 1), nc = (2 * lay.coarse_r + 1) * (2 * lay.coarse_r + 1);
    if (lay.fine) gather(fine_nb_.data() + t * std::size_t(nf), l, lay.fine_r, lay.fine_w, o, visited);
    if (lay.coarse) gather(coarse_nb_.data() + t * std::size_t(nc), l + 1, lay.coarse_r, lay.coarse_w, o);
  }

  /// Positions and frames at the texel centres of level l (from the finest
  /// level's cache), for the offsets between texels.
  void level_frames(int l) {
    const TexelGrid& g = grids_[std::size_t(l)];
    lpos_.resize(g.size());
    lt1_.resize(g.size());
    lt2_.resize(g.size());
    StageProgress progress(ctx_, "multiscale level " + std::to_string(l) + " frames", 0.0, 1.0, g.size());
    parallel_chunks(g.size(), 4096, progress, [&](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) {
        const SurfacePoint p = g.centre(t);
        const std::size_t f0 = frames_.grid.texel(p);
        lpos_[t] = frames_.approx(p).position.cast<float>();
        lt1_[t] = frames_.t1[f0];
        lt2_[t] = frames_.t2[f0];
      }
    });
  }

  /// Walks the neighbourhoods of level l (current and coarser) once.
  void prepare_level(int l) {
    const int fr = opt_.fine_neighborhood / 2, cr = opt_.coarse_neighborhood / 2;
    level_frames(l);
    fine_nb_ = landing_table(l, l, fr, spacing(l));
    coarse_nb_ = l + 1 < levels_ ? landing_table(l, l + 1, cr, spacing(l + 1)) : std::vector<std::int32_t>{};
  }

  /// Among k (distance, pixel) pairs sorted by distance: a random one within
  /// (1 + tolerance) of the best.
  /// (Distances squared: the tolerance applies to their square roots.)
  int pick(std::vector<std::pair<float, int>>& best, std::size_t t, std::uint64_t stream, double tolerance) const {
    std::sort(best.begin(), best.end());
    const float limit = best[0].first * float((1.0 + tolerance) * (1.0 + tolerance));
    std::size_t n = 1;
    while (n < best.size() && best[n].first <= limit) ++n;
    IndexRng rng(opt_.seed, t, stream);
    return best[std::size_t(rng.below(n))].second;
  }

  /// The exemplar side of one kind of pass at one level: the (weighted)
  /// neighbourhood of every candidate pixel, and its PCA + k-d tree (not for
  /// brute force). Without wrapping, candidates are the pixels whose whole
  /// neighbourhood (and coarse neighbourhood) lies inside the exemplar, as in
  /// Wei & Levoy: clamped border neighbourhoods matched the surface's
  /// neighbourhoods as well as real ones and were copied down whole columns
  /// (visible streaks on the flat-plane test).
  struct PassIndex {
    RowMatrixXf X;            // rows x D
    std::vector<int> pixel;   // per row: its exemplar pixel
    std::vector<int> row;     // per exemplar pixel: its row, -1 = not a candidate
    search::Pca pca;
    RowMatrixXf Y;            // rows x d
    using Tree = nanoflann::KDTreeEigenMatrixAdaptor<RowMatrixXf, -1, nanoflann::metric_L2_Simple>;
    std::unique_ptr<Tree> tree;
  };

  std::unique_ptr<PassIndex> pass_index(int l, const Layout& lay, bool with_tree, StageProgress& progress) const {
    const Image& e = ex_[std::size_t(l)];
    const int W = e.width(), H = e.height();
    auto ix = std::make_unique<PassIndex>();
    int margin = 0;
    if (!opt_.tileable_exemplar) {
      margin = std::max(lay.fine ? lay.fine_r : 0, lay.coarse ? 2 * lay.coarse_r + 1 : 0);
      // The coarsest level (no coarser one) takes every pixel: on a 16^2
      // level a 9x9 neighbourhood leaves (16 - 8)^2 = 64 whole ones, and so
      // few candidates repeated themselves as long bands (the 64^2 wood on
      // a flat grid: stripes 3-4 exemplars long; the multiscale cow's
      // diagonal stripes). Flat-plane score unchanged (0.478 vs 0.480, 5 seeds).
      if (!lay.coarse) margin = 0;
      margin = std::min(margin, (std::min(W, H) - 1) / 2);
    }
    ix->row.assign(std::size_t(W) * std::size_t(H), -1);
    for (int y = margin; y < H - margin; ++y)
      for (int x = margin; x < W - margin; ++x) {
        ix->row[std::size_t(y * W + x)] = int(ix->pixel.size());
        ix->pixel.push_back(y * W + x);
      }
    ix->X.resize(Eigen::Index(ix->pixel.size()), lay.dims());
    parallel_chunks(ix->pixel.size(), 64, progress, [&](std::size_t b, std::size_t end) {
      for (std::size_t i = b; i < end; ++i)
        exemplar_feature(l, ix->pixel[i] % W, ix->pixel[i] / W, lay, ix->X.row(Eigen::Index(i)).data());
    });
    if (with_tree) {
      ix->pca = search::fit_pca(ix->X, opt_.pca_variance, opt_.max_pca_dims, &progress);
      ix->Y = ix->pca.project(ix->X);
      ix->tree = std::make_unique<PassIndex::Tree>(int(ix->Y.cols()), std::cref(ix->Y), 16);
      search::nf::ensure_built(search::nf::index(*ix->tree));
    }
    return ix;
  }

  /// Per-thread buffers of the searches (nothing allocated per texel).
  struct Scratch {
    Eigen::RowVectorXf q, qp;
    std::vector<std::size_t> idx;
    std::vector<float> d2;
    std::vector<std::pair<float, int>> best;
    std::vector<std::pair<int, Source>> cands;
    std::vector<char> mark;
    std::vector<std::pair<float, int>> coh;
    Scratch(int D, int d, int k) : q(D), qp(d), idx(std::size_t(k)), d2(std::size_t(k)) {}
  };

  /// Squared distance of the target neighbourhood to candidate `pixel`: in
  /// the PCA space of the pass (the k-d tree's metric), and in full.
  float pca_d2(const PassIndex& ix, const Scratch& s, int pixel) const {
    return (ix.Y.row(ix.row[std::size_t(pixel)]) - s.qp).squaredNorm();
  }
  float exact_d2(const PassIndex& ix, const Scratch& s, int pixel) const {
    return (ix.X.row(ix.row[std::size_t(pixel)]) - s.q).squaredNorm();
  }

  /// The coherent candidates of texel t at level l: the source of each
  /// fine-neighbourhood sample's texel (visited ones only, if given) shifted
  /// back by that texel's offset, one per pixel (the first), candidates of
  /// the pass only. mark: per-thread flags by pixel (all clear on return).
  void coherent_candidates(int l, std::size_t t, const Layout& lay, const PassIndex& ix,
                           const std::vector<char>* visited, std::vector<std::pair<int, Source>>& out,
                           std::vector<char>& mark) const {
    mark.resize(ix.row.size(), 0);
    const int side = 2 * lay.fine_r + 1, per = side * side;
    const std::int32_t* nb = fine_nb_.data() + t * std::size_t(per);
    const std::vector<Source>& src = src_[std::size_t(l)];
    out.clear();
    for (int j = 0; j < per; ++j) {
      if (nb[j] < 0) continue;  // past a boundary
      const std::size_t q = std::size_t(nb[j]);
      if (visited && !(*visited)[q]) continue;
      Source c = src[q] - offset(l, t, q, j % side - lay.fine_r, j / side - lay.fine_r);
      const int pixel = pixel_of(l, c);
      // Border pixels are no candidates here either: compared over the part
      // of their neighbourhood inside the exemplar they scored the flat
      // plane better (0.383 vs 0.397, 10 seeds) but copied columns down the
      // mesh's boundary faces, where samples past the boundary repeat the
      // last texel (visible stripes the window score hardly sees).
      if (pixel < 0 || ix.row[std::size_t(pixel)] < 0) continue;
      if (mark[std::size_t(pixel)]) continue;
      mark[std::size_t(pixel)] = 1;
      out.emplace_back(pixel, c);
    }
    for (const std::pair<int, Source>& o : out) mark[std::size_t(o.first)] = 0;
  }

  /// One texel of a k-d tree pass: the approximate nearest neighbours,
  /// re-ranked by their exact distance, one picked at random within the
  /// tolerance; with the current level in the neighbourhood, the coherent
  /// candidates (the sources of the 9x9 neighbours shifted back by their
  /// offsets: Ashikhmin's / Hertzmann's coherence; the best kCoherentExact
  /// by PCA distance re-ranked exactly) win unless the best k-d tree match is
  /// more than (1 + coherence) closer (squared L2). Flat-plane window
  /// distance (5 seeds): 0.61 without coherence, 0.49 with it; ranking the
  /// coherent candidates by PCA distance alone gave 0.525, exact distances
  /// for all of them cost 13x more per candidate for 0.490. The bounded
  /// tree search gave the same sources as the unbounded one on the flat and
  /// triangulated planes (2 seeds each) for 13 % less CPU on the flat plane.
  Source search_texel(int l, std::size_t t, const Layout& lay, const PassIndex& ix, Scratch& s,
                      std::uint64_t stream) const {
    target_feature(l, t, lay, s.q.data());
    s.qp.noalias() = (s.q - ix.pca.mean) * ix.pca.basis;
    // The coherent candidates first: the best of them (exact distance) bounds
    // the tree search, which can only change the pick by a match more than
    // (1 + coherence) closer — and the PCA distance (the tree's metric) is
    // never more than the exact one, so the tree need not look farther.
    float coh_d2 = std::numeric_limits<float>::infinity();
    const Source* coh = nullptr;
    if (lay.fine && opt_.coherence > 0) {
      coherent_candidates(l, t, lay, ix, nullptr, s.cands, s.mark);
      s.coh.clear();
      for (std::size_t i = 0; i < s.cands.size(); ++i) s.coh.push_back({pca_d2(ix, s, s.cands[i].first), int(i)});
      const std::size_t m = std::min(s.coh.size(), kCoherentExact);
      std::partial_sort(s.coh.begin(), s.coh.begin() + std::ptrdiff_t(m), s.coh.end());
      for (std::size_t i = 0; i < m; ++i) {
        const std::pair<int, Source>& c = s.cands[std::size_t(s.coh[i].second)];
        const float d2 = exact_d2(ix, s, c.first);
        if (d2 < coh_d2) {
          coh_d2 = d2;
          coh = &c.second;
        }
      }
    }
    const std::size_t k = s.idx.size();
    // The bound prunes the search until k matches inside it are found.
    const float bound = coh ? coh_d2 / float(1.0 + opt_.coherence) : std::numeric_limits<float>::max();
    search::nf::BoundedKnn<std::size_t, float> result(k, s.idx.data(), s.d2.data(), bound);
    search::nf::index(*ix.tree).findNeighbors(result, s.qp.data(), search::nf::params(kSearchEps));
    if (result.size() == 0) return *coh;  // nothing (1 + coherence) closer
    s.best.clear();
    for (std::size_t i = 0; i < result.size(); ++i) {
      const int p = ix.pixel[s.idx[i]];
      s.best.push_back({exact_d2(ix, s, p), p});
    }
    std::sort(s.best.begin(), s.best.end());
    const float app_d2 = s.best[0].first;
    const Source app = source_of(pick(s.best, t, stream, opt_.knn_tolerance), ex_[std::size_t(l)].width());
    return coh && coh_d2 <= app_d2 * float(1.0 + opt_.coherence) ? *coh : app;
  }

  /// Texels of level l in waves: texel (i, j) of its face map in wave
  /// (i mod 3) + 3 (j mod 3), each wave in synthesis order. A wave's texels
  /// are searched in parallel against the values of the waves before it
  /// (and the previous pass): deterministic whatever the thread count, and
  /// close to the sequential scanline order in quality (flat-plane window
  /// distance, 5 seeds: sequential 0.480, 3x3 waves 0.490, 2x2 0.506, all
  /// at once 0.523).
  std::vector<std::vector<std::size_t>> waves(int l) const {
    const TexelGrid& g = grids_[std::size_t(l)];
    const int m = kWaveModulus;
    std::vector<std::vector<std::size_t>> w(std::size_t(m * m));
    for (std::size_t t : synthesis_order(surface_, g)) {
      const int f = g.face_of[t], r = g.res[std::size_t(f)];
      const std::size_t k = t - g.offset[std::size_t(f)];
      const int i = int(k % std::size_t(r)), j = int(k / std::size_t(r));
      w[std::size_t((i % m) + m * (j % m))].push_back(t);
    }
    return w;
  }

  void commit(int l, const std::vector<std::size_t>& texels, const std::vector<Source>& pixels) {
    for (std::size_t i = 0; i < texels.size(); ++i) set_texel(l, texels[i], pixels[i]);
  }

  /// A k-d tree pass over level l (current + coarse neighbourhoods, in waves).
  void run_tree_pass(int l, const Layout& lay, const PassIndex& ix, std::uint64_t stream, const std::string& stage) {
    const std::size_t n = grids_[std::size_t(l)].size();
    const int k = std::min(opt_.knn, int(ix.X.rows()));
    StageProgress progress(ctx_, stage, 0.0, 1.0, n);
    for (const std::vector<std::size_t>& texels : waves(l)) {
      std::vector<Source> pixels(texels.size());
      parallel_chunks(texels.size(), 256, progress, [&](std::size_t b, std::size_t e) {
        Scratch s(int(ix.X.cols()), ix.pca.dims(), k);
        for (std::size_t i = b; i < e; ++i) pixels[i] = search_texel(l, texels[i], lay, ix, s, stream);
      });
      commit(l, texels, pixels);
    }
  }

  /// Per-thread buffers of the brute-force passes.
  struct BruteScratch {
    std::vector<std::pair<float, int>> dist, best;
    std::vector<std::pair<int, Source>> cands;
    std::vector<char> mark;
  };

  /// Brute force at the coarsest level: the pixel for texel t from the
  /// distances d2 of its neighbourhood to every candidate row. The best coherent candidate (see coherent_candidates) wins
  /// unless the best of all is more than (1 + coherence) closer, as in the
  /// k-d tree passes: the coarsest level decides the patches every finer
  /// level copies, and the exact nearest alone broke them up (flat-plane
  /// window distance 0.413 without, 0.341 with it, 10 seeds, 400 windows).
  Source brute_pick(int l, std::size_t t, const Layout& lay, const PassIndex& ix, const std::vector<float>& d2,
                    const std::vector<char>* visited, BruteScratch& s, std::uint64_t stream) const {
    const int P = int(d2.size()), k = std::min(opt_.knn, P);
    float coh_d2 = std::numeric_limits<float>::infinity();
    const Source* coh = nullptr;
    if (opt_.coherence > 0) {
      coherent_candidates(l, t, lay, ix, visited, s.cands, s.mark);
      for (const std::pair<int, Source>& c : s.cands) {
        const float d = d2[std::size_t(ix.row[std::size_t(c.first)])];
        if (d < coh_d2) coh_d2 = d, coh = &c.second;
      }
    }
    s.dist.resize(std::size_t(P));
    for (int p = 0; p < P; ++p) s.dist[std::size_t(p)] = {d2[std::size_t(p)], ix.pixel[std::size_t(p)]};
    std::partial_sort(s.dist.begin(), s.dist.begin() + k, s.dist.end());
    s.best.assign(s.dist.begin(), s.dist.begin() + k);
    const float best_d2 = s.best[0].first;
    const Source app = source_of(pick(s.best, t, stream, std::max(opt_.knn_tolerance, kCoarsestTolerance)),
                                 ex_[std::size_t(l)].width());
    return coh && coh_d2 <= best_d2 * float(1.0 + opt_.coherence) ? *coh : app;
  }

  /// The coarsest level by brute force over all exemplar pixels, in place.
  /// causal: in synthesis order, comparing only the texels visited so far
  /// (the others are noise), the per-texel distances computed in parallel;
  /// else the full neighbourhood, in waves of texels searched in parallel.
  /// (Jacobi passes from noise stayed noise.)
  void run_brute_pass(int l, const Layout& lay, const PassIndex& ix, bool causal, std::uint64_t stream) {
    const std::size_t n = grids_[std::size_t(l)].size();
    const int P = int(ix.X.rows()), D = int(ix.X.cols());
    StageProgress progress(ctx_, std::string("multiscale level ") + std::to_string(l) + " coarsest", 0.0, 1.0, n);
    if (causal) {
      std::vector<char> visited(n, 0);
      Eigen::RowVectorXf q(D), mask(D);
      std::vector<float> d2(static_cast<std::size_t>(P));
      BruteScratch s;
      const std::vector<std::size_t> order = synthesis_order(surface_, grids_[std::size_t(l)]);
      for (std::size_t i = 0; i < n; ++i) {
        if ((i & 255) == 0) progress.check();
        const std::size_t t = order[i];
        target_feature(l, t, lay, q.data(), &visited);
        int known_dims = 0;
        for (int d = 0; d < D; ++d) {
          const bool known = !std::isnan(q[d]);
          known_dims += known ? 1 : 0;
          mask[d] = known ? 1.0f : 0.0f;
          if (!known) q[d] = 0.0f;
        }
        // Texels that see fewer than a ninth of their samples synthesized
        // (the first row of the first face) keep their random pixels: with
        // the first texel alone random, the whole level followed from one
        // of 576 pixels and seeds 8 / 17, 9 / 18, 10 / 19, 11 / 16 gave the
        // same texture (flat plane, seeds 4-23).
        if (known_dims * 9 >= D) {
          tbb::parallel_for(tbb::blocked_range<int>(0, P, 64), [&](const tbb::blocked_range<int>& r) {
            for (int p = r.begin(); p < r.end(); ++p)
              d2[std::size_t(p)] = ((ix.X.row(p) - q).cwiseProduct(mask)).squaredNorm();
          }, tbb::simple_partitioner());
          set_texel(l, t, brute_pick(l, t, lay, ix, d2, &visited, s, stream));
        }
        visited[t] = 1;
      }
      progress.advance(n);
      return;
    }
    for (const std::vector<std::size_t>& texels : waves(l)) {
      std::vector<Source> pixels(texels.size());
      parallel_chunks(texels.size(), 16, progress, [&](std::size_t b, std::size_t e) {
        Eigen::RowVectorXf q(D);
        std::vector<float> d2(static_cast<std::size_t>(P));
        BruteScratch s;
        for (std::size_t i = b; i < e; ++i) {
          target_feature(l, texels[i], lay, q.data());
          for (int p = 0; p < P; ++p) d2[std::size_t(p)] = (ix.X.row(p) - q).squaredNorm();
          pixels[i] = brute_pick(l, texels[i], lay, ix, d2, nullptr, s, stream);
        }
      });
      commit(l, texels, pixels);
    }
  }

  const SubdivSurface& surface_;
  const TexelFrames& frames_;
  const VertexCharts* charts_;
  const SurfaceSynthesisOptions& opt_;
  double h_;
  ExecContext* ctx_;
  int C_;
  int levels_ = 1;
  std::vector<Image> ex_;
  std::vector<TexelGrid> grids_;
  std::vector<std::vector<float>> values_;
  std::vector<std::vector<Source>> src_;
  std::vector<Eigen::Vector3f> lpos_, lt1_, lt2_;  // texel centres and frames of the level being synthesized
  std::vector<std::int32_t> fine_nb_, coarse_nb_;  // landing tables of the level being synthesized
  ChartStats stats_;  // over all landing tables

};

}  // namespace

void run_multiscale(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts* charts,
                    const Image& exemplar, const SurfaceSynthesisOptions& opt, SurfaceTexture& out,
                    ExecContext* ctx) {
  MultiscaleSolver solver(surface, frames, charts, exemplar, opt, out.sample_spacing, ctx);
  solver.run(out);
}

}  // namespace exsynth::surface
