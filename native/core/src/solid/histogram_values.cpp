// Histogram-matched exemplar values (TextureOptimizationOptions::histogram_values).
//
// The plain pass (LevelSolver::discrete) gives voxel p the texel that the
// best-matching window of the best-supported view puts there. On
// high-contrast exemplars (stone33, brick, granite1) the solid's histogram
// then misses the exemplar's (hist_emd 9-14 grey levels on 64^3 slices,
// docs/solid.md, tenth pass): the best-matching windows are the exemplar's
// commoner mid-tone ones, and the optimisation's histogram re-weighting acted
// on the averages this pass discards. Here each voxel chooses among every
// texel its covering windows propose (all views); proposal t of view i scores
//     S_i * (w_t / W_i) / (exp((1 - beta) P(t)) * exp(beta * mean P over t's window)),
// S_i = the view's summed IRLS weights over p, W_i = its best weight, w_t =
// t's window's weight, P(t) = the sum over value channels c of
// price[c][bin_c(t)], beta = histogram_value_window. With every price 0 the
// best is the plain pass's texel (score S_max, the only one: see
// choose_value), so round 0 is that pass. Prices are a Lagrangian (dual
// ascent) of "the solid's histogram = the exemplars'": after a round of
// choices at fixed prices, a bin whose share exceeds the target by e (a
// fraction) gets price += step * e, an under-full one loses as much. Each
// voxel's choice depends only on the prices and the matches, so any thread
// count gives the same. The rounds count a spread sample of the voxels
// (value_sample); the round nearest the target (1-D EMD summed over
// channels) is the one written, so the result's histogram is (up to the
// sample) never farther than the plain pass's. A round that comes out
// farther than the nearest so far goes back to the nearest prices with half
// the step. Measured: a constant step of 0.3 converges smoothly over 32
// rounds on stone33 but overshoots at once on granite1 (1.10 -> 1.37 ->
// 1.90; 1.10 -> 0.38 with the halving); 1 and more oscillate on stone33 too
// (5.1 -> 7.3 -> 12.1 at 3).

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <tbb/enumerable_thread_specific.h>

#include "exsynth/parallel.hpp"
#include "solid/level_solver.hpp"

