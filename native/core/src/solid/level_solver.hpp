#pragma once
// One pyramid level of the texture optimisation: the matches of the sparse
// grid for each active view, and the two phases that alternate on them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/solid.hpp"
#include "search/kd_tree.hpp"
#include "solid/candidate_scoring.hpp"
#include "solid/exemplar_index.hpp"

namespace exsynth::solid {

/// The slice orthogonal to `axis` maps exemplar column -> `u`, row -> `v`.
struct SliceAxes {
  int axis, u, v;
};
constexpr SliceAxes kSlices[3] = {{0, 1, 2}, {1, 0, 2}, {2, 0, 1}};


class LevelSolver {
 public:
  /// `views[i]` = exemplar of the slice orthogonal to axis i, nullptr = view
  /// inactive. `constraint`: empty or same grid as `texture` with K + 1
  /// channels, K <= C: targets for the first K channels, then a weight (the
  /// channels after K, e.g. the feature-distance channel, are not constrained).
  /// `channel_lo/hi`: the value range the histogram bins span (as the
  /// exemplars') for the first H <= C channels, the ones histogram matching
  /// keeps (not the feature-distance channel: a guide, not a value).
  LevelSolver(Volume& texture, std::array<const ExemplarIndex*, 3> views, const Volume& constraint,
              const TextureOptimizationOptions& opt, bool wrap, std::uint64_t seed,
              std::vector<float> channel_lo, std::vector<float> channel_hi);
  ~LevelSolver();

  /// Starts the matches from the next-coarser level's (positions doubled).
  void inherit_matches(const LevelSolver& coarser);

  /// Search phase; `exhaustive` = search every exemplar neighbourhood (in PCA
  /// space, or as the options' method says). Returns the mean energy |s-e|^r.
  double search(int iteration, bool exhaustive, StageProgress& progress);
  /// Optimisation phase: every voxel from the matched neighbourhoods.
  void optimize(int iteration, StageProgress& progress);

  /// Exemplar values: every voxel takes one exemplar texel, the one its
  /// best-matching covering window puts there (see level_solver.cpp).
  /// `source`, when given, receives per voxel the view and exemplar pixel taken
  /// (view * 2^28 + pixel index; -1 = no window covered it: value kept).
  /// With opt.histogram_values > 0 the choice is histogram-matched instead
  /// (discrete_histogram).
  void discrete(StageProgress& progress, std::vector<std::int32_t>* source = nullptr);

  /// Bytes of the histogram_values pricing rounds' proposals (SampleProposals)
  /// for a solid of `voxels` with n x n windows: 3 ceil(n/2)^2 per sampled voxel
  /// (one window more per axis where an odd wrapped edge adds one: not counted).
  static double sample_proposal_bytes(double voxels, int n) {
    const double per_view = std::ceil(n / 2.0) * std::ceil(n / 2.0);
    return std::min(voxels, double(kValueSample)) * (3.0 * per_view * sizeof(Proposal) + sizeof(std::uint32_t));
  }

  /// The level's texture (the solver writes it in place).
  const Volume& texture() const { return tex_; }
  /// Every voxel pulled towards the constraint's targets by its weight, as
  /// the phases do: after a step that rewrote the texture (structure_sigma).
  void constrain_texture() {
    if (constraint_.empty()) return;
    for (int z = 0; z < tex_.nz(); ++z)
      for (int y = 0; y < tex_.ny(); ++y)
        for (int x = 0; x < tex_.nx(); ++x) constrain(x, y, z, &tex_.at(x, y, z));
  }

  /// Units of progress each phase reports (for StageProgress totals).
  std::size_t search_units() const;
  std::size_t optimize_units() const;
  std::size_t discrete_units() const {
    const std::size_t rows = std::size_t(tex_.ny()) * tex_.nz();
    if (opt_.histogram_values <= 0) return rows;
    // the sample's proposals (once), the rounds, then write_values' two passes
    return 2 * rows + std::size_t(opt_.histogram_value_rounds + 1) * ((value_sample() + kValueChunk - 1) / kValueChunk);
  }

