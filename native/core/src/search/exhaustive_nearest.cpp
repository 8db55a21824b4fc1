#include "search/exhaustive_nearest.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace exsynth::search {

ExhaustiveNearest::ExhaustiveNearest(const RowMatrixXf& rows) : rows_(rows), norms_(rows.rowwise().squaredNorm()) {
  max_norm_ = norms_.size() ? norms_.maxCoeff() : 0.0f;
}

int ExhaustiveNearest::brute_force(const RowMatrixXf& rows, const RowMatrixXf& queries, Eigen::Index k) {
  int best = -1;
  ((rows.rowwise() - queries.row(k)).rowwise().squaredNorm()).minCoeff(&best);
  return best;
}

// Rounding: a d-term float dot product or squared norm is within about
// d * 2^-24 * (|q| + |c|)^2 <= d * 2^-23 * (|q|^2 + |c|^2) of its exact value
// (the solver's 32 PCA dimensions: 4e-6 relative), for the GEMM's distances
// and the re-ranking's alike. A row whose GEMM distance is within twice that
// of the batch row's GEMM minimum may be the re-ranking's minimum; 1e-4
// relative covers it with margin up to 400 dimensions (more: 4 d 2^-23), and
// in practice leaves one to a few rows to re-rank.
constexpr float kRelativeTolerance = 1e-4f;

void ExhaustiveNearest::nearest(const RowMatrixXf& queries, Eigen::Index count, int* best, RowMatrixXf& scratch) const {
  const Eigen::Index n = rows_.rows();
  if (n == 0) {
    std::fill(best, best + count, -1);
    return;
  }
  scratch.resize(count, n);
  scratch.noalias() = queries.topRows(count) * rows_.transpose();  // q . c
  for (Eigen::Index k = 0; k < count; ++k) {
    float* g = scratch.row(k).data();
    float lowest = std::numeric_limits<float>::infinity();
    for (Eigen::Index j = 0; j < n; ++j) {
      g[j] = norms_[j] - 2.0f * g[j];  // |c - q|^2 - |q|^2
      lowest = std::min(lowest, g[j]);
    }
    const float q2 = queries.row(k).squaredNorm();
    if (!std::isfinite(lowest) || !std::isfinite(q2)) {  // non-finite query: the reference's own answer
      best[k] = brute_force(rows_, queries, k);
      continue;
    }
    const float relative = std::max(kRelativeTolerance, 4.0f * float(rows_.cols()) * std::numeric_limits<float>::epsilon());
    const float bound = lowest + relative * (q2 + max_norm_);
    int pick = -1;
    float pick_d = 0.0f;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (g[j] > bound) continue;
      const float d = ((rows_.middleRows(j, 1).rowwise() - queries.row(k)).rowwise().squaredNorm())(0);
      if (pick < 0 || d < pick_d) pick = int(j), pick_d = d;
    }
    best[k] = pick;
  }
}

}  // namespace exsynth::search
