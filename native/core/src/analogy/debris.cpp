#include "analogy/debris.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace exsynth::analogy {
namespace {

struct Parts {
  std::vector<std::int32_t> label;  ///< per voxel: part index, -1 = other side
  std::vector<std::size_t> size;
  std::vector<unsigned char> anchored;  ///< shares a voxel with the same side of b
};

// 6-connected parts of one side (inside: sdf < 0, or outside) of bp.
Parts parts_of(const Volume& bp, const Volume& b, bool inside, StageProgress& progress) {
  const int nx = bp.nx(), ny = bp.ny(), nz = bp.nz();
  Parts p;
  p.label.assign(bp.voxel_count(), -1);
  std::vector<std::uint32_t> stack;
  auto side = [&](const Volume& v, std::size_t i) { return (v.data()[i] < 0) == inside; };
  std::size_t visited = 0;  // voxels taken off the stack, for the cancel checks
  for (std::size_t seed = 0; seed < p.label.size(); ++seed) {
    progress.check_every(seed);
    if (p.label[seed] >= 0 || !side(bp, seed)) continue;
    const auto id = std::int32_t(p.size.size());
    p.size.push_back(0);
    p.anchored.push_back(0);
    p.label[seed] = id;
    stack.push_back(std::uint32_t(seed));
    while (!stack.empty()) {
      const std::uint32_t i = stack.back();
      stack.pop_back();
      progress.check_every(++visited);
      ++p.size.back();
      if (side(b, i)) p.anchored.back() = 1;
      const int x = int(i % std::uint32_t(nx)), y = int((i / std::uint32_t(nx)) % std::uint32_t(ny)),
                z = int(i / (std::uint32_t(nx) * std::uint32_t(ny)));
      const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      for (const auto& d : nb) {
        const int qx = x + d[0], qy = y + d[1], qz = z + d[2];
        if (qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz) continue;
        const std::size_t q = bp.voxel_index(qx, qy, qz);
        if (p.label[q] >= 0 || !side(bp, q)) continue;
        p.label[q] = id;
        stack.push_back(std::uint32_t(q));
      }
    }
  }
  return p;
}

}  // namespace

std::size_t remove_debris(Volume& b_prime, const Volume& b, StageProgress& progress) {
  const float half = 0.5f * float(b_prime.transform().voxel_size);
  std::size_t changed = 0;
  for (const bool inside : {true, false}) {
    const Parts p = parts_of(b_prime, b, inside, progress);
    if (p.size.empty()) continue;
    // Crumbs: parts under 0.2 % of the largest (at least 27 voxels) go too,
    // even when they touch B: a sliver a groove cut off, a one-voxel bubble.
    const std::size_t largest = *std::max_element(p.size.begin(), p.size.end());
    const std::size_t crumb = std::max<std::size_t>(27, largest / 500);
    for (std::size_t i = 0; i < p.label.size(); ++i) {
      const std::int32_t id = p.label[i];
      if (id < 0 || (p.anchored[std::size_t(id)] && p.size[std::size_t(id)] >= crumb)) continue;
      float& v = b_prime.data()[i];
      // Mirror to the other side (at least half a voxel away from the surface).
      v = inside ? std::max(-v, half) : std::min(-v, -half);
      ++changed;
    }
    progress.advance(1);
  }
  return changed;
}

}  // namespace exsynth::analogy