 private:
  struct View {
    const ExemplarIndex* ex = nullptr;
    int nu = 0, nv = 0, na = 0;          // sparse grid: na slices x nv rows x nu columns
    std::vector<std::int32_t> match;     // exemplar neighbourhood index per sparse voxel
    std::vector<float> weight;           // IRLS weight |s - e|^(r - 2)
    std::unique_ptr<search::KdTree> kd;  // search = KdTree only
    int scoring = -1;                    // k-coherence: index into scoring_ (shared by views of one exemplar)
    std::size_t size() const { return std::size_t(na) * nv * nu; }
  };

  void gather(int i, std::size_t sparse, float* row) const;
  struct ScoringTable;
  static ScoringTable scoring_table(const ExemplarIndex& ex);

  // The optimisation phase's pieces (level_solver.cpp).
  // Per sparse voxel, its matched window's top-left exemplar pixel (-1 = no
  // match) beside its IRLS weight; per exemplar pixel, its histogram factor
  // beside its C values (stride C + 1). A covering window then costs two
  // loads instead of four dependent ones (match -> corner -> factor, texel),
  // which is where the blend stalled (perf, 128^3: ~19 % of the CPU).
  struct SparseWindow {
    std::int32_t corner;
    float weight;
  };
  // Views that share an exemplar share its texel table (one 256 KiB table
  // for a 128^2 RGB exemplar fits the L2 cache; three did not: perf).
  struct OptimizeTables {
    std::array<std::vector<SparseWindow>, 3> window;  // per view: per sparse voxel
    std::vector<std::vector<float>> texel;            // per distinct exemplar: per pixel, factor then C values
    std::vector<const ExemplarIndex*> texel_ex;       // the exemplar of each texel table
    std::array<int, 3> texel_of{-1, -1, -1};          // per view: its texel table
  };
  struct VoxelScratch {
    std::vector<float> acc, mode;      // C floats each: the voxel's value, mean-shift scratch
    std::vector<float> values, weights;  // the covering texels and weights (mean shift only)
  };
  std::vector<double> target_histogram() const;
  std::vector<std::int64_t> solid_histogram() const;
  void histogram_factors(const std::vector<std::int64_t>& counts, const std::vector<double>& target,
                         OptimizeTables& tables) const;
  bool blend_voxel(const int p[3], const OptimizeTables& tables, VoxelScratch& scratch) const;
  // Histogram-matched exemplar values (level_solver.cpp, discrete_histogram).
  // Per distinct exemplar: per pixel its kValueBins bin of each value
  // channel and its price factor; the target histogram (fractions per
  // channel and bin) and the views' exemplar tables.
  struct ValueTables {
    int channels = 0;                                // value channels (the feature channel is not matched)
    std::vector<const ExemplarIndex*> ex;            // distinct exemplars
    std::vector<std::vector<std::uint8_t>> bins;     // per exemplar: pixel * channels + c
    std::vector<std::vector<float>> factor;          // per exemplar: per pixel exp((1 - beta) x its price)
    std::vector<std::vector<float>> window;          // per exemplar: per window corner exp(beta x mean price)
    std::array<int, 3> of{-1, -1, -1};               // per view: its exemplar's tables
    std::vector<double> target;                      // channels * kValueBins fractions
  };
  // One covering window's proposal for a voxel: the texel it puts there
  // (source_code(view, pixel)), the window's top-left exemplar pixel and its
  // score before prices (the view's summed weight over the voxel times the
  // window's weight relative to the view's best; see value_proposals).
  struct Proposal {
    double unpriced;
    std::int32_t code;
    std::uint32_t corner;
  };
  struct Choice {
    int view = -1;  // -1: no window covers the voxel
    std::size_t pix = 0;
  };
  // The pricing rounds' voxels and their proposals, gathered once: the
  // proposals do not change between rounds, only the prices do. Per chunk of
  // kValueChunk sample voxels, the proposals in voxel order and each voxel's
  // end among them (an empty range: no window covers it); plus the counts of
  // the values the uncovered voxels keep.
  struct SampleProposals {
    std::vector<std::vector<Proposal>> proposals;
    std::vector<std::vector<std::uint32_t>> ends;
    std::vector<std::int64_t> uncovered;
  };
  static constexpr std::size_t kValueSample = std::size_t(1) << 15;  // voxels the pricing rounds count
  static constexpr std::size_t kValueChunk = 1024;                   // of them per parallel chunk
  std::size_t value_sample() const;
  ValueTables value_tables() const;
  void price_factors(const std::vector<double>& price, ValueTables& vt) const;
  std::size_t value_proposals(const int p[3], Proposal* out) const;  // voxel p's, in scan order; their count
  // Room value_proposals needs: the most covering windows of a voxel in each view.
  std::size_t max_proposals() const { return 3 * std::size_t(max_cover_) * std::size_t(max_cover_); }
  std::int32_t priced_choice(const Proposal* begin, const Proposal* end, const ValueTables& vt) const;
  // The priced choice; `plain`, when given, receives the unpriced one (the plain pass's).
  Choice choose_value(const int p[3], const ValueTables& vt, std::vector<Proposal>& proposals,
                      Choice* plain = nullptr) const;
  SampleProposals sample_proposals(const ValueTables& vt, StageProgress& progress) const;
  bool coherent_choice(const int p[3], std::int32_t code, const std::vector<std::int32_t>& chosen) const;
  std::vector<std::int64_t> chosen_histogram(const ValueTables& vt, const SampleProposals& sample,
                                             StageProgress& progress) const;
  void write_values(const ValueTables& vt, StageProgress& progress, std::vector<std::int32_t>* source);
  void discrete_histogram(StageProgress& progress, std::vector<std::int32_t>* source);
  void plain_values(StageProgress& progress, std::vector<std::int32_t>* source);  // discrete's plain pass
  static constexpr int kValuePatience = 8;  // rounds with no nearer histogram before the pricing stops
  // The plain choices' histogram distance (1-D EMD in bins, summed over the
  // value channels) below which they count as matched and are written as they are.
  static constexpr double kValueMatched = 0.25;
  // TextureResult::source's code of a voxel's choice: view * 2^28 + exemplar
  // pixel; -1 = none (no window covers the voxel).
  static std::int32_t source_code(int view, std::size_t pix) {
    return view < 0 ? -1 : std::int32_t((std::size_t(view) << 28) | pix);
  }
  static int source_view(std::int32_t code) { return int(code >> 28); }
  static std::size_t source_pixel(std::int32_t code) { return std::size_t(code & ((1 << 28) - 1)); }
  // fn(weight, corner, pix) for each window of view i that covers voxel p
  // and has a match, in scan order: its IRLS weight, its top-left exemplar
  // pixel and the exemplar pixel it puts at p.
  template <class Fn>
  void for_each_covering(const int p[3], int i, Fn&& fn) const {
    const View& w = views_[i];
    const SliceAxes& s = kSlices[i];
    const std::size_t width = std::size_t(w.ex->image().width());
    const Covering cov = cover(p, s);
    for (int a = 0; a < cov.nv; ++a) {
      const std::size_t row_sp = (std::size_t(p[s.axis]) * w.nv + cov.sv[a]) * w.nu;
      for (int b = 0; b < cov.nu; ++b) {
        const std::size_t sp = row_sp + cov.su[b];
        const int j = w.match[sp];
        if (j < 0) continue;
        const std::size_t corner = std::size_t(w.ex->centre_v(j) - lo_) * width + std::size_t(w.ex->centre_u(j) - lo_);
        fn(w.weight[sp], corner, corner + std::size_t(cov.dv[a]) * width + std::size_t(cov.du[b]));
      }
    }
  }
  // fn(x, y, z) for every voxel, in parallel over groups of up to kTileRows
  // rows (y, z), each walked in tiles of kTileX columns: a tile's voxels share
  // the sparse windows of every view (the x-view's slices change along x), so
  // the exemplar-values passes read them from cache. Row by row the x-view
  // took a new slice's windows at every voxel (measured on a 128^3 brick
  // solid: value_proposals 9.2 -> 8.6 % of the CPU; the plain pass within
  // the noise). Progress: one unit per row.
  static constexpr int kTileRows = 8, kTileX = 8;
  template <class Fn>
  void for_each_voxel_tiled(StageProgress& progress, Fn&& fn) const {
    const int nx = tex_.nx(), ny = tex_.ny();
    parallel_chunks(std::size_t(ny) * tex_.nz(), kTileRows, progress, [&](std::size_t r0, std::size_t r1) {
      for (int x0 = 0; x0 < nx; x0 += kTileX)
        for (std::size_t row = r0; row < r1; ++row)
          for (int x = x0; x < std::min(x0 + kTileX, nx); ++x) fn(x, int(row % std::size_t(ny)), int(row / std::size_t(ny)));
    });
  }
  // Voxel (x, y, z) takes exemplar pixel `pix` of view `view`'s exemplar (the
  // exemplar values), then the constraint: a requested target still wins by its weight.
  void put_texel(int x, int y, int z, int view, std::size_t pix) {
    const float* e = views_[view].ex->image().data() + pix * C_;
    float* out = tex_.data() + tex_.offset(x, y, z);
    std::copy(e, e + C_, out);
    constrain(x, y, z, out);
  }
  // Voxel (x, y, z)'s values pulled towards the constraint's targets by its weight.
  void constrain(int x, int y, int z, float* values) const {
    if (constraint_.empty()) return;
    const int K = constraint_.channels() - 1;
    const float wc = std::clamp(constraint_.at(x, y, z, K), 0.0f, 1.0f);
    for (int c = 0; c < K; ++c) values[c] = (1.0f - wc) * values[c] + wc * constraint_.at(x, y, z, c);
  }
  template <int kChannels>
  bool blend_voxel_channels(const int p[3], const OptimizeTables& tables, VoxelScratch& scratch) const;

