// Multiscale synthesis on the surface (Ying et al. 2001, §4; Wei & Levoy
// 2000): Gaussian pyramids of the exemplar and of every face map, brute force
// at the coarsest level, then per finer level a pass with coarse-level
// neighbourhoods only and a pass with current + coarse neighbourhoods.
//
// Departure: each pass reads the previous pass's values (Jacobi order, all
// texels in parallel) instead of the paper's causal scanline order — passes
// are deterministic whatever the thread count and use both cores; the
// second pass sees a full 9x9 (non-causal) current-level neighbourhood.
#include <algorithm>
#include <cmath>
#include <limits>

#include <nanoflann.hpp>

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
  MultiscaleSolver(const SubdivSurface& s, const TexelFrames& fr, const Image& ex, const SurfaceSynthesisOptions& o,
                   double h, ExecContext* ctx)
      : surface_(s), frames_(fr), opt_(o), h_(h), ctx_(ctx), C_(ex.channels()) {
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
    for (int pass = 0; pass < 2; ++pass) run_pass(top, layout(Pass::Coarsest), true, 100 + std::uint64_t(pass));
    for (int l = top - 1; l >= 0; --l) {
      prepare_level(l);
      run_pass(l, layout(Pass::CoarseOnly), false, 4 * std::uint64_t(l));
      run_pass(l, layout(Pass::Full), false, 4 * std::uint64_t(l) + 1);
      run_pass(l, layout(Pass::Full), false, 4 * std::uint64_t(l) + 2);
    }
    out.texels = values_[0];
    const std::size_t n = grids_[0].size();
    out.source.resize(n * 2);
    const int w = ex_[0].width();
    for (std::size_t t = 0; t < n; ++t) {
      out.source[t * 2] = float(src_[0][t] % w);
      out.source[t * 2 + 1] = float(src_[0][t] / w);
    }
  }

 private:
  enum class Pass { Coarsest, CoarseOnly, Full };

  /// Coarsest level: current-level neighbourhood only (brute force). Finer
  /// levels: pass 1 coarse-level only, pass 2 current + coarse.
  Layout layout(Pass pass) const {
    Layout lay;
    lay.channels = C_;
    lay.fine = pass != Pass::CoarseOnly;
    lay.coarse = pass != Pass::Coarsest;
    lay.fine_r = opt_.fine_neighborhood / 2;
    lay.coarse_r = opt_.coarse_neighborhood / 2;
    lay.fine_w = gaussian_sqrt_weights(lay.fine_r);
    lay.coarse_w = gaussian_sqrt_weights(lay.coarse_r);
    return lay;
  }

  double spacing(int level) const { return h_ * double(1 << level); }

  void set_texel(int l, std::size_t t, int pixel) {
    src_[std::size_t(l)][t] = pixel;
    const Image& e = ex_[std::size_t(l)];
    const float* p = e.data() + std::size_t(pixel) * std::size_t(C_);
    std::copy(p, p + C_, values_[std::size_t(l)].begin() + std::ptrdiff_t(t * std::size_t(C_)));
  }

  void init_random(int l) {
    const std::size_t n = grids_[std::size_t(l)].size();
    values_[std::size_t(l)].assign(n * std::size_t(C_), 0.0f);
    src_[std::size_t(l)].assign(n, 0);
    const Image& e = ex_[std::size_t(l)];
    for (std::size_t t = 0; t < n; ++t) {
      IndexRng rng(opt_.seed, t, 1000 + std::uint64_t(l));
      set_texel(l, t, int(rng.below(std::uint64_t(e.width()) * std::uint64_t(e.height()))));
    }
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
          sample_exemplar(e, 0.5 * x + i, 0.5 * y + m, wrap, o);
          for (int c = 0; c < C_; ++c) o[c] *= lay.coarse_w[std::size_t(k)];
          o += C_;
        }
    }
  }

  /// Walks the sample grid of radius r at spacing hh around p and copies the
  /// values of the level-`lv` texels the samples land in.
  /// The texels of level `lv` the (2r+1)^2 samples at spacing hh around each
  /// texel of level l land in: walked once per level (in parallel) and read
  /// by every pass (the walks are most of the work on fine meshes, where
  /// coarse neighbourhoods cross many faces).
  std::vector<std::int32_t> landing_table(int l, int lv, int r, double hh) const {
    const int per = (2 * r + 1) * (2 * r + 1);
    const TexelGrid& g = grids_[std::size_t(l)];
    const TexelGrid& to = grids_[std::size_t(lv)];
    std::vector<std::int32_t> tab(g.size() * std::size_t(per));
    StageProgress progress(ctx_, "surface neighbourhoods, level " + std::to_string(l), 0.0, 1.0, g.size());
    parallel_chunks(g.size(), 512, progress, [&](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) {
        const SurfacePoint p = g.centre(t);
        const std::size_t t0 = frames_.grid.texel(p);
        const Eigen::Vector3d a = frames_.t1[t0].cast<double>() * hh, bb = frames_.t2[t0].cast<double>() * hh;
        // Marching: each row starts one step from the previous row's start,
        // each sample one step from its neighbour towards the centre column
        // (the walk re-projects the step into each tangent plane). Walking
        // every sample from the centre cost 2-3x more face crossings.
        const int side = 2 * r + 1;
        std::int32_t* row = tab.data() + t * std::size_t(per);
        auto march_row = [&](SurfacePoint start, int m) {
          row[(m + r) * side + r] = std::int32_t(to.texel(start));
          for (int dir : {1, -1}) {
            SurfacePoint q = start;
            for (int i = 1; i <= r; ++i) {
              walk_cached(surface_, frames_, q, double(dir) * a);
              row[(m + r) * side + r + dir * i] = std::int32_t(to.texel(q));
            }
          }
        };
        march_row(p, 0);
        for (int dir : {1, -1}) {
          SurfacePoint start = p;
          for (int m = 1; m <= r; ++m) {
            walk_cached(surface_, frames_, start, -double(dir) * bb);
            march_row(start, dir * m);
          }
        }
      }
    });
    return tab;
  }

  void gather(const std::int32_t* landing, int lv, int r, const std::vector<float>& w, float*& o,
              const std::vector<char>* visited = nullptr) const {
    const std::vector<float>& vals = values_[std::size_t(lv)];
    const int per = (2 * r + 1) * (2 * r + 1);
    for (int k = 0; k < per; ++k) {
      const std::size_t tq = std::size_t(landing[k]);
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

  /// Walks the neighbourhoods of level l (current and coarser) once.
  void prepare_level(int l) {
    const int fr = opt_.fine_neighborhood / 2, cr = opt_.coarse_neighborhood / 2;
    fine_nb_ = landing_table(l, l, fr, spacing(l));
    coarse_nb_ = l + 1 < levels_ ? landing_table(l, l + 1, cr, spacing(l + 1)) : std::vector<std::int32_t>{};
  }

  /// Among k (distance, pixel) pairs sorted by distance: a random one within
  /// (1 + tolerance) of the best.
  int pick(std::vector<std::pair<float, int>>& best, std::size_t t, std::uint64_t stream) const {
    std::sort(best.begin(), best.end());
    const float limit = best[0].first * float(1.0 + opt_.knn_tolerance);
    std::size_t n = 1;
    while (n < best.size() && best[n].first <= limit) ++n;
    IndexRng rng(opt_.seed, t, stream);
    return best[std::size_t(rng.below(n))].second;
  }

  void run_pass(int l, const Layout& lay, bool brute_force, std::uint64_t stream) {
    const Image& e = ex_[std::size_t(l)];
    const int D = lay.dims();
    const int P = e.width() * e.height();
    RowMatrixXf X(P, D);
    for (int y = 0; y < e.height(); ++y)
      for (int x = 0; x < e.width(); ++x) exemplar_feature(l, x, y, lay, X.row(y * e.width() + x).data());

    const std::size_t n = grids_[std::size_t(l)].size();
    std::vector<float> next_values(n * std::size_t(C_));
    std::vector<int> next_src(n);
    if (values_[std::size_t(l)].empty()) {
      values_[std::size_t(l)].assign(n * std::size_t(C_), 0.0f);
      src_[std::size_t(l)].assign(n, 0);
    }
    const int k = std::min(opt_.knn, P);
    StageProgress progress(ctx_, "multiscale level " + std::to_string(l) + (lay.fine ? (lay.coarse ? " pass 2" : " coarsest") : " pass 1"),
                           0.0, 1.0, n);
    auto store = [&](std::size_t t, int pixel) {
      next_src[t] = pixel;
      const float* p = e.data() + std::size_t(pixel) * std::size_t(C_);
      std::copy(p, p + C_, next_values.begin() + std::ptrdiff_t(t * std::size_t(C_)));
    };
    if (brute_force) {
      // The coarsest level, in synthesis order and in place: the first pass
      // compares only the texels visited so far (causal, from random noise
      // the others), the second the full neighbourhood. Jacobi passes from
      // noise stayed noise.
      const bool causal = stream == 100;
      std::vector<char> visited(n, causal ? 0 : 1);
      std::vector<float> q(static_cast<std::size_t>(D));
      std::vector<std::pair<float, int>> all(static_cast<std::size_t>(P));
      const std::vector<std::size_t> order = synthesis_order(surface_, grids_[std::size_t(l)]);
      for (std::size_t i = 0; i < n; ++i) {
        if ((i & 255) == 0) progress.check();
        const std::size_t t = order[i];
        target_feature(l, t, lay, q.data(), &visited);
        bool any = false;
        for (int d = 0; d < D && !any; ++d) any = !std::isnan(q[std::size_t(d)]);
        if (any) {
          for (int p = 0; p < P; ++p) {
            const float* x = X.row(p).data();
            float s2 = 0;
            for (int d = 0; d < D; ++d)
              if (!std::isnan(q[std::size_t(d)])) s2 += (x[d] - q[std::size_t(d)]) * (x[d] - q[std::size_t(d)]);
            all[std::size_t(p)] = {std::sqrt(s2), p};
          }
          std::partial_sort(all.begin(), all.begin() + k, all.end());
          std::vector<std::pair<float, int>> best(all.begin(), all.begin() + k);
          set_texel(l, t, pick(best, t, stream));
        }
        visited[t] = 1;
      }
      progress.advance(n);
      return;
    } else {
      const search::Pca pca = search::fit_pca(X, opt_.pca_variance, opt_.max_pca_dims);
      const RowMatrixXf Y = pca.project(X);
      using Tree = nanoflann::KDTreeEigenMatrixAdaptor<RowMatrixXf, -1, nanoflann::metric_L2_Simple>;
      Tree tree(int(Y.cols()), std::cref(Y), 16);
      tree.index->buildIndex();
      auto search_one = [&](std::size_t t, RowMatrixXf& q, std::vector<Eigen::Index>& idx, std::vector<float>& d2) {
        target_feature(l, t, lay, q.data());
        const RowMatrixXf qp = pca.project(q);
        nanoflann::KNNResultSet<float, Eigen::Index> result(static_cast<std::size_t>(k));
        result.init(idx.data(), d2.data());
        tree.index->findNeighbors(result, qp.data(), nanoflann::SearchParams(32, 0.0f));
        std::vector<std::pair<float, int>> best;
        for (std::size_t i = 0; i < result.size(); ++i) best.push_back({std::sqrt(d2[i]), int(idx[i])});
        return pick(best, t, stream);
      };
      if (lay.fine) {
        // Current-level neighbourhoods: in synthesis order, each texel seeing
        // the ones already updated in this pass (the paper's scanline order);
        // Jacobi updates of all texels at once did not converge to coherent
        // patches (window distance 0.74 vs 0.38 for coherent on a flat grid).
        RowMatrixXf q(1, D);
        std::vector<Eigen::Index> idx(static_cast<std::size_t>(k));
        std::vector<float> d2(static_cast<std::size_t>(k));
        next_values = values_[std::size_t(l)];
        next_src = src_[std::size_t(l)];
        values_[std::size_t(l)].swap(next_values);  // read and write the same buffer
        src_[std::size_t(l)].swap(next_src);
        const std::vector<std::size_t> order = synthesis_order(surface_, grids_[std::size_t(l)]);
        for (std::size_t i = 0; i < n; ++i) {
          if ((i & 1023) == 0) progress.check();
          const std::size_t t = order[i];
          const int pixel = search_one(t, q, idx, d2);
          src_[std::size_t(l)][t] = pixel;
          const float* p = e.data() + std::size_t(pixel) * std::size_t(C_);
          std::copy(p, p + C_, values_[std::size_t(l)].begin() + std::ptrdiff_t(t * std::size_t(C_)));
        }
        progress.advance(n);
        return;
      }
      parallel_chunks(n, 256, progress, [&](std::size_t b, std::size_t end) {
        RowMatrixXf q(1, D);
        std::vector<Eigen::Index> idx(static_cast<std::size_t>(k));
        std::vector<float> d2(static_cast<std::size_t>(k));
        for (std::size_t t = b; t < end; ++t) store(t, search_one(t, q, idx, d2));
      });
    }
    values_[std::size_t(l)].swap(next_values);
    src_[std::size_t(l)].swap(next_src);
  }

  const SubdivSurface& surface_;
  const TexelFrames& frames_;
  const SurfaceSynthesisOptions& opt_;
  double h_;
  ExecContext* ctx_;
  int C_;
  int levels_ = 1;
  std::vector<Image> ex_;
  std::vector<TexelGrid> grids_;
  std::vector<std::vector<float>> values_;
  std::vector<std::vector<int>> src_;
  std::vector<std::int32_t> fine_nb_, coarse_nb_;  // landing tables of the level being synthesized
};

}  // namespace

void run_multiscale(const SubdivSurface& surface, const TexelFrames& frames, const Image& exemplar,
                    const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx) {
  MultiscaleSolver solver(surface, frames, exemplar, opt, out.sample_spacing, ctx);
  solver.run(out);
}

}  // namespace exsynth::surface
