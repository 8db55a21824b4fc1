#include "solid/exemplar_index.hpp"

#include <algorithm>
#include <limits>

#include "exsynth/parallel.hpp"
#include "search/kd_tree.hpp"

namespace exsynth::solid {

ExemplarIndex::ExemplarIndex(const Image& image, int n, double pca_variance, int max_pca_dims, int coherence_k,
                             int bins, const std::vector<float>& channel_lo, const std::vector<float>& channel_hi,
                             ExecContext* ctx, const std::string& stage, double lo, double hi, Coherence coherence)
    : image_(image), n_(n), vw_(image.width() - n + 1), vh_(image.height() - n + 1), bins_(bins) {
  // Window centres as tables (n_ / 2 = lo(); the parameter lo shadows it).
  centre_u_.resize(std::size_t(std::max(count(), 0)));
  centre_v_.resize(centre_u_.size());
  for (int j = 0; j < count(); ++j) centre_u_[std::size_t(j)] = n_ / 2 + j % vw_, centre_v_[std::size_t(j)] = n_ / 2 + j / vw_;
  // Shares of the stage's progress, roughly as the parts cost at 512^2 RGB.
  const double split = coherence_k > 0 ? lo + 0.35 * (hi - lo) : hi;
  const std::size_t rows = std::size_t(count());
  {
    StageProgress progress(ctx, stage + " (neighbourhoods, PCA)", lo, split, 3 * rows);
    build_neighbourhoods(progress);
    pca_ = search::fit_pca(neigh_, pca_variance, max_pca_dims, &progress);
    progress.advance(rows);
    // Zero columns up to a multiple of 8: coefficients then compare in whole
    // 8-float SIMD blocks, and the zeros add nothing to any distance.
    const Eigen::Index d = pca_.basis.cols(), padded = (d + 7) / 8 * 8;
    pca_.basis.conservativeResize(Eigen::NoChange, padded);
    pca_.basis.rightCols(padded - d).setZero();
    project(progress);
  }
  if (coherence_k > 0) {
    k_ = std::min(coherence_k, std::max(0, count() - 1));
    similar_.assign(std::size_t(count()) * std::max(k_, 1), -1);
    StageProgress progress(ctx, stage + " (k-coherence sets)", split, hi, rows);
    if (k_ > 0) {
      if (coherence == Coherence::KdTree) build_coherence_kdtree(progress);
      else build_coherence_brute_force(progress);
    }
  }

  // Histograms of the first K channels, those channel_lo/hi span (the rest,
  // such as the feature-distance channel, are guides, not values to match).
  const int C = image_.channels(), K = hist_channels_ = int(channel_lo.size());
  bin_.resize(image_.pixel_count() * K);
  hist_.assign(std::size_t(K) * bins_, 0.0);
  for (std::size_t p = 0; p < image_.pixel_count(); ++p)
    for (int c = 0; c < K; ++c) {
      const int b = value_bin(image_.data()[p * C + c], channel_lo[c], channel_hi[c], bins_);
      bin_[p * K + c] = std::uint8_t(b);
      hist_[std::size_t(c) * bins_ + b] += 1.0 / double(image_.pixel_count());
    }
}

int ExemplarIndex::clamped_index(int u, int v) const {
  const int a = std::clamp(u - lo(), 0, vw_ - 1), b = std::clamp(v - lo(), 0, vh_ - 1);
  return b * vw_ + a;
}

// Rows per parallel chunk: small enough that a cancel is seen within
// milliseconds, large enough to amortise the scheduling.
constexpr std::size_t kRowsPerChunk = 1024;

void ExemplarIndex::build_neighbourhoods(StageProgress& progress) {
  const int C = image_.channels();
  neigh_.resize(count(), dims());
  parallel_chunks(std::size_t(count()), kRowsPerChunk, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t jj = begin; jj < end; ++jj) {
      const int j = int(jj);
      const int u0 = centre_u(j) - lo(), v0 = centre_v(j) - lo();
      float* row = neigh_.row(j).data();
      for (int dv = 0; dv < n_; ++dv) {
        const float* src = image_.data() + image_.offset(u0, v0 + dv);
        std::copy(src, src + std::size_t(n_) * C, row + std::size_t(dv) * n_ * C);
      }
    }
  });
}

void ExemplarIndex::project(StageProgress& progress) {
  coeffs_.resize(count(), pca_.basis.cols());
  parallel_chunks(std::size_t(count()), kRowsPerChunk, progress, [&](std::size_t begin, std::size_t end) {
    const Eigen::Index r0 = Eigen::Index(begin), rows = Eigen::Index(end - begin);
    coeffs_.middleRows(r0, rows).noalias() = (neigh_.middleRows(r0, rows).rowwise() - pca_.mean) * pca_.basis;
  });
}