  // The sparse voxels whose windows cover voxel p in a slice of axes s: per
  // slice axis, the offsets d (0..n-1) with p - (d - lo) on the sparse grid
  // (even, inside the texture or wrapped) and that sparse coordinate. They
  // depend on one coordinate each, so they are tabulated per axis (axis_cover_).
  struct Covering {
    int nu = 0, nv = 0;
    const int *du = nullptr, *su = nullptr, *dv = nullptr, *sv = nullptr;
  };
  Covering cover(const int p[3], const SliceAxes& s) const {
    const std::size_t u = std::size_t(p[s.u]), v = std::size_t(p[s.v]);
    const AxisCover &cu = axis_cover_[s.u], &cv = axis_cover_[s.v];
    return {cu.count[u], cv.count[v], cu.d.data() + u * n_, cu.s.data() + u * n_, cv.d.data() + v * n_,
            cv.s.data() + v * n_};
  }
  struct AxisCover {
    std::vector<int> count, d, s;  // per coordinate x: count, then n slots of (d, sparse coordinate)
  };

  Volume& tex_;
  std::array<View, 3> views_;
  const Volume& constraint_;
  const TextureOptimizationOptions& opt_;
  bool wrap_;
  std::uint64_t seed_;
  int C_, H_, n_, lo_;  // channels, histogram-matched channels, window size, its half
  std::vector<float> channel_lo_, channel_hi_;
  std::array<std::vector<int>, 3> wrapped_;  // per axis: coordinate x + n -> wrapped/clamped x
  std::array<AxisCover, 3> axis_cover_;
  int max_cover_ = 0;  // the largest count of axis_cover_ (about n/2; one more where an odd edge wraps)

  // The PCA coefficients for the k-coherence scoring, one 64-byte aligned
  // row per window with a stride of whole cache lines (16 floats): the first
  // two 8-float blocks, where most candidates are decided, are then one
  // cache line, requested when the candidate is proposed. (Measured: Eigen's
  // rows straddle lines; a block-major copy kept the first blocks of all
  // windows in L2, but the many candidates that reach the second block then
  // stalled on a second, unrequested line: ~46 % of the scoring in perf.)
  struct Centre {
    std::int32_t u, v;  // one load where ExemplarIndex's two tables took two
  };
  struct ScoringTable {
    const ExemplarIndex* ex = nullptr;
    std::vector<Centre> centre;  // per window
    std::vector<float> storage;
    CoefficientRows rows;  // into storage
  };
  std::vector<ScoringTable> scoring_;
  struct Candidates {
    std::vector<int> idx;  // capacity for the most a query proposes; the first n are its candidates
    std::size_t n = 0;
  };
};

}  // namespace exsynth::solid
