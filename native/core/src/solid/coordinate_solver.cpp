#include "solid/coordinate_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"

namespace exsynth::solid {
namespace {

/// Edge of the coarsest level's start cells (each copies one table triple,
/// shifted with the voxel's offset). 4 instead of 8 (with the Euclidean
/// costs and fewer passes below): 64^3 crackedground / stone33 hist_emd
/// 3.39 / 9.82 -> 1.99 / 8.75 and voxels equal 4 steps away 0.24 -> 0.18 /
/// 0.16 (docs/solid.md, sixth pass).
constexpr int kInitCell = 4;

/// Sub-pass class of coordinate x along an axis of n voxels: its parity,
/// except that with an odd n and wrapping, the last voxel (a neighbour of
/// voxel 0 and of n - 2) gets a class of its own.
int parity_class(int x, int n, bool wrap) { return wrap && (n & 1) && x == n - 1 ? 2 : (x & 1); }

}  // namespace

CoordinateSolver::CoordinateSolver(const std::array<int, 3>& dims, const std::array<const ExemplarIndex*, 3>& views,
                                   const CrossbarCandidates& candidates, int coherence_k, bool wrap, std::uint64_t seed)
    : dims_(dims), views_(views), table_(candidates), k_(coherence_k), wrap_(wrap), seed_(seed),
      coords_(std::size_t(dims[0]) * dims[1] * dims[2], Triple{-1, -1, -1}) {
  for (int i = 0; i < 3; ++i)
    if (views_[i]) {
      features_[i] = views_[i]->coefficients().data();
      dims_pca_[i] = int(views_[i]->coefficients().cols());
      k_ = std::min(k_, views_[i]->coherence_k());
    }
}

std::int64_t CoordinateSolver::neighbour(const std::array<int, 3>& p, int axis, int s) const {
  std::array<int, 3> q = p;
  q[axis] += s;
  if (q[axis] < 0 || q[axis] >= dims_[axis]) {
    if (!wrap_) return -1;
    q[axis] = (q[axis] + dims_[axis]) % dims_[axis];
  }
  return std::int64_t(voxel(q[0], q[1], q[2]));
}

std::int32_t CoordinateSolver::shift(int view, std::int32_t j, int du, int dv) const {
  const ExemplarIndex& ix = *views_[view];
  return ix.clamped_index(ix.centre_u(j) + du, ix.centre_v(j) + dv);
}

void CoordinateSolver::initialize(StageProgress& progress) {
  std::array<int, 3> active{};
  int n_active = 0;
  for (int i = 0; i < 3; ++i)
    if (views_[i]) active[n_active++] = i;
  // Coherent patches, not texels: from per-voxel random triples the
  // parallel correction converges to the exemplar's flattest texels (every
  // neighbourhood is closest to the mean; seen at 32^3). Each cell of
  // kInitCell^3 voxels copies one random table triple, shifted with the
  // voxel's offset from the cell's centre in every view (as a 3D block of
  // the exemplars would be); the corrections then mend the seams.
  const int cells = (std::max({dims_[0], dims_[1], dims_[2]}) + kInitCell - 1) / kInitCell;
  parallel_chunks(coords_.size(), 1 << 14, progress, [&](std::size_t v0, std::size_t v1) {
    for (std::size_t v = v0; v < v1; ++v) {
      const std::array<int, 3> p{int(v % dims_[0]), int(v / dims_[0] % dims_[1]), int(v / dims_[0] / dims_[1])};
      const std::uint64_t cell = (std::uint64_t(p[2] / kInitCell) * cells + p[1] / kInitCell) * cells + p[0] / kInitCell;
      IndexRng rng(seed_, cell, 0xC00D);
      const int view = active[rng.below(std::uint64_t(n_active))];
      const auto j = std::int32_t(rng.below(std::uint64_t(views_[view]->count())));
      Triple t = table_.of(view, j)[0];
      for (int i = 0; i < 3; ++i) {
        if (!views_[i]) continue;
        const int a = col_axis(i), b = row_axis(i);
        t[i] = shift(i, t[i], p[a] % kInitCell - kInitCell / 2, p[b] % kInitCell - kInitCell / 2);
      }
      coords_[v] = t;
    }
  });
}

void CoordinateSolver::upsample(const CoordinateSolver& coarser, StageProgress& progress) {
  const std::size_t rows = std::size_t(dims_[1]) * dims_[2];
  parallel_chunks(rows, 64, progress, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1; ++r) {
      const int y = int(r % dims_[1]), z = int(r / dims_[1]);
      for (int x = 0; x < dims_[0]; ++x) {
        const std::array<int, 3> p{x, y, z};
        const Triple& parent = coarser.coords_[coarser.voxel(x / 2, y / 2, z / 2)];
        Triple& child = coords_[voxel(x, y, z)];
        for (int i = 0; i < 3; ++i) {
          if (!views_[i]) continue;
          const ExemplarIndex& c = *coarser.views_[i];
          const int a = col_axis(i), b = row_axis(i);
          child[i] = views_[i]->clamped_index(2 * c.centre_u(parent[i]) + (p[a] & 1), 2 * c.centre_v(parent[i]) + (p[b] & 1));
        }
        // The offset moves a view's texel along its slice axes only, so the
        // two children along view i's own axis would share its texel: every
        // level doubled that extrusion (64^3 crackedground: 94 % of each
        // view's texels equal to their neighbour's along its own axis, 72 %
        // of the voxels equal to their x-neighbour; docs/solid.md). The odd
        // child takes instead the view-i texel of the table triple of the
        // next view's texel, which did move along that axis.
        const Triple moved = child;
        for (int i = 0; i < 3; ++i) {
          if (!views_[i] || !(p[i] & 1)) continue;
          const int j = views_[(i + 1) % 3] ? (i + 1) % 3 : (i + 2) % 3;
          if (j != i && views_[j]) child[i] = table_.of(j, moved[j])[0][i];
        }
      }
    }
    progress.advance((r1 - r0) * std::size_t(dims_[0]) - (r1 - r0));
  });
}

