#pragma once
// Iterated greedy pairing between a patch's overlap points (sources) and the
// output's points there (targets), the pairs a thin-plate spline warp fits.
// Round 0 accepts candidate pairs cheapest first, each point at most once,
// by the paper's cost (its Equation 2) with positions in point spacings s:
// c = w_p |dp|^2 / s^2 + (w_n / 2)(1 - n.n') + w_v (sigma - sigma')^2
// (thresholds refuse far, misoriented or unlike pairs). Later rounds add the
// paper's coherence g = w_l | |d| - f_l | / s + (w_d / 2)(1 - f_d . d / |d|):
// f_l and f_d are the Gaussian-weighted mean length and the normalised mean
// direction of the accepted pairs' displacements around the source, so
// neighbouring pairs move alike and do not cross.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace exsynth::points {

struct PairPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();
  Eigen::Vector3f n = Eigen::Vector3f::UnitZ();
  float sigma = 0;  ///< surface variation
};

struct PairingOptions {
  double spacing = 1.0;           ///< s: the point spacing
  double w_p = 1, w_n = 1, w_v = 1;
  double max_distance = 3.0;      ///< in spacings
  double min_normal_dot = 0.5;
  double max_variation = 0.1;
  double w_l = 1, w_d = 1;
  double coherence_radius = 2.5;  ///< Gaussian width of g, in spacings (cut off at twice that)
  int iterations = 3;
  int candidates = 4;             ///< nearest targets tried per source
};

struct PointPair {
  std::uint32_t source, target;
  float cost;
};

std::vector<PointPair> greedy_pairs(const std::vector<PairPoint>& sources, const std::vector<PairPoint>& targets,
                                    const PairingOptions& opt);

}  // namespace exsynth::points
