#pragma once
// The k-coherence search's inner loop: which of a query's candidate windows
// is nearest in PCA space. Kept apart so the tests can compare it with a
// plain scan (tests/cpp/test_solid.cpp, CandidateScoring).
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace exsynth::solid {

/// PCA coefficient rows laid out for the scoring: row j at base + j * stride,
/// base 64-byte aligned and stride a multiple of 16 floats (whole cache lines),
/// d (the padded PCA dimension, a multiple of 8) <= stride.
struct CoefficientRows {
  const float* base = nullptr;
  std::size_t stride = 0;
  const float* row(int j) const { return base + std::size_t(j) * stride; }
};

/// The first of the `n` candidates `cand` (in their order) with the least
/// squared distance to the query `q` over its `d` coefficients, the distance
/// summed over 8-float blocks in order; -1 when no distance is finite (or
/// n = 0). `scratch` is reused between calls.
///
/// Partial distances: most candidates lose within the first,
/// highest-variance blocks, so a candidate's sum stops as soon as it reaches
/// the best so far (exact: sums of non-negative floats never decrease). The
/// first two blocks (one cache line) of every candidate are summed first in
/// a branch-free pass so their loads overlap (inline, the early exit's
/// unpredictable branches serialised them: ~40 % of the scoring in perf),
/// then the scan goes on as if they had been summed inline: same sums, same
/// order, same ties.
inline int nearest_candidate(const float* q, int d, const CoefficientRows& rows, const int* cand, std::size_t n,
                             std::vector<float>& scratch) {
  using Block = Eigen::Matrix<float, 8, 1>;
  const bool two = d >= 16;
  scratch.resize(2 * n);
  const Eigen::Map<const Block> q0(q), q1(q + (two ? 8 : 0));
  for (std::size_t m = 0; m < n; ++m) {
    const float* e = rows.row(cand[m]);
    scratch[2 * m] = (Eigen::Map<const Block>(e) - q0).squaredNorm();
    if (two) scratch[2 * m + 1] = (Eigen::Map<const Block>(e + 8) - q1).squaredNorm();
  }
  float bd = std::numeric_limits<float>::max();
  int best = -1;
  for (std::size_t m = 0; m < n; ++m) {
    const float* e = rows.row(cand[m]);
    float acc = 0.0f;
    int t = 0;
    if (acc < bd) acc += scratch[2 * m], t = 8;
    if (two && acc < bd) acc += scratch[2 * m + 1], t = 16;
    for (; t < d && acc < bd; t += 8)
      acc += (Eigen::Map<const Block>(e + t) - Eigen::Map<const Block>(q + t)).squaredNorm();
    if (t >= d && acc < bd) bd = acc, best = cand[m];
  }
  return best;
}

}  // namespace exsynth::solid
