#include <Eigen/Geometry>

#include "points/pairing.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "search/point_grid.hpp"
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
  const double s2 = opt.spacing * opt.spacing;
  const double max_d2 = opt.max_distance * opt.max_distance * s2;
  const float reach = float(opt.max_distance * opt.spacing);
  // The k nearest targets within reach: a radius query on a grid (a sort to
  // build, where a k-d tree's serial build was most of the pairing's time),
  // then the k closest by (distance, index).
  const search::PointGrid index(tp, reach);
  const std::size_t k = std::size_t(std::max(1, opt.candidates));
  // Per source in parallel, then concatenated in source order (the serial
  // pairing was 7 % of a synthesis' wall time): the same list for any thread count.
  std::vector<std::vector<Candidate>> per(sources.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sources.size(), 32), [&](const auto& r) {
    std::vector<std::pair<std::size_t, float>> near;
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      index.radius(sources[i].p, reach, near);
      const auto closer = [](const auto& a, const auto& b) { return a.second != b.second ? a.second < b.second : a.first < b.first; };
      const std::size_t m = std::min(k, near.size());
      std::partial_sort(near.begin(), near.begin() + std::ptrdiff_t(m), near.end(), closer);
      for (std::size_t j = 0; j < m; ++j) {
        const auto [t_idx, dist2] = near[j];
        const PairPoint& t = targets[t_idx];
        const double dot = sources[i].n.dot(t.n), dv = std::abs(sources[i].sigma - t.sigma);
        if (double(dist2) > max_d2 || dot < opt.min_normal_dot || dv > opt.max_variation) continue;
        const float c = float(opt.w_p * double(dist2) / s2 + 0.5 * opt.w_n * (1.0 - dot) + opt.w_v * dv * dv);
        per[i].push_back({std::uint32_t(i), std::uint32_t(t_idx), c, c});
      }
    }
  });
  std::vector<Candidate> out;
  for (const auto& v : per) out.insert(out.end(), v.begin(), v.end());
  return out;
}

std::vector<PointPair> accept_greedily(std::vector<Candidate> cands, std::size_t ns, std::size_t nt) {
  // A total order (source, target are unique per candidate): any sort gives the same list.
  tbb::parallel_sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
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
  const double s = opt.spacing;
  const float r = float(opt.coherence_radius * opt.spacing);
  const double inv_r2 = 1.0 / (double(r) * r);
  for (int round = 1; round < opt.iterations && !pairs.empty(); ++round) {
    // The accepted pairs' displacements, looked up by their source position.
    std::vector<Eigen::Vector3f> at(pairs.size());
    std::vector<Eigen::Vector3f> disp(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      at[k] = sources[pairs[k].source].p;
      disp[k] = targets[pairs[k].target].p - at[k];
    }
    const search::PointGrid index(at, 2.0f * r);
    // Candidates are grouped by source (candidate_pairs emits them so): one
    // neighbourhood query per source serves all its candidates; each group
    // writes only its own candidates, so the groups run in parallel.
    std::vector<std::size_t> group{0};
    for (std::size_t c = 1; c <= cands.size(); ++c)
      if (c == cands.size() || cands[c].source != cands[c - 1].source) group.push_back(c);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, group.size() - 1, 16), [&](const auto& rg) {
      std::vector<std::pair<std::size_t, float>> near;
      for (std::size_t gi = rg.begin(); gi < rg.end(); ++gi) {
        const std::size_t c0 = group[gi], c1 = group[gi + 1];
        const Eigen::Vector3f& sp = sources[cands[c0].source].p;
        index.radius(sp, 2.0f * r, near);  // weights beyond 2 r are below e^-4
        // The neighbours' Gaussian-weighted mean length f_l and mean direction f_d
        // (the same for every candidate of this source).
        double wsum = 0, lsum = 0;
        Eigen::Vector3d dsum = Eigen::Vector3d::Zero();
        for (const auto& [k, dist2] : near) {
          if (pairs[k].source == cands[c0].source) continue;
          const double w = std::exp(-double(dist2) * inv_r2);
          lsum += w * double(disp[k].norm());
          dsum += w * disp[k].template cast<double>();
          wsum += w;
        }
        const double f_l = wsum > 0 ? lsum / wsum : 0.0, dn = dsum.norm();
        for (std::size_t ci = c0; ci < c1; ++ci) {
          Candidate& c = cands[ci];
          const Eigen::Vector3d d = (targets[c.target].p - sp).template cast<double>();
          const double len = d.norm();
          const double dir = (len > 1e-12 && dn > 1e-12) ? 1.0 - dsum.dot(d) / (dn * len) : 0.0;
          c.total = c.base + float(wsum > 0 ? opt.w_l * std::abs(len - f_l) / s + 0.5 * opt.w_d * dir : 0.0);
        }
      }
    });
    pairs = accept_greedily(cands, sources.size(), targets.size());
  }
  return pairs;
}

}  // namespace exsynth::points
