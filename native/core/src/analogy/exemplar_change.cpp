#include "analogy/exemplar_change.hpp"

#include <cmath>
#include <cstddef>

namespace exsynth::analogy {

Reach pair_reach(const Volume& a, const Volume& ap) {
  Reach r;
  const float near = float(a.transform().voxel_size);
  for (std::size_t i = 0; i < a.voxel_count(); ++i) {
    const float va = a.data()[i], vp = ap.data()[i];
    if (std::abs(va) > near && std::abs(vp) > near) continue;
    r.outward = std::max(r.outward, double(va - vp));
    r.inward = std::max(r.inward, double(vp - va));
  }
  return r;
}

std::vector<unsigned char> change_mask(const Volume& a, const Volume& ap, float tol, int r,
                                       const StageProgress& progress) {
  const int nx = a.nx(), ny = a.ny(), nz = a.nz();
  std::vector<unsigned char> m(a.voxel_count()), tmp(a.voxel_count());
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = std::abs(ap.data()[i] - a.data()[i]) > tol;
  // Separable max filter, one axis after another.
  const int dims[3] = {nx, ny, nz};
  const std::size_t stride[3] = {1, std::size_t(nx), std::size_t(nx) * ny};
  for (int axis = 0; axis < 3; ++axis) {
    for (int z = 0; z < nz; ++z) {
      progress.check();
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          const int c[3] = {x, y, z};
          const std::size_t i = a.voxel_index(x, y, z);
          unsigned char v = 0;
          for (int d = -r; d <= r && !v; ++d) {
            const int q = c[axis] + d;
            if (q >= 0 && q < dims[axis]) v = m[std::size_t(std::ptrdiff_t(i) + std::ptrdiff_t(d) * std::ptrdiff_t(stride[axis]))];
          }
          tmp[i] = v;
        }
    }
    m.swap(tmp);
  }
  return m;
}

}  // namespace exsynth::analogy
