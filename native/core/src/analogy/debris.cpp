#include "analogy/debris.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace exsynth::analogy {
namespace {

// Voxels of one side (inside or outside) of b_prime that are connected to
// a voxel on the same side of b: a flood fill from all such seeds at once.
std::vector<unsigned char> anchored(const Volume& bp, const Volume& b, bool inside) {
  const int nx = bp.nx(), ny = bp.ny(), nz = bp.nz();
  std::vector<unsigned char> reached(bp.voxel_count(), 0);
  std::vector<std::uint32_t> stack;
  auto side = [&](const Volume& v, std::size_t i) { return (v.data()[i] < 0) == inside; };
  for (std::size_t i = 0; i < reached.size(); ++i)
    if (side(bp, i) && side(b, i)) {
      reached[i] = 1;
      stack.push_back(std::uint32_t(i));
    }
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const int x = int(i % std::uint32_t(nx)), y = int((i / std::uint32_t(nx)) % std::uint32_t(ny)),
              z = int(i / (std::uint32_t(nx) * std::uint32_t(ny)));
    const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& d : nb) {
      const int qx = x + d[0], qy = y + d[1], qz = z + d[2];
      if (qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz) continue;
      const std::size_t q = bp.voxel_index(qx, qy, qz);
      if (reached[q] || !side(bp, q)) continue;
      reached[q] = 1;
      stack.push_back(std::uint32_t(q));
    }
  }
  return reached;
}

}  // namespace

std::size_t remove_debris(Volume& b_prime, const Volume& b) {
  const float half = 0.5f * float(b_prime.transform().voxel_size);
  std::size_t changed = 0;
  for (const bool inside : {true, false}) {
    const std::vector<unsigned char> keep = anchored(b_prime, b, inside);
    for (std::size_t i = 0; i < keep.size(); ++i) {
      float& v = b_prime.data()[i];
      if (keep[i] || (v < 0) != inside) continue;
      // Mirror to the other side (at least half a voxel away from the surface).
      v = inside ? std::max(-v, half) : std::min(-v, -half);
      ++changed;
    }
  }
  return changed;
}

}  // namespace exsynth::analogy