namespace exsynth::solid {
namespace {

// Sum over channels of the 1-D earth mover's distance (in bins) between the
// histogram of `counts` (of `total` voxels) and the target fractions.
double histogram_distance(const std::vector<std::int64_t>& counts, const std::vector<double>& target, int channels,
                          double total) {
  double d = 0.0;
  for (int c = 0; c < channels; ++c) {
    double cum = 0.0;
    for (int b = 0; b < kValueBins; ++b) {
      const std::size_t k = std::size_t(c) * kValueBins + b;
      cum += double(counts[k]) / total - target[k];
      d += std::abs(cum);
    }
  }
  return d;
}

}  // namespace

// The bins of every distinct exemplar's pixels and the target: the mean of
// the active views' exemplar histograms (as target_histogram). The
// feature-distance channel, when present (the last), is not a value the
// output keeps, so it is not matched.
LevelSolver::ValueTables LevelSolver::value_tables() const {
  ValueTables vt;
  vt.channels = H_;  // the histogram-matched channels (the feature channel, when present, is the last)
  const int V = vt.channels;
  vt.target.assign(std::size_t(V) * kValueBins, 0.0);
  int active = 0;
  for (int i = 0; i < 3; ++i) {
    const View& w = views_[i];
    if (!w.ex) continue;
    ++active;
    const Image& img = w.ex->image();
    const auto shared = std::find(vt.ex.begin(), vt.ex.end(), w.ex);
    vt.of[i] = int(shared - vt.ex.begin());
    if (shared == vt.ex.end()) {
      vt.ex.push_back(w.ex);
      std::vector<std::uint8_t>& bins = vt.bins.emplace_back(img.pixel_count() * std::size_t(V));
      for (std::size_t p = 0; p < img.pixel_count(); ++p)
        for (int c = 0; c < V; ++c)
          bins[p * V + c] = std::uint8_t(value_bin(img.data()[p * C_ + c], channel_lo_[c], channel_hi_[c], kValueBins));
      vt.factor.emplace_back(img.pixel_count(), 1.0f);
      vt.window.emplace_back(img.pixel_count(), 1.0f);
    }
    const std::vector<std::uint8_t>& bins = vt.bins[std::size_t(vt.of[i])];
    const double share = 1.0 / double(img.pixel_count());
    for (std::size_t p = 0; p < img.pixel_count(); ++p)
      for (int c = 0; c < V; ++c) vt.target[std::size_t(c) * kValueBins + bins[p * V + c]] += share;
  }
  for (double& t : vt.target) t /= active;
  return vt;
}

// Per exemplar pixel its price P (the sum of its bins' prices), as the two
// factors choose_value divides by: exp((1 - beta) P) per texel and
// exp(beta x mean P over the n x n window) per window corner (a summed-area
// table). One load each per proposal instead of one per channel and an exp.
// Exponents are clamped so a runaway price cannot make a factor 0 or infinite.
void LevelSolver::price_factors(const std::vector<double>& price, ValueTables& vt) const {
  const int V = vt.channels;
  const double beta = opt_.histogram_value_window;
  auto factor_of = [](double x) { return float(std::exp(std::clamp(x, -60.0, 60.0))); };
  for (std::size_t e = 0; e < vt.ex.size(); ++e) {
    const Image& img = vt.ex[e]->image();
    const std::size_t W = std::size_t(img.width()), H = std::size_t(img.height());
    const std::vector<std::uint8_t>& bins = vt.bins[e];
    std::vector<double> sat((W + 1) * (H + 1), 0.0);  // sat[(y + 1)(W + 1) + x + 1] = sum over [0, x] x [0, y]
    for (std::size_t y = 0; y < H; ++y)
      for (std::size_t x = 0; x < W; ++x) {
        const std::size_t p = y * W + x;
        double P = 0.0;
        for (int c = 0; c < V; ++c) P += price[std::size_t(c) * kValueBins + bins[p * V + c]];
        vt.factor[e][p] = factor_of((1.0 - beta) * P);
        sat[(y + 1) * (W + 1) + x + 1] = P + sat[y * (W + 1) + x + 1] + sat[(y + 1) * (W + 1) + x] - sat[y * (W + 1) + x];
      }
    if (beta == 0.0) continue;  // the window factors stay 1
    for (std::size_t y = 0; y < H; ++y)
      for (std::size_t x = 0; x < W; ++x) {
        const std::size_t x1 = std::min(W, x + std::size_t(n_)), y1 = std::min(H, y + std::size_t(n_));
        const double sum = sat[y1 * (W + 1) + x1] - sat[y * (W + 1) + x1] - sat[y1 * (W + 1) + x] + sat[y * (W + 1) + x];
        vt.window[e][y * W + x] = factor_of(beta * sum / double((x1 - x) * (y1 - y)));
      }
  }
}

// Voxel p's proposals (see the file comment), written to out[0..count) in
// the plain pass's order (view, then scan order): each covering window's
// texel with S_i * w_t / W_i, its score before prices. Supports are summed in
// float in the plain pass's order and the score is formed in double, so with
// unit price factors the strict maximum is exactly the plain pass's texel:
// within the best view only its first best window scores S_max, every other
// proposal scores below. `out` holds max_proposals(): a raw buffer, because
// with push_back the hottest instruction (40 % of this function's samples in
// perf) was the vector's end-pointer update after every proposal; without it
// the function went from 8.6 to 6.4 % of a 128^3 brick solid's CPU.
std::size_t LevelSolver::value_proposals(const int p[3], Proposal* out) const {
  std::size_t count = 0, first[4] = {0, 0, 0, 0};
  float support[3] = {0.0f, 0.0f, 0.0f}, best[3] = {0.0f, 0.0f, 0.0f};
  for (int i = 0; i < 3; ++i) {
    first[i] = count;
    if (!views_[i].ex) continue;
    for_each_covering(p, i, [&](float wt, std::size_t corner, std::size_t pix) {
      support[i] += wt;
      best[i] = std::max(best[i], wt);
      out[count++] = {double(wt), source_code(i, pix), std::uint32_t(corner)};  // the weight until the supports are known
    });
  }
  first[3] = count;
  for (int i = 0; i < 3; ++i)
    for (std::size_t k = first[i]; k < first[i + 1]; ++k) {
      const double rel = best[i] > 0.0f ? out[k].unpriced / double(best[i]) : 1.0;
      out[k].unpriced = double(support[i]) * rel;
    }
  return count;
}

// The code of the best-scoring proposal in [begin, end) at the current prices
// (ties: the first), -1 for none. Without the window share (beta = 0, the
// default) every window factor is exactly 1 and is not read: the same scores.
std::int32_t LevelSolver::priced_choice(const Proposal* begin, const Proposal* end, const ValueTables& vt) const {
  const float* factor[3] = {nullptr, nullptr, nullptr};
  const float* window[3] = {nullptr, nullptr, nullptr};
  for (int i = 0; i < 3; ++i)
    if (vt.of[i] >= 0) factor[i] = vt.factor[std::size_t(vt.of[i])].data(), window[i] = vt.window[std::size_t(vt.of[i])].data();
  double best_score = -1.0;
  std::int32_t code = -1;
  if (opt_.histogram_value_window == 0.0) {
    for (const Proposal* q = begin; q != end; ++q) {
      const double score = q->unpriced / double(factor[source_view(q->code)][source_pixel(q->code)]);
      if (score > best_score) best_score = score, code = q->code;
    }
    return code;
  }
  for (const Proposal* q = begin; q != end; ++q) {
    const int view = source_view(q->code);
    const double score = q->unpriced / (double(factor[view][source_pixel(q->code)]) * double(window[view][q->corner]));
    if (score > best_score) best_score = score, code = q->code;
  }
  return code;
}

// Voxel p's choice at the current prices; `plain`, when given, receives the
// unpriced best (the plain pass's texel).
LevelSolver::Choice LevelSolver::choose_value(const int p[3], const ValueTables& vt, std::vector<Proposal>& proposals,
                                              Choice* plain) const {
  if (proposals.size() < max_proposals()) proposals.resize(max_proposals());
  const Proposal* begin = proposals.data();
  const Proposal* end = begin + value_proposals(p, proposals.data());
  auto choice_of = [](std::int32_t code) { return code < 0 ? Choice{} : Choice{source_view(code), source_pixel(code)}; };
  if (plain) {
    double best_plain = -1.0;
    std::int32_t code = -1;
    for (const Proposal* q = begin; q != end; ++q)
      if (q->unpriced > best_plain) best_plain = q->unpriced, code = q->code;
    *plain = choice_of(code);
  }
  return choice_of(priced_choice(begin, end, vt));
}

// The voxels the pricing rounds count: all of them up to
// kValueSample (32768), else kValueSample spread over the solid (i * P mod N, P a
// prime above any edge, so coprime with N: distinct voxels, no lattice
// aligned with the sparse grid's parity). A histogram of 32768 voxels is
// within ~0.1 percentage points per bin (a 3 % bin) of the whole's, and the rounds then cost a fraction
// of a pass each at 64^3 and above (16 full rounds took 5 s of CPU at 64^3).
std::size_t LevelSolver::value_sample() const { return std::min<std::size_t>(tex_.voxel_count(), kValueSample); }

// The sample's proposals, gathered once for all rounds (16 bytes each, up to
// 3 (n/2)^2 per voxel: 25 MB at n = 8). Gathering them every round took
// about as long as the plain pass over a 128^3 solid for 32 rounds (stone33:
// 2.2 s CPU for rounds 2..32, docs/solid.md). A voxel no window covers counts
// by the value it keeps (the constraint, applied when writing, pulls values
// the prices cannot move). Integer counts: the sum does not depend on the
// order chunks finish in.
LevelSolver::SampleProposals LevelSolver::sample_proposals(const ValueTables& vt, StageProgress& progress) const {
  const std::size_t N = tex_.voxel_count(), M = value_sample(), nx = std::size_t(tex_.nx()), ny = std::size_t(tex_.ny());
  constexpr std::uint64_t kSpread = 2654435761u;  // prime, above kMaxSolidSize
  const int V = vt.channels;
  const std::size_t chunks = (M + kValueChunk - 1) / kValueChunk;
  SampleProposals sample;
  sample.proposals.resize(chunks);
  sample.ends.resize(chunks);
  sample.uncovered.assign(vt.target.size(), 0);
  std::mutex merge;
  parallel_chunks(chunks, 1, progress, [&](std::size_t c0, std::size_t c1) {
    std::vector<std::int64_t> local(sample.uncovered.size(), 0);
    for (std::size_t c = c0; c < c1; ++c) {
      std::vector<Proposal>& proposals = sample.proposals[c];
      std::vector<std::uint32_t>& ends = sample.ends[c];
      // The chunk's room at once: no reallocation (and no doubled capacity) as it fills.
      proposals.reserve(kValueChunk * max_proposals());
      ends.reserve(kValueChunk);
      for (std::size_t i = c * kValueChunk; i < std::min(M, (c + 1) * kValueChunk); ++i) {
        const std::size_t v = M == N ? i : std::size_t((std::uint64_t(i) * kSpread) % N);
        const int p[3] = {int(v % nx), int((v / nx) % ny), int(v / (nx * ny))};
        const std::size_t before = proposals.size();
        proposals.resize(before + max_proposals());
        proposals.resize(before + value_proposals(p, proposals.data() + before));
        ends.push_back(std::uint32_t(proposals.size()));
        if (proposals.size() > before) continue;
        const float* kept = tex_.data() + v * std::size_t(C_);
        for (int ch = 0; ch < V; ++ch)
          ++local[std::size_t(ch) * kValueBins + value_bin(kept[ch], channel_lo_[ch], channel_hi_[ch], kValueBins)];
      }
    }
    std::lock_guard<std::mutex> lock(merge);
    for (std::size_t k = 0; k < local.size(); ++k) sample.uncovered[k] += local[k];
  });
  return sample;
}

// The histogram (channels x kValueBins counts) of the sample's choices at
// the current prices, nothing written; the uncovered voxels' counts as gathered.
std::vector<std::int64_t> LevelSolver::chosen_histogram(const ValueTables& vt, const SampleProposals& sample,
                                                        StageProgress& progress) const {
  const int V = vt.channels;
  std::vector<std::int64_t> counts = sample.uncovered;
  std::mutex merge;
  parallel_chunks(sample.proposals.size(), 1, progress, [&](std::size_t c0, std::size_t c1) {
    std::vector<std::int64_t> local(counts.size(), 0);
    for (std::size_t c = c0; c < c1; ++c) {
      const Proposal* proposals = sample.proposals[c].data();
      std::uint32_t begin = 0;
      for (const std::uint32_t end : sample.ends[c]) {
        const std::int32_t code = priced_choice(proposals + begin, proposals + end, vt);
        begin = end;
        if (code < 0) continue;  // uncovered: counted once in sample.uncovered
        const std::uint8_t* bins = vt.bins[std::size_t(vt.of[source_view(code)])].data() + source_pixel(code) * V;
        for (int ch = 0; ch < V; ++ch) ++local[std::size_t(ch) * kValueBins + bins[ch]];
      }
    }
    std::lock_guard<std::mutex> lock(merge);
    for (std::size_t k = 0; k < counts.size(); ++k) counts[k] += local[k];
  });
  return counts;
}

// Whether choice `code` of voxel p continues a neighbour's: one of its four
// neighbours in the chosen view's slice plane chose, in the same view, the
// exemplar texel next to p's in that direction (a piece of >= 2 voxels).
bool LevelSolver::coherent_choice(const int p[3], std::int32_t code, const std::vector<std::int32_t>& chosen) const {
  const int view = source_view(code);
  const std::size_t pix = source_pixel(code);
  const SliceAxes& s = kSlices[view];
  const Image& img = views_[view].ex->image();
  const std::size_t width = std::size_t(img.width()), height = std::size_t(img.height());
  const std::size_t col = pix % width, row = pix / width;
  for (int axis : {s.u, s.v})
    for (int step : {-1, 1}) {
      const std::size_t along = axis == s.u ? col : row, edge = axis == s.u ? width : height;
      if ((step < 0 && along == 0) || (step > 0 && along + 1 == edge)) continue;
      int q[3] = {p[0], p[1], p[2]};
      q[axis] = wrapped_[axis][std::size_t(q[axis] + step + n_)];
      if (q[axis] == p[axis]) continue;  // clamped at the edge of a solid that does not tile
      const std::size_t next = axis == s.u ? pix + step : pix + step * std::ptrdiff_t(width);
      if (chosen[tex_.voxel_index(q[0], q[1], q[2])] == source_code(view, next)) return true;
    }
  return false;
}

// The choices at the current prices written as the plain pass writes its
// own: the texel, then the constraint, and its source. A voxel whose priced
// choice differs from the plain pass's and continues no neighbour's is a
// lone texel from a window that covers it alone (a dark voxel inside a light
// stone: the speckle of the tenth pass, docs/solid.md): it keeps the plain
// pass's texel. Both passes read the first pass's choices only, so any
// thread order gives the same.
void LevelSolver::write_values(const ValueTables& vt, StageProgress& progress, std::vector<std::int32_t>* source) {
  const int dims[3] = {tex_.nx(), tex_.ny(), tex_.nz()};
  const std::size_t rows = std::size_t(dims[1]) * dims[2];
  std::vector<std::int32_t> own;
  std::vector<std::int32_t>& chosen = source ? *source : own;
  chosen.assign(tex_.voxel_count(), -1);
  std::vector<std::int32_t> plain(tex_.voxel_count(), -1);
  tbb::enumerable_thread_specific<std::vector<Proposal>> scratch;
  for_each_voxel_tiled(progress, [&](int x, int y, int z) {
    const int p[3] = {x, y, z};
    Choice unpriced;
    const Choice ch = choose_value(p, vt, scratch.local(), &unpriced);
    const std::size_t v = tex_.voxel_index(x, y, z);
    chosen[v] = source_code(ch.view, ch.pix);
    plain[v] = source_code(unpriced.view, unpriced.pix);
  });
  // plain[v] becomes v's final choice: each voxel reads only its own entry of
  // plain, and its neighbours' of chosen.
  parallel_chunks(rows, 1, progress, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t row = r0; row < r1; ++row) {
      const int y = int(row % std::size_t(dims[1])), z = int(row / std::size_t(dims[1]));
      for (int x = 0; x < dims[0]; ++x) {
        const int p[3] = {x, y, z};
        const std::size_t v = tex_.voxel_index(x, y, z);
        const std::int32_t code = chosen[v];
        if (code != plain[v] && coherent_choice(p, code, chosen)) plain[v] = code;
        const std::int32_t kept = plain[v];
        if (kept < 0) continue;  // no window covers p: keep the optimised value
        put_texel(x, y, z, source_view(kept), source_pixel(kept));
      }
    }
  });
  chosen.swap(plain);
}

