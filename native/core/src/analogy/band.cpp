#include "analogy/band.hpp"

#include "analogy/features.hpp"
#include "exsynth/parallel.hpp"

#include <cstring>

#include <tbb/parallel_sort.h>

namespace exsynth::analogy {

std::vector<std::uint32_t> breadth_first(const Volume& grid, const std::vector<std::uint32_t>& band,
                                         const std::vector<std::int32_t>& band_of,
                                         const std::vector<std::uint32_t>& order, const StageProgress& progress) {
  std::vector<std::uint32_t> out;
  out.reserve(band.size());
  std::vector<unsigned char> seen(band.size(), 0);
  for (const std::uint32_t start : order) {
    if (seen[start]) continue;
    seen[start] = 1;
    std::size_t head = out.size();
    out.push_back(start);
    while (head < out.size()) {
      progress.check_every(head);
      const Vec3 g = voxel_position(grid, band[out[head++]]);
      const int x = int(g.x()), y = int(g.y()), z = int(g.z());
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = y + dy, qz = z + dz;
            if (qx < 0 || qy < 0 || qz < 0 || qx >= grid.nx() || qy >= grid.ny() || qz >= grid.nz()) continue;
            const std::int32_t q = band_of[grid.voxel_index(qx, qy, qz)];
            if (q < 0 || seen[std::size_t(q)]) continue;
            seen[std::size_t(q)] = 1;
            out.push_back(std::uint32_t(q));
          }
    }
  }
  return out;
}

Volume upsample(const Volume& coarse, const Volume& like, StageProgress& progress) {
  Volume out(like.nx(), like.ny(), like.nz(), 1, 0.0f, like.transform());
  parallel_chunks(std::size_t(like.nz()), 1, progress, [&](std::size_t z0, std::size_t z1) {
    for (int z = int(z0); z < int(z1); ++z)
      for (int y = 0; y < like.ny(); ++y)
        for (int x = 0; x < like.nx(); ++x) out.at(x, y, z) = trilinear(coarse, 0.5f * x, 0.5f * y, 0.5f * z);
  });
  return out;
}

std::vector<float> upsample_phi(const Volume& phi_coarse, const Volume& has_coarse, const Volume& level,
                                const std::vector<std::uint32_t>& voxels, StageProgress& progress) {
  if (phi_coarse.empty()) return {};
  std::vector<float> out(voxels.size(), 0.0f);
  parallel_chunks(voxels.size(), 1 << 14, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 g = 0.5f * voxel_position(level, voxels[i]);
      const float w = trilinear(has_coarse, g.x(), g.y(), g.z());
      out[i] = w > 1e-6f ? 2.0f * trilinear(phi_coarse, g.x(), g.y(), g.z()) / w : 0.0f;
    }
  });
  return out;
}

std::vector<std::uint32_t> sorted_by(const std::vector<float>& key, const StageProgress& progress) {
  // Float bits made to order as unsigned integers (negatives flipped), the
  // position in the low half: every pair is distinct, so any sort gives the
  // one stable order whatever the thread count.
  std::vector<std::uint64_t> pairs(key.size());
  for (std::size_t i = 0; i < key.size(); ++i) {
    progress.check_every(i);
    std::uint32_t bits;
    std::memcpy(&bits, &key[i], sizeof bits);
    bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
    pairs[i] = (std::uint64_t(bits) << 32) | std::uint32_t(i);
  }
  tbb::parallel_sort(pairs.begin(), pairs.end(), [&progress](std::uint64_t a, std::uint64_t b) {
    thread_local std::uint32_t calls = 0;  // a check per ~10^6 comparisons and thread
    if ((++calls & 0xFFFFF) == 0) progress.check();
    return a < b;
  });
  std::vector<std::uint32_t> order(key.size());
  for (std::size_t i = 0; i < key.size(); ++i) order[i] = std::uint32_t(pairs[i]);
  return order;
}

}  // namespace exsynth::analogy
