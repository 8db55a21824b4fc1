#pragma once
// The growing output point set: positions, normals and an alive flag per
// point, found by a hashed grid of buckets (cell -> point indices), so a
// patch gathers only the points around it. Points moved by blending stay in
// the bucket they were added to; gather() takes a margin for that.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace exsynth::points {

class OutputStore {
 public:
  explicit OutputStore(float cell) : cell_(cell) {}

  /// sigma: the point's surface variation (carried from the exemplar, so
  /// patches need not recompute it for the points they overlap).
  std::uint32_t add(const Eigen::Vector3f& p, const Eigen::Vector3f& n, float sigma = 0.0f) {
    const auto id = std::uint32_t(positions.size());
    positions.push_back(p);
    normals.push_back(n);
    this->sigma.push_back(sigma);
    alive.push_back(1);
    buckets_[key(cell_of(p))].push_back(id);
    return id;
  }

  /// Alive points within r of c (bucket order, so deterministic).
  void gather(const Eigen::Vector3f& c, float r, std::vector<std::uint32_t>& out) const {
    out.clear();
    const Eigen::Vector3i lo = cell_of(c - Eigen::Vector3f::Constant(r + cell_)),
                          hi = cell_of(c + Eigen::Vector3f::Constant(r + cell_));
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) {
          const auto it = buckets_.find(key({x, y, z}));
          if (it == buckets_.end()) continue;
          for (std::uint32_t i : it->second)
            if (alive[i] && (positions[i] - c).squaredNorm() <= r * r) out.push_back(i);
        }
  }

  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<float> sigma;
  std::vector<char> alive;

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    return (std::uint64_t(std::uint32_t(c.x()) & 0x1FFFFF) << 42) | (std::uint64_t(std::uint32_t(c.y()) & 0x1FFFFF) << 21) |
           std::uint64_t(std::uint32_t(c.z()) & 0x1FFFFF);
  }
  float cell_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets_;
};

}  // namespace exsynth::points
