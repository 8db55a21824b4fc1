#pragma once
// Small analytic volumes for tests: a sphere's signed distance and the field
// of circles around z, on grids centred on the origin.
#include <cmath>

#include "exsynth/grid.hpp"

namespace exsynth::testing {

/// n^3 voxels of size h centred on the origin.
inline GridTransform centred_grid(int n, double h) {
  GridTransform t;
  t.voxel_size = h;
  const double o = -0.5 * (n - 1) * h;
  t.origin = {o, o, o};
  return t;
}

inline Volume sphere_volume(int n, double h, double radius) {
  Volume v(n, n, n, 1, 0.0f, centred_grid(n, h));
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const auto p = v.transform().index_to_world(x, y, z);
        v.at(x, y, z) = float(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - radius);
      }
  return v;
}

/// Unit circles around z (3 channels) on `like`'s grid; +x on the axis.
inline Volume around_z_field(const Volume& like) {
  Volume f(like.nx(), like.ny(), like.nz(), 3, 0.0f, like.transform());
  for (int z = 0; z < f.nz(); ++z)
    for (int y = 0; y < f.ny(); ++y)
      for (int x = 0; x < f.nx(); ++x) {
        const auto p = f.transform().index_to_world(x, y, z);
        const double r = std::hypot(p[0], p[1]);
        f.at(x, y, z, 0) = float(r > 1e-9 ? -p[1] / r : 1.0);
        f.at(x, y, z, 1) = float(r > 1e-9 ? p[0] / r : 0.0);
      }
  return f;
}

}  // namespace exsynth::testing
