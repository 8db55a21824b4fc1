#include "solid/exemplar_index.hpp"

#include <algorithm>
#include <limits>

#include "exsynth/parallel.hpp"

namespace exsynth::solid {

ExemplarIndex::ExemplarIndex(const Image& image, int n, double pca_variance, int max_pca_dims, int coherence_k,
                             int bins, const std::vector<float>& channel_lo, const std::vector<float>& channel_hi,
                             StageProgress* progress)
    : image_(image), n_(n), vw_(image.width() - n + 1), vh_(image.height() - n + 1), bins_(bins) {
  build_neighbourhoods();
  pca_ = search::fit_pca(neigh_, pca_variance, max_pca_dims);
  // Zero columns up to a multiple of 8: coefficients then compare in whole
  // 8-float SIMD blocks, and the zeros add nothing to any distance.
  const Eigen::Index d = pca_.basis.cols(), padded = (d + 7) / 8 * 8;
  pca_.basis.conservativeResize(Eigen::NoChange, padded);
  pca_.basis.rightCols(padded - d).setZero();
  coeffs_ = pca_.project(neigh_);
  if (coherence_k > 0) build_coherence(coherence_k, progress);

  const int C = image_.channels();
  bin_.resize(image_.pixel_count() * C);
  hist_.assign(std::size_t(C) * bins_, 0.0);
  for (std::size_t p = 0; p < image_.pixel_count(); ++p)
    for (int c = 0; c < C; ++c) {
      const int b = value_bin(image_.data()[p * C + c], channel_lo[c], channel_hi[c], bins_);
      bin_[p * C + c] = std::uint8_t(b);
      hist_[std::size_t(c) * bins_ + b] += 1.0 / double(image_.pixel_count());
    }
}

int ExemplarIndex::clamped_index(int u, int v) const {
  const int a = std::clamp(u - lo(), 0, vw_ - 1), b = std::clamp(v - lo(), 0, vh_ - 1);
  return b * vw_ + a;
}

void ExemplarIndex::build_neighbourhoods() {
  const int C = image_.channels();
  neigh_.resize(count(), dims());
  for (int j = 0; j < count(); ++j) {
    const int u0 = centre_u(j) - lo(), v0 = centre_v(j) - lo();
    float* row = neigh_.row(j).data();
    for (int dv = 0; dv < n_; ++dv) {
      const float* src = image_.data() + image_.offset(u0, v0 + dv);
      std::copy(src, src + std::size_t(n_) * C, row + std::size_t(dv) * n_ * C);
    }
  }
}

// For every neighbourhood, its k nearest others in PCA space, skipping
// windows that overlap it by more than half (near-copies of itself, which
// would give the search no new choices). Brute force with a GEMM per tile of
// rows: exact, deterministic and fast for exemplars up to a few hundred
// pixels across.
void ExemplarIndex::build_coherence(int k, StageProgress* progress) {
  const int N = count();
  k_ = std::min(k, std::max(0, N - 1));
  similar_.assign(std::size_t(N) * std::max(k_, 1), -1);
  if (k_ == 0) return;
  const Eigen::VectorXf norms = coeffs_.rowwise().squaredNorm();
  const int tile = 128;
  const int tiles = (N + tile - 1) / tile;
  StageProgress local(nullptr, "", 0, 1, 1);
  StageProgress& prog = progress ? *progress : local;
  parallel_chunks(std::size_t(tiles), 1, prog, [&](std::size_t begin, std::size_t end) {
    std::vector<std::pair<float, int>> best;
    for (std::size_t t = begin; t < end; ++t) {
      const int r0 = int(t) * tile, rows = std::min(tile, N - r0);
      const RowMatrixXf dots = coeffs_.middleRows(r0, rows) * coeffs_.transpose();
      for (int r = 0; r < rows; ++r) {
        const int j = r0 + r;
        const int ju = centre_u(j) - lo(), jv = centre_v(j) - lo();
        best.clear();
        auto consider = [&](int i) {
          const float d = norms[j] + norms[i] - 2.0f * dots(r, i);
          if (int(best.size()) < k_) {
            best.emplace_back(d, i);
            std::push_heap(best.begin(), best.end());
          } else if (std::make_pair(d, i) < best.front()) {
            std::pop_heap(best.begin(), best.end());
            best.back() = {d, i};
            std::push_heap(best.begin(), best.end());
          }
        };
        const int half = n_ / 2;
        for (int iv = 0; iv < vh_; ++iv) {
          const bool near_row = std::abs(iv - jv) < half;
          for (int iu = 0; iu < vw_; ++iu) {
            if (near_row && std::abs(iu - ju) < half) continue;
            consider(iv * vw_ + iu);
          }
        }
        std::sort(best.begin(), best.end());
        for (int q = 0; q < int(best.size()); ++q) similar_[std::size_t(j) * k_ + q] = best[q].second;
      }
    }
  });
}

}  // namespace exsynth::solid