// The rounds stop once kValuePatience rounds in a row came no nearer. When
// the nearest is round 0 (all prices 0), or the plain choices are already
// within kValueMatched of the target (crackedground 0.17, marble1 0.06 at
// 64^3: matching them changed no figure), the plain pass writes: the same
// output as write_values at round 0 (round 0 is the plain pass, tested), at
// its own cost. Measured at 128^3 crackedground (seed 1): 10.4 s CPU for the
// whole solid with all 32 rounds and the priced write, 7.3 s with this, as
// with histogram_values = 0.
void LevelSolver::discrete_histogram(StageProgress& progress, std::vector<std::int32_t>* source) {
  ValueTables vt = value_tables();
  const SampleProposals sample = sample_proposals(vt, progress);
  const double total = double(value_sample());
  std::vector<double> price(vt.target.size(), 0.0), kept = price;
  std::vector<std::int64_t> kept_counts;
  double nearest = std::numeric_limits<double>::infinity(), step = opt_.histogram_values;
  int kept_round = 0, round = 0;
  for (; round < opt_.histogram_value_rounds && round - kept_round <= kValuePatience; ++round) {
    price_factors(price, vt);
    std::vector<std::int64_t> counts = chosen_histogram(vt, sample, progress);
    const double d = histogram_distance(counts, vt.target, vt.channels, total);
    if (round == 0 && d < kValueMatched) {  // already matched: the plain pass writes
      round = 1;
      break;
    }
    if (d < nearest) {
      nearest = d, kept = price, kept_round = round, kept_counts = counts;
    } else {  // farther: back to the nearest prices, half the step
      price = kept, counts = kept_counts, step *= 0.5;
    }
    for (std::size_t k = 0; k < price.size(); ++k)
      price[k] += step * (double(counts[k]) / total - vt.target[k]);
  }
  // The units discrete_units() counted for rounds not run and, on the plain
  // path, for the second pass of write_values.
  const std::size_t rows = std::size_t(tex_.ny()) * tex_.nz();
  progress.advance(std::size_t(opt_.histogram_value_rounds - round) * ((value_sample() + kValueChunk - 1) / kValueChunk));
  if (kept_round == 0) {
    plain_values(progress, source);
    return progress.advance(rows);
  }
  price_factors(kept, vt);
  write_values(vt, progress, source);
}

}  // namespace exsynth::solid
