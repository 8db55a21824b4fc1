#include "solid/level_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"
#include "search/exhaustive_nearest.hpp"
#include "solid/candidate_scoring.hpp"

namespace exsynth::solid {

constexpr std::size_t kBatch = 256;  // sparse voxels gathered and PCA-projected together (one GEMM)
constexpr int kBlock = 8;            // optimisation visits blocks of kBlock^3 voxels in random order

LevelSolver::LevelSolver(Volume& texture, std::array<const ExemplarIndex*, 3> views, const Volume& constraint,
                         const TextureOptimizationOptions& opt, bool wrap, std::uint64_t seed,
                         std::vector<float> channel_lo, std::vector<float> channel_hi)
    : tex_(texture), constraint_(constraint), opt_(opt), wrap_(wrap), seed_(seed), C_(texture.channels()),
      H_(int(channel_lo.size())),
      n_(opt.neighborhood), lo_(opt.neighborhood / 2), channel_lo_(std::move(channel_lo)),
      channel_hi_(std::move(channel_hi)) {
  const int dims[3] = {tex_.nx(), tex_.ny(), tex_.nz()};
  // wrapped_[a][x + n] for x in [-n, dims[a] + n): wrapped, or clamped when
  // not tileable. axis_cover_: for each coordinate, the window offsets d whose
  // sparse voxel x - (d - lo) exists (wrapped, or inside when not tileable).
  for (int a = 0; a < 3; ++a) {
    wrapped_[a].resize(std::size_t(dims[a]) + 2 * n_);
    for (int x = -n_; x < dims[a] + n_; ++x)
      wrapped_[a][x + n_] = wrap_ ? ((x % dims[a]) + dims[a]) % dims[a] : std::clamp(x, 0, dims[a] - 1);
    AxisCover& ac = axis_cover_[a];
    ac.count.assign(std::size_t(dims[a]), 0);
    ac.d.assign(std::size_t(dims[a]) * n_, 0);
    ac.s.assign(std::size_t(dims[a]) * n_, 0);
    for (int x = 0; x < dims[a]; ++x)
      for (int d = 0; d < n_; ++d) {
        const int y = x - d + lo_;
        const int c = wrap_ ? ((y % dims[a]) + dims[a]) % dims[a] : (y < 0 || y >= dims[a] ? -1 : y);
        if (c < 0 || (c & 1)) continue;
        const std::size_t k = std::size_t(x) * n_ + std::size_t(ac.count[x]++);
        ac.d[k] = d;
        ac.s[k] = c / 2;
      }
    max_cover_ = std::max(max_cover_, *std::max_element(ac.count.begin(), ac.count.end()));
  }
  for (int i = 0; i < 3; ++i) {
    View& w = views_[i];
    w.ex = views[i];
    if (!w.ex) continue;
    const SliceAxes& s = kSlices[i];
    w.na = dims[s.axis];
    w.nu = (dims[s.u] + 1) / 2;
    w.nv = (dims[s.v] + 1) / 2;
    w.match.assign(w.size(), -1);
    w.weight.assign(w.size(), 1.0f);
    if (opt_.search == SolidSearch::KdTree) w.kd = std::make_unique<search::KdTree>(w.ex->coefficients());
    if (opt_.search == SolidSearch::KCoherence) {
      auto it = std::find_if(scoring_.begin(), scoring_.end(), [&](const ScoringTable& b) { return b.ex == w.ex; });
      w.scoring = int(it - scoring_.begin());
      if (it == scoring_.end()) scoring_.push_back(scoring_table(*w.ex));
    }
  }
}

LevelSolver::ScoringTable LevelSolver::scoring_table(const ExemplarIndex& ex) {
  const RowMatrixXf& rows = ex.coefficients();  // columns padded to a multiple of 8 (ExemplarIndex)
  ScoringTable b;
  b.ex = &ex;
  const std::size_t count = std::size_t(rows.rows()), cols = std::size_t(rows.cols());
  const std::size_t stride = (cols + 15) / 16 * 16;
  b.storage.assign(stride * count + 16, 0.0f);
  const std::uintptr_t addr = reinterpret_cast<std::uintptr_t>(b.storage.data());
  float* base = b.storage.data() + ((64 - addr % 64) % 64) / sizeof(float);
  b.rows = {base, stride};
  for (std::size_t j = 0; j < count; ++j) std::copy_n(rows.row(Eigen::Index(j)).data(), cols, base + j * stride);
  b.centre.resize(count);
  for (std::size_t j = 0; j < count; ++j) b.centre[j] = {ex.centre_u(int(j)), ex.centre_v(int(j))};
  return b;
}

LevelSolver::~LevelSolver() = default;

// Progress units: search batches of kBatch sparse voxels; optimisation blocks.
std::size_t LevelSolver::search_units() const {
  std::size_t units = 0;
  for (const View& w : views_) units += w.ex ? (w.size() + kBatch - 1) / kBatch : 0;
  return units;
}
std::size_t LevelSolver::optimize_units() const {
  return std::size_t((tex_.nx() + kBlock - 1) / kBlock) * ((tex_.ny() + kBlock - 1) / kBlock) *
         ((tex_.nz() + kBlock - 1) / kBlock);
}

void LevelSolver::gather(int i, std::size_t sparse, float* row) const {
  const View& w = views_[i];
  const SliceAxes& s = kSlices[i];
  int p[3];
  p[s.axis] = int(sparse / (std::size_t(w.nu) * w.nv));
  p[s.v] = 2 * int((sparse / w.nu) % w.nv);
  p[s.u] = 2 * int(sparse % w.nu);
  const std::size_t stride[3] = {1, std::size_t(tex_.nx()), std::size_t(tex_.nx()) * tex_.ny()};
  const int* wu = wrapped_[s.u].data() + n_ + p[s.u] - lo_;
  const int* wv = wrapped_[s.v].data() + n_ + p[s.v] - lo_;
  const float* base = tex_.data() + std::size_t(p[s.axis]) * stride[s.axis] * C_;
  if (C_ == 3) {  // RGB: three moves per texel (the loop below became a memmove call per texel: perf)
    for (int dv = 0; dv < n_; ++dv) {
      const float* line = base + std::size_t(wv[dv]) * stride[s.v] * 3;
      for (int du = 0; du < n_; ++du, row += 3) {
        const float* src = line + std::size_t(wu[du]) * stride[s.u] * 3;
        row[0] = src[0], row[1] = src[1], row[2] = src[2];
      }
    }
    return;
  }
  for (int dv = 0; dv < n_; ++dv) {
    const float* line = base + std::size_t(wv[dv]) * stride[s.v] * C_;
    for (int du = 0; du < n_; ++du) {
      const float* src = line + std::size_t(wu[du]) * stride[s.u] * C_;
      for (int c = 0; c < C_; ++c) *row++ = src[c];  // C is small: a loop beats memmove
    }
  }
}

void LevelSolver::inherit_matches(const LevelSolver& coarser) {
  for (int i = 0; i < 3; ++i) {
    View& w = views_[i];
    const View& c = coarser.views_[i];
    if (!w.ex || !c.ex) continue;
    for (std::size_t sp = 0; sp < w.size(); ++sp) {
      const int a = int(sp / (std::size_t(w.nu) * w.nv)), sv = int((sp / w.nu) % w.nv), su = int(sp % w.nu);
      // Fine voxel (a, 2su, 2sv) sits on coarse voxel (a/2, su, sv); the
      // nearest coarse sparse voxel is (su/2, sv/2), offset by (su%2, sv%2).
      const int ca = std::min(a / 2, c.na - 1), csu = std::min(su / 2, c.nu - 1), csv = std::min(sv / 2, c.nv - 1);
      const int j = c.match[(std::size_t(ca) * c.nv + csv) * c.nu + csu];
      if (j < 0) continue;
      const int u = 2 * (c.ex->centre_u(j) + (su - 2 * csu)), v = 2 * (c.ex->centre_v(j) + (sv - 2 * csv));
      w.match[sp] = w.ex->clamped_index(u, v);
    }
  }
}

double LevelSolver::search(int iteration, bool exhaustive, StageProgress& progress) {
  const int D = n_ * n_ * C_;
  const float r = float(opt_.r);
  double energy_sum = 0.0;
  std::size_t energy_count = 0;
  for (int i = 0; i < 3; ++i) {
    View& w = views_[i];
    if (!w.ex) continue;
    const ExemplarIndex& ex = *w.ex;
    static const ScoringTable kNone;
    const ScoringTable& table = w.scoring >= 0 ? scoring_[std::size_t(w.scoring)] : kNone;
    // Matches are read from the previous round and written to a new one, so
    // the result does not depend on the order chunks run in.
    std::vector<std::int32_t> next(w.size());
    std::vector<float> energy(w.size());
    // Visit order: for the x-view the slice axis x is the volume's unit
    // stride, so walking along it first lets consecutive gathers share cache
    // lines (the other views already walk along x as their u axis).
    const bool along_axis = kSlices[i].axis == 0;
    auto sparse_of = [&](std::size_t k) -> std::size_t {
      if (!along_axis) return k;
      const std::size_t a = k % w.na, rest = k / w.na;  // rest = sv * nu + su
      return std::size_t(a) * w.nv * w.nu + rest;
    };
    const std::size_t batch = kBatch;
    const std::size_t batches = (w.size() + batch - 1) / batch;
    // Every window (in PCA space) is a candidate: one GEMM per batch.
    const bool all_windows = exhaustive && opt_.search != SolidSearch::Exact && opt_.search != SolidSearch::KdTree;
    std::optional<search::ExhaustiveNearest> every_window;
    if (all_windows) every_window.emplace(ex.coefficients());
    parallel_chunks(batches, 1, progress, [&](std::size_t b0, std::size_t b1) {
      RowMatrixXf products;  // the exhaustive search's q . c, per batch
      RowMatrixXf x(batch, D), centred(opt_.search != SolidSearch::Exact ? batch : 0, D);
      RowMatrixXf y(opt_.search != SolidSearch::Exact ? batch : 0, ex.pca().basis.cols());
      std::vector<std::size_t> order(batch);
      // stamp[j] = the last query that proposed candidate j: O(1) dedupe.
      // Coherent neighbours mostly propose the same candidates. The last
      // slot is a sink for shifts that leave the exemplar: it always holds
      // the current query, so they are never taken.
      const bool coherent_search = opt_.search == SolidSearch::KCoherence;
      const int sink = ex.count();
      std::vector<std::uint32_t> stamp(coherent_search ? std::size_t(ex.count()) + 1 : 0, 0);
      std::uint32_t query = 0;
      const int k_sim = ex.coherence_k();
      const std::size_t max_candidates = 9 * std::size_t(k_sim + 1) + std::size_t(std::max(opt_.random_candidates, 1));
      // Sparse voxel sp as (slice, v, u): computed once per query.
      struct Slot {
        int a, sv, su;
      };
      auto slot_of = [&](std::size_t sp) {
        return Slot{int(sp / (std::size_t(w.nu) * w.nv)), int((sp / w.nu) % w.nv), int(sp % w.nu)};
      };
      // The match of a slot's neighbour (du, dv) in its slice, or negative
      // (outside a clamped solid, or no match yet).
      auto neighbour_match = [&](const Slot& at, int du, int dv) -> int {
        int nu = at.su + du, nv = at.sv + dv;
        if (wrap_) {  // |du|, |dv| <= 1: one step wraps (no division)
          nu = nu < 0 ? nu + w.nu : (nu >= w.nu ? nu - w.nu : nu);
          nv = nv < 0 ? nv + w.nv : (nv >= w.nv ? nv - w.nv : nv);
        } else if (nu < 0 || nv < 0 || nu >= w.nu || nv >= w.nv) {
          return -1;
        }
        return w.match[(std::size_t(at.a) * w.nv + nv) * w.nu + nu];
      };
      // k-coherence: each sparse neighbour's match, shifted to this voxel,
      // and that match's k most similar neighbourhoods, shifted likewise;
      // plus a few random ones to escape local minima. Branch-free appends
      // (the dedupe's branch was unpredictable; perf) in the same order.
      auto candidates = [&](std::size_t sp, Candidates& out) {
        out.idx.resize(max_candidates);
        int* cand = out.idx.data();
        std::size_t n = 0;
        const std::uint32_t now = ++query;  // stamps start at 0, queries at 1; a local: the stores alias
        std::uint32_t* stamps = stamp.data();
        const int ks = k_sim;
        stamps[sink] = now;
        const Slot at = slot_of(sp);
        for (int dv = -1; dv <= 1; ++dv)
          for (int du = -1; du <= 1; ++du) {
            const int j = neighbour_match(at, du, dv);
            if (j < 0) continue;
            auto add_shifted = [&](int jj) {
              const Centre cc = table.centre[std::size_t(jj < 0 ? 0 : jj)];
              const int c = jj < 0 ? -1 : ex.index_of(cc.u - 2 * du, cc.v - 2 * dv);
              const std::size_t slot = std::size_t(c < 0 ? sink : c);
              cand[n] = c;
              n += stamps[slot] != now;
              stamps[slot] = now;
            };
            add_shifted(j);
            const std::int32_t* sim = ex.similar(j);
            for (int q = 0; q < ks; ++q) add_shifted(sim[q]);
          }
        IndexRng rng(seed_, sp, std::uint64_t(iteration) * 3 + i);
        for (int q = 0; q < opt_.random_candidates || n == 0; ++q) cand[n++] = int(rng.below(ex.count()));
        out.n = n;
        // Candidates sit at scattered exemplar positions: request their first
        // coefficients while the previous queries are scored.
        for (std::size_t m = 0; m < n; ++m) __builtin_prefetch(table.rows.row(cand[m]));
      };
      // One query before its candidates are generated: request the similar
      // sets and centres of its neighbours' matches (the generation's loads
      // are a dependent chain: match -> similar set -> centre -> stamp).
      auto warm = [&](std::size_t sp) {
        const Slot at = slot_of(sp);
        for (int dv = -1; dv <= 1; ++dv)
          for (int du = -1; du <= 1; ++du) {
            const int j = neighbour_match(at, du, dv);
            if (j < 0) continue;
            __builtin_prefetch(ex.similar(j));
            __builtin_prefetch(table.centre.data() + j);
          }
      };
      // Candidates are generated kAhead queries before they are scored, so
      // their prefetched coefficients have arrived (one query ahead, the
      // first coefficient load was a third of the scoring's time in perf).
      constexpr std::size_t kAhead = 2;
      Candidates cand_of[kAhead + 1];
      std::vector<int> best_of(batch);
      std::vector<float> first_block;
      for (std::size_t b = b0; b < b1; ++b) {
        const std::size_t first = b * batch, rows = std::min(batch, w.size() - first);
        for (std::size_t k = 0; k < rows; ++k) order[k] = sparse_of(first + k);
        for (std::size_t k = 0; k < rows; ++k) gather(i, order[k], x.row(Eigen::Index(k)).data());
        // PCA projection into buffers kept across batches: Pca::project on
        // x.topRows() copied the batch, then centred it into a temporary, and
        // allocated its result (same operations; ~5 % of the CPU in perf).
        if (opt_.search != SolidSearch::Exact) {
          const Eigen::Index r = Eigen::Index(rows);
          centred.topRows(r) = x.topRows(r).rowwise() - ex.pca().mean;
          y.topRows(r).noalias() = centred.topRows(r) * ex.pca().basis;
        }
        if (all_windows) every_window->nearest(y, Eigen::Index(rows), best_of.data(), products);
        const bool coherence = opt_.search == SolidSearch::KCoherence && !exhaustive;
        if (coherence)
          for (std::size_t k = 0; k < std::min(kAhead, rows); ++k) candidates(order[k], cand_of[k % (kAhead + 1)]);
        for (std::size_t k = 0; k < rows; ++k) {
          const std::size_t sp = order[k];
          int best = -1;
          if (opt_.search == SolidSearch::Exact) {
            float bd = std::numeric_limits<float>::max();
            for (int j = 0; j < ex.count(); ++j) {
              const float d = (ex.neighbourhoods().row(j) - x.row(Eigen::Index(k))).squaredNorm();
              if (d < bd || best < 0) bd = d, best = j;
            }
          } else if (opt_.search == SolidSearch::KdTree) {
            best = int(w.kd->nearest(y.row(Eigen::Index(k)).data(), float(opt_.ann_eps)));
          } else if (exhaustive) {
            best = best_of[k];
          } else {
            // The next query's candidates first (their loads overlap this
            // query's scoring; reads only the previous round's matches).
            if (k + kAhead + 1 < rows) warm(order[k + kAhead + 1]);
            if (k + kAhead < rows) candidates(order[k + kAhead], cand_of[(k + kAhead) % (kAhead + 1)]);
            const Candidates& cand_list = cand_of[k % (kAhead + 1)];
            const int* cand = cand_list.idx.data();
            const std::size_t cand_count = cand_list.n;
            best = nearest_candidate(y.row(Eigen::Index(k)).data(), int(y.cols()), table.rows, cand, cand_count,
                                     first_block);
            if (best < 0) best = cand[0];  // every distance non-finite: never index with -1
          }
          next[sp] = best;
          best_of[k] = best;
        }
        // The matches' full-dimension distances, in a pass of their own: each
        // reads a scattered D-float exemplar row, requested kRowAhead matches
        // before (inline after the scoring, its first load stalled: perf).
        constexpr std::size_t kRowAhead = 2;
        const std::size_t row_bytes = std::size_t(D) * sizeof(float);
        auto prefetch_row = [&](std::size_t k) {
          const char* p = reinterpret_cast<const char*>(ex.neighbourhoods().row(best_of[k]).data());
          for (std::size_t o = 0; o < row_bytes; o += 64) __builtin_prefetch(p + o);
        };
        for (std::size_t k = 0; k < std::min(kRowAhead, rows); ++k) prefetch_row(k);
        for (std::size_t k = 0; k < rows; ++k) {
          if (k + kRowAhead < rows) prefetch_row(k + kRowAhead);
          const std::size_t sp = order[k];
          const float d2 = (ex.neighbourhoods().row(best_of[k]) - x.row(Eigen::Index(k))).squaredNorm();
          energy[sp] = std::pow(d2, 0.5f * r);
          // IRLS for the |.|^r energy; the floor keeps exact matches finite.
          w.weight[sp] = std::pow(std::max(d2, 1e-6f), 0.5f * (r - 2.0f));
        }
      }
    });
    w.match.swap(next);
    for (float e : energy) energy_sum += e;
    energy_count += energy.size();
  }
  return energy_count ? energy_sum / double(energy_count) : 0.0;
}

// Target histogram: the mean of the active views' exemplar histograms,
// scaled so that a uniform histogram is 1 in every bin.
std::vector<double> LevelSolver::target_histogram() const {
  const int bins = opt_.histogram_bins;
  std::vector<double> target(std::size_t(H_) * bins, 0.0);
  int active = 0;
  for (const View& w : views_)
    if (w.ex) {
      ++active;
      for (int c = 0; c < H_; ++c)
        for (int b = 0; b < bins; ++b) target[std::size_t(c) * bins + b] += w.ex->histogram(c, b);
    }
  for (double& t : target) t *= double(bins) / active;
  return target;
}

std::vector<std::int64_t> LevelSolver::solid_histogram() const {
  const int bins = opt_.histogram_bins;
  std::vector<std::int64_t> counts(std::size_t(H_) * bins, 0);
  const float* d = tex_.data();
  for (std::size_t v = 0; v < tex_.voxel_count(); ++v)
    for (int c = 0; c < H_; ++c) ++counts[std::size_t(c) * bins + value_bin(d[v * C_ + c], channel_lo_[c], channel_hi_[c], bins)];
  return counts;
}

// Per exemplar pixel: (1 + sum_c max(0, H_solid - H_exemplar))^-p at its bins
// (all 1 without histogram matching). The excess sums over channels, so many
// channels would multiply the re-weighting: the exponent is as measured on RGB
// for up to 3 channels and scaled by 3 / C above (6 channels: half).
// Writes the factors into slot 0 of tables.texel's pixels (the texels follow).
void LevelSolver::histogram_factors(const std::vector<std::int64_t>& counts, const std::vector<double>& target,
                                    OptimizeTables& tables) const {
  const int bins = opt_.histogram_bins;
  const double strength = H_ <= 3 || opt_.histogram_strength == 1.0 ? opt_.histogram_strength : opt_.histogram_strength * 3.0 / H_;
  const double total = double(tex_.voxel_count());
  const std::size_t stride = std::size_t(C_) + 1;
  for (std::size_t e = 0; e < tables.texel.size(); ++e) {
    const ExemplarIndex& ex = *tables.texel_ex[e];
    const Image& img = ex.image();
    float* texel = tables.texel[e].data();
    if (!opt_.histogram_matching) {
      for (std::size_t p = 0; p < img.pixel_count(); ++p) texel[p * stride] = 1.0f;
      continue;
    }
    for (std::size_t p = 0; p < img.pixel_count(); ++p) {
      double excess = 0.0;
      for (int c = 0; c < H_; ++c) {
        const std::size_t k = std::size_t(c) * bins + ex.bin(p, c);
        excess += std::max(0.0, counts[k] * bins / total - target[k]);
      }
      texel[p * stride] = float(strength == 1.0 ? 1.0 / (1.0 + excess) : std::pow(1.0 + excess, -strength));
    }
  }
}

namespace {

// Mean shift from the weighted mean `acc` with a shrinking Gaussian bandwidth:
// converges to the dominant cluster of the C-channel `values` instead of
// blurring modes. `mode` is scratch of C floats.
void mean_shift(const std::vector<float>& values, const std::vector<float>& weights, float wsum, int C,
                std::vector<float>& acc, std::vector<float>& mode) {
  float var = 0.0f;
  for (std::size_t q = 0; q < weights.size(); ++q)
    for (int c = 0; c < C; ++c) var += weights[q] * (values[q * C + c] - acc[c]) * (values[q * C + c] - acc[c]);
  float h2 = std::max(var / wsum, 1e-8f);
  for (int step = 0; step < 4; ++step, h2 *= 0.25f) {
    std::fill(mode.begin(), mode.end(), 0.0f);
    float ksum = 0.0f;
    for (std::size_t q = 0; q < weights.size(); ++q) {
      float d2 = 0.0f;
      for (int c = 0; c < C; ++c) d2 += (values[q * C + c] - acc[c]) * (values[q * C + c] - acc[c]);
      const float kq = weights[q] * std::exp(-0.5f * d2 / h2);
      for (int c = 0; c < C; ++c) mode[c] += kq * values[q * C + c];
      ksum += kq;
    }
    if (ksum < 1e-12f) break;
    for (int c = 0; c < C; ++c) acc[c] = mode[c] / ksum;
  }
}

}  // namespace

// The weighted mean of the exemplar texels the matched windows of every
// active view put on voxel p (IRLS weight x histogram factor), into
// scratch.acc; false when no window covers p. With mean shift, the texels and
// weights are kept in scratch for it.
bool LevelSolver::blend_voxel(const int p[3], const OptimizeTables& tables, VoxelScratch& scratch) const {
  // RGB, and RGB with the feature-distance channel (the solids' default).
  if (C_ == 3 && !opt_.mean_shift) return blend_voxel_channels<3>(p, tables, scratch);
  if (C_ == 4 && !opt_.mean_shift) return blend_voxel_channels<4>(p, tables, scratch);
  return blend_voxel_channels<0>(p, tables, scratch);
}

// kChannels > 0: that many channels, summed in locals (registers; through
// scratch.acc every add waited on the previous store: perf), no mean shift.
// 0: C_ channels, with mean shift when asked. Same sums in the same order.
template <int kChannels>
bool LevelSolver::blend_voxel_channels(const int p[3], const OptimizeTables& tables, VoxelScratch& scratch) const {
  constexpr bool fixed = kChannels > 0;
  const int C = fixed ? kChannels : C_;
  float local[fixed ? kChannels : 1] = {};
  float* acc = fixed ? local : scratch.acc.data();
  if (!fixed) std::fill(scratch.acc.begin(), scratch.acc.end(), 0.0f);
  const bool keep = !fixed && opt_.mean_shift;
  float wsum = 0.0f;
  scratch.values.clear();
  scratch.weights.clear();
  for (int i = 0; i < 3; ++i) {
    const View& w = views_[i];
    if (!w.ex) continue;
    const SliceAxes& s = kSlices[i];
    const Image& img = w.ex->image();
    const Covering cov = cover(p, s);
    const std::size_t slice = std::size_t(p[s.axis]) * w.nv;
    const SparseWindow* window = tables.window[i].data();
    const float* texel = tables.texel[std::size_t(tables.texel_of[i])].data();
    const std::size_t stride = std::size_t(C) + 1;
    for (int a = 0; a < cov.nv; ++a) {
      const std::size_t row = (slice + cov.sv[a]) * w.nu;
      const std::size_t pix_dv = std::size_t(cov.dv[a]) * img.width();
      for (int b = 0; b < cov.nu; ++b) {
        const SparseWindow& sw = window[row + cov.su[b]];
        if (sw.corner < 0) continue;
        const std::size_t pix = std::size_t(sw.corner) + pix_dv + cov.du[b];
        const float* t = texel + pix * stride;
        const float wt = sw.weight * t[0];
        const float* e = t + 1;
        for (int c = 0; c < C; ++c) acc[c] += wt * e[c];
        wsum += wt;
        if (keep) {
          scratch.values.insert(scratch.values.end(), e, e + C);
          scratch.weights.push_back(wt);
        }
      }
    }
  }
  if (wsum <= 0.0f) return false;
  for (int c = 0; c < C; ++c) acc[c] /= wsum;
  if (fixed) std::copy(local, local + C, scratch.acc.begin());
  if (keep && scratch.weights.size() > 1) mean_shift(scratch.values, scratch.weights, wsum, C_, scratch.acc, scratch.mode);
  return true;
}

void LevelSolver::optimize(int iteration, StageProgress& progress) {
  const int dims[3] = {tex_.nx(), tex_.ny(), tex_.nz()};
  const int bins = opt_.histogram_bins;
  const bool hist = opt_.histogram_matching;
  const std::vector<double> target = hist ? target_histogram() : std::vector<double>();
  std::vector<std::int64_t> counts = hist ? solid_histogram() : std::vector<std::int64_t>();

  // Blocks of voxels in a seeded random order, processed in groups: within a
  // group in parallel against the histogram as it was at the group's start,
  // then the histogram takes the group's changes. Deterministic for any
  // thread count; "random order with histogram updates" at block granularity.
  const int B = kBlock;
  const int bx = (dims[0] + B - 1) / B, by = (dims[1] + B - 1) / B, bz = (dims[2] + B - 1) / B;
  const std::size_t blocks = std::size_t(bx) * by * bz;
  std::vector<std::size_t> order(blocks);
  std::iota(order.begin(), order.end(), std::size_t(0));
  IndexRng shuffle(seed_, std::uint64_t(iteration), 0xB10C);
  for (std::size_t k = blocks; k > 1; --k) std::swap(order[k - 1], order[shuffle.below(k)]);
  const std::size_t groups = std::min<std::size_t>(blocks, 16);

  // The blend's tables (see OptimizeTables): per sparse voxel its window's
  // top-left texel and weight; per exemplar pixel its values (the factor
  // slot is written per group by histogram_factors).
  OptimizeTables tables;
  const std::size_t stride = std::size_t(C_) + 1;
  for (int i = 0; i < 3; ++i) {
    const View& w = views_[i];
    if (!w.ex) continue;
    const Image& img = w.ex->image();
    tables.window[i].resize(w.size());
    for (std::size_t sp = 0; sp < w.size(); ++sp) {
      const int j = w.match[sp];
      tables.window[i][sp] = {j < 0 ? -1 : (w.ex->centre_v(j) - lo_) * img.width() + (w.ex->centre_u(j) - lo_), w.weight[sp]};
    }
    const auto shared = std::find(tables.texel_ex.begin(), tables.texel_ex.end(), w.ex);
    tables.texel_of[i] = int(shared - tables.texel_ex.begin());
    if (shared != tables.texel_ex.end()) continue;
    tables.texel_ex.push_back(w.ex);
    std::vector<float>& texel = tables.texel.emplace_back(img.pixel_count() * stride, 1.0f);
    for (std::size_t p = 0; p < img.pixel_count(); ++p)
      std::copy(img.data() + p * C_, img.data() + (p + 1) * C_, texel.data() + p * stride + 1);
  }

  std::vector<std::vector<std::int64_t>> deltas;
  for (std::size_t g = 0; g < groups; ++g) {
    histogram_factors(counts, target, tables);
    const std::size_t g0 = g * blocks / groups, g1 = (g + 1) * blocks / groups;
    deltas.assign(g1 - g0, {});
    parallel_chunks(g1 - g0, 1, progress, [&](std::size_t k0, std::size_t k1) {
      VoxelScratch scratch{std::vector<float>(C_), std::vector<float>(C_), {}, {}};
      std::vector<float>& acc = scratch.acc;
      for (std::size_t k = k0; k < k1; ++k) {
        std::vector<std::int64_t>& delta = deltas[k];
        if (hist) delta.assign(std::size_t(H_) * bins, 0);
        const std::size_t blk = order[g0 + k];
        const int x0 = int(blk % bx) * B, y0 = int((blk / bx) % by) * B, z0 = int(blk / (std::size_t(bx) * by)) * B;
        for (int z = z0; z < std::min(z0 + B, dims[2]); ++z)
          for (int y = y0; y < std::min(y0 + B, dims[1]); ++y)
            for (int x = x0; x < std::min(x0 + B, dims[0]); ++x) {
              const int p[3] = {x, y, z};
              if (!blend_voxel(p, tables, scratch)) continue;
              constrain(x, y, z, acc.data());
              float* out = tex_.data() + tex_.offset(x, y, z);
              for (int c = 0; c < C_; ++c) {
                if (hist && c < H_) {
                  --delta[std::size_t(c) * bins + value_bin(out[c], channel_lo_[c], channel_hi_[c], bins)];
                  ++delta[std::size_t(c) * bins + value_bin(acc[c], channel_lo_[c], channel_hi_[c], bins)];
                }
                out[c] = acc[c];
              }
            }
      }
    });
    if (hist)
      for (const auto& delta : deltas)
        for (std::size_t k = 0; k < delta.size(); ++k) counts[k] += delta[k];
  }
}

}  // namespace exsynth::solid

