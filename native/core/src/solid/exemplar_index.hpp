#pragma once
// Everything the search and optimisation phases need to know about one
// exemplar at one pyramid level: its n x n neighbourhoods (only those fully
// inside the image: exemplars are not assumed to tile), their PCA
// coefficients, k-coherence sets, and channel histograms.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "search/pca.hpp"

namespace exsynth::solid {

using search::RowMatrixXf;

class ExemplarIndex {
 public:
  /// How the k-coherence sets are found: nanoflann k-NN in PCA space (the
  /// default: ~N log N), or the brute-force reference (all pairs, N^2; the
  /// tests compare the two).
  enum class Coherence { KdTree, BruteForce };

  /// Builds everything; `coherence_k` = 0 skips the k-coherence sets.
  /// Progress goes to [lo, hi] of `ctx` under the stage name `stage`, and
  /// each part checks for cancellation at chunk granularity.
  /// `channel_lo/hi`: the value ranges of the first K <= C channels, the
  /// ones histograms are kept for.
  ExemplarIndex(const Image& image, int n, double pca_variance, int max_pca_dims, int coherence_k, int bins,
                const std::vector<float>& channel_lo, const std::vector<float>& channel_hi, ExecContext* ctx,
                const std::string& stage, double lo, double hi, Coherence coherence = Coherence::KdTree);

  const Image& image() const { return image_; }
  int n() const { return n_; }
  /// Window offsets run over [-lo, n - 1 - lo] on both axes.
  int lo() const { return n_ / 2; }
  int dims() const { return int(image_.channels()) * n_ * n_; }

  /// Valid neighbourhood centres: index j <-> pixel (lo + j % vw, lo + j / vw).
  int count() const { return vw_ * vh_; }
  // Tables, not j % vw: the search and optimisation ask millions of times.
  int centre_u(int j) const { return centre_u_[std::size_t(j)]; }
  int centre_v(int j) const { return centre_v_[std::size_t(j)]; }
  /// Index of the valid centre at (u, v), or -1 when its window leaves the image.
  int index_of(int u, int v) const {
    const int a = u - lo(), b = v - lo();
    return (a < 0 || b < 0 || a >= vw_ || b >= vh_) ? -1 : b * vw_ + a;
  }
  /// Clamps (u, v) to the valid centres and returns the index.
  int clamped_index(int u, int v) const;

  const RowMatrixXf& neighbourhoods() const { return neigh_; }  ///< count x dims
  const search::Pca& pca() const { return pca_; }
  const RowMatrixXf& coefficients() const { return coeffs_; }    ///< count x pca dims
  /// k most similar other neighbourhoods of j (indices), k = coherence_k().
  const std::int32_t* similar(int j) const { return similar_.data() + std::size_t(j) * k_; }
  int coherence_k() const { return k_; }

  int bins() const { return bins_; }
  /// Histogram bin of channel c of pixel p (row-major pixel index).
  std::uint8_t bin(std::size_t p, int c) const { return bin_[p * hist_channels_ + c]; }
  /// Normalised histogram: fraction of pixels in bin b of channel c.
  double histogram(int c, int b) const { return hist_[std::size_t(c) * bins_ + b]; }

 private:
  void build_neighbourhoods(StageProgress& progress);
  void project(StageProgress& progress);
  void build_coherence_kdtree(StageProgress& progress);
  void build_coherence_brute_force(StageProgress& progress);
  /// Windows i and j overlap by more than half along both axes (near-copies).
  bool overlaps(int i, int j) const {
    const int half = n_ / 2;
    return std::abs(centre_u(i) - centre_u(j)) < half && std::abs(centre_v(i) - centre_v(j)) < half;
  }

  Image image_;
  int n_, vw_, vh_, k_ = 0, bins_, hist_channels_ = 0;
  std::vector<std::int32_t> centre_u_, centre_v_;
  RowMatrixXf neigh_, coeffs_;
  search::Pca pca_;
  std::vector<std::int32_t> similar_;
  std::vector<std::uint8_t> bin_;
  std::vector<double> hist_;
};

/// Histogram bin of value x for a channel spanning [lo, hi].
inline int value_bin(float x, float lo, float hi, int bins) {
  const float t = hi > lo ? (x - lo) / (hi - lo) : 0.0f;
  const int b = int(t * bins);
  return b < 0 ? 0 : (b >= bins ? bins - 1 : b);
}

}  // namespace exsynth::solid