// For every neighbourhood, its k nearest others in PCA space, skipping
// windows that overlap it by more than half (near-copies of itself, which
// would give the search no new choices). Exact k-NN of every window in the
// full PCA space is slow in a k-d tree (32 dimensions: 19 s at 121^2
// windows on a shared, loaded machine) and mostly returns those near-copies. So: a tree over
// the windows at even (u, v) only, in their leading kTreeDims
// coefficients, proposes kCandidates non-overlapping windows; each and its
// 8 one-pixel shifts are ranked by the full PCA distance. ~N log N; the
// tests compare the sets' distances with the brute force below.
constexpr int kTreeDims = 8, kCandidates = 8;
constexpr float kTreeEps = 1.0f;  // nanoflann approximation: (1 + eps) times the true k-th distance

void ExemplarIndex::build_coherence_kdtree(StageProgress& progress) {
  const int N = count();
  const int tree_dims = std::min<int>(kTreeDims, int(coeffs_.cols()));
  std::vector<int> grid;  // windows at even (u, v)
  for (int j = 0; j < N; ++j)
    if (((centre_u(j) - lo()) & 1) == 0 && ((centre_v(j) - lo()) & 1) == 0) grid.push_back(j);
  RowMatrixXf leading(Eigen::Index(grid.size()), tree_dims);
  for (std::size_t g = 0; g < grid.size(); ++g) leading.row(Eigen::Index(g)) = coeffs_.row(grid[g]).leftCols(tree_dims);
  const search::KdTree tree(leading);
  const int half = n_ / 2, near = half * half;  // grid windows that can overlap j by > half (at most)
  const std::size_t K = std::min(grid.size(), std::size_t(near + kCandidates));
  parallel_chunks(std::size_t(N), kRowsPerChunk, progress, [&](std::size_t begin, std::size_t end) {
    std::vector<Eigen::Index> idx(K);
    std::vector<float> d2(K);
    std::vector<std::pair<float, int>> ranked;
    // seen[i] = j + 1 once window i is ranked for j: neighbouring grid
    // windows' shifts propose the same window, which is ranked once. Then
    // only the k best are ordered (a full sort and unique were ~4 % of a
    // turned exemplar's 128^3 solid; the same sets: bench/solid_hashes.py).
    std::vector<std::int32_t> seen(std::size_t(N), 0);
    for (std::size_t jj = begin; jj < end; ++jj) {
      const int j = int(jj);
      Eigen::Matrix<float, 1, Eigen::Dynamic> q = coeffs_.row(j).leftCols(tree_dims);
      const std::size_t got = tree.knn(q.data(), K, idx.data(), d2.data(), kTreeEps);
      ranked.clear();
      for (std::size_t t = 0; t < got; ++t) {
        const int g = grid[std::size_t(idx[t])];
        for (int dv = -1; dv <= 1; ++dv)
          for (int du = -1; du <= 1; ++du) {
            const int i = index_of(centre_u(g) + du, centre_v(g) + dv);
            if (i < 0 || seen[std::size_t(i)] == j + 1 || overlaps(j, i)) continue;
            seen[std::size_t(i)] = j + 1;
            ranked.emplace_back((coeffs_.row(i) - coeffs_.row(j)).squaredNorm(), i);
          }
      }
      const int take = std::min<int>(k_, int(ranked.size()));
      std::partial_sort(ranked.begin(), ranked.begin() + take, ranked.end());
      for (int q2 = 0; q2 < take; ++q2) similar_[std::size_t(j) * k_ + q2] = ranked[q2].second;
    }
  });
}

// The reference: all pairs, a GEMM per tile of rows. Exact and
// deterministic, but quadratic in the exemplar's pixel count (16 s at 256^2).
void ExemplarIndex::build_coherence_brute_force(StageProgress& progress) {
  const int N = count();
  const Eigen::VectorXf norms = coeffs_.rowwise().squaredNorm();
  const int tile = 128;
  const int tiles = (N + tile - 1) / tile;
  StageProgress tiles_progress(nullptr, "", 0, 1, 1);
  parallel_chunks(std::size_t(tiles), 1, tiles_progress, [&](std::size_t begin, std::size_t end) {
    std::vector<std::pair<float, int>> best;
    for (std::size_t t = begin; t < end; ++t) {
      progress.check();
      const int r0 = int(t) * tile, rows = std::min(tile, N - r0);
      const RowMatrixXf dots = coeffs_.middleRows(r0, rows) * coeffs_.transpose();
      for (int r = 0; r < rows; ++r) {
        const int j = r0 + r;
        best.clear();
        for (int i = 0; i < N; ++i) {
          if (overlaps(i, j)) continue;
          const float d = norms[j] + norms[i] - 2.0f * dots(r, i);
          if (int(best.size()) < k_) {
            best.emplace_back(d, i);
            std::push_heap(best.begin(), best.end());
          } else if (std::make_pair(d, i) < best.front()) {
            std::pop_heap(best.begin(), best.end());
            best.back() = {d, i};
            std::push_heap(best.begin(), best.end());
          }
        }
        std::sort(best.begin(), best.end());
        for (int q = 0; q < int(best.size()); ++q) similar_[std::size_t(j) * k_ + q] = best[q].second;
      }
      progress.advance(std::size_t(rows));
    }
  });
}

}  // namespace exsynth::solid