float CoordinateSolver::correct_voxel(const std::array<int, 3>& p, std::vector<Triple>& candidates, Triple& best) const {
  // The neighbours' features: per active view, its four crossbar neighbours
  // in the slice (dir 0/1: -/+ along the columns, 2/3: along the rows).
  struct Target {
    const float* f = nullptr;  // neighbour's feature in this view (nullptr: outside)
    int du = 0, dv = 0;        // its offset in the exemplar
  };
  std::array<std::array<Target, 4>, 3> targets{};
  std::array<std::int64_t, 6> nb{};  // face neighbours: axis * 2 + (s > 0)
  for (int axis = 0; axis < 3; ++axis)
    for (int s = 0; s < 2; ++s) nb[axis * 2 + s] = neighbour(p, axis, s ? 1 : -1);

  candidates.clear();
  auto add = [&](const Triple& t) { candidates.push_back(t); };
  add(coords_[voxel(p[0], p[1], p[2])]);
  // Whole-triple coherence: a neighbour's triple moved back by the step to it.
  for (int axis = 0; axis < 3; ++axis)
    for (int s = 0; s < 2; ++s) {
      if (nb[axis * 2 + s] < 0) continue;
      Triple t = coords_[std::size_t(nb[axis * 2 + s])];
      const int step = s ? 1 : -1;
      for (int i = 0; i < 3; ++i) {
        if (!views_[i] || axis == i) continue;
        t[i] = axis == col_axis(i) ? shift(i, t[i], -step, 0) : shift(i, t[i], 0, -step);
      }
      add(t);
    }
  // Per view: the neighbours' texels moved back (k-coherence) and their
  // k most similar texels, each with its crossbar triples.
  for (int i = 0; i < 3; ++i) {
    if (!views_[i]) continue;
    const int axes[2] = {col_axis(i), row_axis(i)};
    for (int a = 0; a < 2; ++a)
      for (int s = 0; s < 2; ++s) {
        const std::int64_t w = nb[axes[a] * 2 + s];
        if (w < 0) continue;
        const int step = s ? 1 : -1;
        const int du = a == 0 ? step : 0, dv = a == 1 ? step : 0;
        const std::int32_t there = coords_[std::size_t(w)][i];
        targets[i][a * 2 + s] = {feature(i, there), du, dv};
        const std::int32_t q = shift(i, there, -du, -dv);
        for (int r = 0; r < table_.per_texel(); ++r) add(table_.of(i, q)[r]);
        if (k_ == 0) continue;
        const std::int32_t* similar = views_[i]->similar(q);
        for (int k = 0; k < k_; ++k)
          if (similar[k] >= 0) add(table_.of(i, similar[k])[0]);
      }
  }
  // The current triple first: it wins ties (no drift between equals).
  const Triple current = candidates[0];
  std::sort(candidates.begin() + 1, candidates.end());
  candidates.erase(std::unique(candidates.begin() + 1, candidates.end()), candidates.end());

  float best_cost = std::numeric_limits<float>::max();
  const int line_dims = table_.line_dims();
  for (std::size_t ci = 0; ci < candidates.size(); ++ci) {
    const Triple& t = candidates[ci];
    if (ci > 0 && t == current) continue;
    // Each neighbour's and each crossbar's mismatch counts by its Euclidean
    // distance, not its square: squared, a flat texel that half-fits every
    // neighbour beat one that fits three exactly and misses one, and the
    // solids went flat (64^3 stone33: shown texels' mean exemplar gradient
    // 20.6 against the exemplar's 28.4, contrast 0.70; docs/solid.md).
    // The neighbourhood match first, then the consistency: the features
    // (8 floats per texel) stay in cache, the 7-texel lines often do not,
    // and most candidates have lost before their lines are read.
    float cost = 0.0f;
    for (int i = 0; i < 3 && cost < best_cost; ++i) {
      if (!views_[i]) continue;
      const int d = dims_pca_[i];
      for (const Target& tg : targets[i]) {
        if (!tg.f || cost >= best_cost) continue;  // costs only grow: this one has lost
        const float* f = feature(i, shift(i, t[i], tg.du, tg.dv));
        float d2 = 0.0f;
        for (int c = 0; c < d; ++c) {
          const float e = f[c] - tg.f[c];
          d2 += e * e;
        }
        cost += std::sqrt(d2);
      }
    }
    // Consistency: the triple's texels must show the same lines where their
    // slices cross (without it, three independent 2D syntheses cost nothing).
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b) {
        if (!views_[a] || !views_[b] || cost >= best_cost) continue;
        const int axis = shared_axis(a, b);
        const float* la = table_.line(a, axis, t[a]);
        const float* lb = table_.line(b, axis, t[b]);
        float d = 0.0f;
        for (int c = 0; c < line_dims; ++c) d += (la[c] - lb[c]) * (la[c] - lb[c]);
        cost += consistency_ * std::sqrt(d);
      }
    if (cost < best_cost) {
      best_cost = cost;
      best = t;
    }
  }
  return best_cost;
}

