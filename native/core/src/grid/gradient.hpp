#pragma once
// Central-difference gradient of a 1-channel volume (one-sided on the
// border), in values per voxel: the normal of a signed distance field.
#include <algorithm>

#include <Eigen/Core>

#include "exsynth/grid.hpp"

namespace exsynth::grid {

inline Eigen::Vector3f gradient(const Volume& v, int x, int y, int z) {
  const int p[3] = {x, y, z}, dims[3] = {v.nx(), v.ny(), v.nz()};
  Eigen::Vector3f g;
  for (int a = 0; a < 3; ++a) {
    int lo[3] = {x, y, z}, hi[3] = {x, y, z};
    lo[a] = std::max(0, p[a] - 1);
    hi[a] = std::min(dims[a] - 1, p[a] + 1);
    const int span = hi[a] - lo[a];  // 2 inside, 1 on the border (one-sided)
    g[a] = span ? (v.at(hi[0], hi[1], hi[2]) - v.at(lo[0], lo[1], lo[2])) / float(span) : 0.0f;
  }
  return g;
}

/// The unit gradient, or +z where it vanishes.
inline Eigen::Vector3f unit_normal(const Volume& v, int x, int y, int z) {
  const Eigen::Vector3f g = gradient(v, x, y, z);
  return g.norm() > 1e-12f ? Eigen::Vector3f(g.normalized()) : Eigen::Vector3f::UnitZ();
}

}  // namespace exsynth::grid