namespace exsynth::solid {

// Exemplar values. The optimisation's value is an IRLS-weighted mean of up to
// 3 x (n/2)^2 exemplar texels from windows that disagree (most of all across
// the three orthogonal views), and that mean is what blurs (docs/solid.md,
// per-stage figures). This pass gives every voxel one exemplar texel instead:
// the one the best-matching window covering it (the highest IRLS weight over
// all views) puts there. Neighbouring voxels share windows, so the result is
// made of coherent pieces of exemplar, i.e. a map of exemplar coordinates.
// Measured alternatives (the views' best texels, then the one nearest the mean
// or their medoid) kept less detail. Reads only the matches: each voxel's
// choice is independent of the others, so any thread count gives the same.
void LevelSolver::discrete(StageProgress& progress, std::vector<std::int32_t>* source) {
  if (opt_.histogram_values > 0) return discrete_histogram(progress, source);  // histogram_values.cpp
  plain_values(progress, source);
}

void LevelSolver::plain_values(StageProgress& progress, std::vector<std::int32_t>* source) {
  if (source) source->assign(tex_.voxel_count(), -1);
  for_each_voxel_tiled(progress, [&](int x, int y, int z) {
    const int p[3] = {x, y, z};
    int best_view = -1;
    std::size_t best_pix = 0;
    float best_support = -1.0f;
    for (int i = 0; i < 3; ++i) {
      if (!views_[i].ex) continue;
      float best_weight = -1.0f, support = 0.0f;
      std::size_t pix = 0;
      for_each_covering(p, i, [&](float wt, std::size_t, std::size_t texel) {
        support += wt;
        if (wt <= best_weight) return;  // ties: the first in scan order
        best_weight = wt;
        pix = texel;
      });
      if (best_weight >= 0.0f && support > best_support) best_support = support, best_view = i, best_pix = pix;
    }
    if (best_view < 0) return;  // no window covers p: keep the optimised value
    put_texel(x, y, z, best_view, best_pix);
    if (source) (*source)[tex_.voxel_index(x, y, z)] = source_code(best_view, best_pix);
  });
}

}  // namespace exsynth::solid