void CoordinateSolver::correct(StageProgress& progress) {
  // Sub-passes: voxels of one parity class along every axis, so none of a
  // sub-pass's voxels reads another's (face neighbours differ in parity).
  std::array<int, 3> classes{};
  for (int a = 0; a < 3; ++a) classes[a] = wrap_ && (dims_[a] & 1) && dims_[a] > 1 ? 3 : std::min(dims_[a], 2);
  double total = 0.0;
  for (int cz = 0; cz < classes[2]; ++cz)
    for (int cy = 0; cy < classes[1]; ++cy) {
      // Rows (y, z) of this class; each chunk handles its rows' voxels of class cx.
      std::vector<std::array<int, 2>> rows;
      for (int z = 0; z < dims_[2]; ++z)
        for (int y = 0; y < dims_[1]; ++y)
          if (parity_class(z, dims_[2], wrap_) == cz && parity_class(y, dims_[1], wrap_) == cy) rows.push_back({y, z});
      for (int cx = 0; cx < classes[0]; ++cx) {
        std::vector<double> row_cost(rows.size(), 0.0);
        parallel_chunks(rows.size(), 16, progress, [&](std::size_t r0, std::size_t r1) {
          std::vector<Triple> candidates;
          std::size_t done = 0;
          for (std::size_t r = r0; r < r1; ++r) {
            for (int x = 0; x < dims_[0]; ++x) {
              if (parity_class(x, dims_[0], wrap_) != cx) continue;
              const std::array<int, 3> p{x, rows[r][0], rows[r][1]};
              Triple best = coords_[voxel(p[0], p[1], p[2])];
              row_cost[r] += correct_voxel(p, candidates, best);
              coords_[voxel(p[0], p[1], p[2])] = best;
              ++done;
            }
          }
          progress.advance(done - (r1 - r0));  // parallel_chunks adds one per row
        });
        for (double c : row_cost) total += c;  // in row order: deterministic
      }
    }
  energy_ = total / double(coords_.size());
}

std::array<float, 3> CoordinateSolver::view_costs(const std::array<int, 3>& p) const {
  const Triple& t = coords_[voxel(p[0], p[1], p[2])];
  std::array<float, 3> cost{0.0f, 0.0f, 0.0f};
  for (int i = 0; i < 3; ++i) {
    if (!views_[i]) continue;
    const int axes[2] = {col_axis(i), row_axis(i)};
    for (int a = 0; a < 2; ++a)
      for (int s = 0; s < 2; ++s) {
        const std::int64_t w = neighbour(p, axes[a], s ? 1 : -1);
        if (w < 0) continue;
        const int step = s ? 1 : -1;
        const float* f = feature(i, shift(i, t[i], a == 0 ? step : 0, a == 1 ? step : 0));
        const float* g = feature(i, coords_[std::size_t(w)][i]);
        for (int c = 0; c < dims_pca_[i]; ++c) cost[i] += (f[c] - g[c]) * (f[c] - g[c]);
      }
  }
  return cost;
}

Volume CoordinateSolver::colours(const std::array<const Image*, 3>& images, StageProgress& progress) const {
  int channels = 0;
  for (int i = 0; i < 3; ++i)
    if (views_[i]) channels = images[i]->channels();
  Volume out(dims_[0], dims_[1], dims_[2], channels);
  // Each voxel takes the texel of the view whose slice neighbourhood agrees
  // best with its neighbours' (the three texels' mean blurs wherever the
  // triple's views disagree).
  parallel_chunks(coords_.size(), 1 << 12, progress, [&](std::size_t v0, std::size_t v1) {
    for (std::size_t v = v0; v < v1; ++v) {
      const std::array<int, 3> p{int(v % dims_[0]), int(v / dims_[0] % dims_[1]), int(v / dims_[0] / dims_[1])};
      const std::array<float, 3> cost = view_costs(p);
      int pick = -1;
      for (int i = 0; i < 3; ++i)
        if (views_[i] && (pick < 0 || cost[i] < cost[pick])) pick = i;
      const std::int32_t j = coords_[v][pick];
      const float* src = images[pick]->data() + images[pick]->offset(views_[pick]->centre_u(j), views_[pick]->centre_v(j));
      std::copy(src, src + channels, out.data() + v * channels);
    }
  });
  return out;
}

}  // namespace exsynth::solid
