#include <Eigen/Geometry>

#include "points/pairing.hpp"

#include <algorithm>
#include <cmath>

#include "search/point_index.hpp"

namespace exsynth::points {
namespace {

struct Candidate {
  std::uint32_t source, target;
  float base;  ///< c
  float total; ///< c + g of the current round
};

std::vector<Candidate> candidate_pairs(const std::vector<PairPoint>& sources, const std::vector<PairPoint>& targets,
                                       const PairingOptions& opt) {
  std::vector<Eigen::Vector3f> tp(targets.size());
  for (std::size_t i = 0; i < targets.size(); ++i) tp[i] = targets[i].p;
  const search::PointIndex index(tp);
  const double s2 = opt.spacing * opt.spacing;
  const double max_d2 = opt.max_distance * opt.max_distance * s2;
  std::vector<Candidate> out;
  std::vector<std::size_t> idx(std::size_t(std::max(1, opt.candidates)));
  std::vector<float> d2(idx.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::size_t m = index.knn(sources[i].p, idx.size(), idx.data(), d2.data());
    for (std::size_t k = 0; k < m; ++k) {
      const PairPoint& t = targets[idx[k]];
      const double dot = sources[i].n.dot(t.n), dv = std::abs(sources[i].sigma - t.sigma);
      if (double(d2[k]) > max_d2 || dot < opt.min_normal_dot || dv > opt.max_variation) continue;
      const float c = float(opt.w_p * double(d2[k]) / s2 + opt.w_n * (1.0 - dot) + opt.w_v * dv);
      out.push_back({std::uint32_t(i), std::uint32_t(idx[k]), c, c});
    }
  }
  return out;
}

std::vector<PointPair> accept_greedily(std::vector<Candidate> cands, std::size_t ns, std::size_t nt) {
  std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
    if (a.total != b.total) return a.total < b.total;
    if (a.source != b.source) return a.source < b.source;
    return a.target < b.target;
  });
  std::vector<char> used_s(ns, 0), used_t(nt, 0);
  std::vector<PointPair> pairs;
  for (const Candidate& c : cands) {
    if (used_s[c.source] || used_t[c.target]) continue;
    used_s[c.source] = used_t[c.target] = 1;
    pairs.push_back({c.source, c.target, c.total});
  }
  return pairs;
}

}  // namespace

std::vector<PointPair> greedy_pairs(const std::vector<PairPoint>& sources, const std::vector<PairPoint>& targets,
                                    const PairingOptions& opt) {
  if (sources.empty() || targets.empty()) return {};
  std::vector<Candidate> cands = candidate_pairs(sources, targets, opt);
  std::vector<PointPair> pairs = accept_greedily(cands, sources.size(), targets.size());
  const double s2 = opt.spacing * opt.spacing;
  const float r = float(opt.coherence_radius * opt.spacing);
  const double inv_r2 = 1.0 / (double(r) * r);
  std::vector<std::pair<std::size_t, float>> near;
  for (int round = 1; round < opt.iterations && !pairs.empty(); ++round) {
    // The accepted pairs' displacements, looked up by their source position.
    std::vector<Eigen::Vector3f> at(pairs.size());
    std::vector<Eigen::Vector3f> disp(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      at[k] = sources[pairs[k].source].p;
      disp[k] = targets[pairs[k].target].p - at[k];
    }
    const search::PointIndex index(at);
    // Candidates are grouped by source (candidate_pairs emits them so): one
    // neighbourhood query per source serves all its candidates.
    for (std::size_t c0 = 0; c0 < cands.size();) {
      std::size_t c1 = c0;
      while (c1 < cands.size() && cands[c1].source == cands[c0].source) ++c1;
      const Eigen::Vector3f& sp = sources[cands[c0].source].p;
      index.radius(sp, 2.0f * r, near);  // weights beyond 2 r are below e^-4
      for (std::size_t ci = c0; ci < c1; ++ci) {
        Candidate& c = cands[ci];
        const Eigen::Vector3f d = targets[c.target].p - sp;
        const double len = d.norm();
        double wsum = 0, g = 0;
        for (const auto& [k, dist2] : near) {
          if (pairs[k].source == c.source) continue;
          const double w = std::exp(-double(dist2) * inv_r2);
          const double lk = disp[k].norm();
          const double dir = (len > 1e-12 && lk > 1e-12) ? 1.0 - double(d.dot(disp[k])) / (len * lk) : 0.0;
          g += w * (opt.w_l * (len - lk) * (len - lk) / s2 + opt.w_d * dir);
          wsum += w;
        }
        c.total = c.base + float(wsum > 0 ? g / wsum : 0.0);
      }
      c0 = c1;
    }
    pairs = accept_greedily(cands, sources.size(), targets.size());
  }
  return pairs;
}

}  // namespace exsynth::points
