#pragma once
// Neighbourhood feature vectors of the analogy, sampled in local frames.
// Private to the analogy.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "analogy/local_frames.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::analogy {

using Vec3 = Eigen::Vector3f;

// Neighbourhood offsets in local frame coordinates (T, B, N). The causal
// part holds the fine cube's offsets that are visited before the centre:
// the -T half cube in sweep order, or the scanline predecessors (z slowest,
// then y, then x) in the isotropic variant.
struct Neighbourhoods {
  std::vector<Vec3> causal, fine, coarse;
  int static_dims(bool with_coarse) const { return int(fine.size() + (with_coarse ? 2 * coarse.size() : 0)); }
  int dims(bool with_coarse) const { return int(causal.size()) + static_dims(with_coarse); }
};

inline Neighbourhoods make_neighbourhoods(int fine, int coarse, bool scanline) {
  Neighbourhoods n;
  const int r = fine / 2, rc = coarse / 2;
  for (int k = -r; k <= r; ++k)
    for (int j = -r; j <= r; ++j)
      for (int i = -r; i <= r; ++i) {
        n.fine.emplace_back(float(i), float(j), float(k));
        const bool before = scanline ? (k < 0 || (k == 0 && (j < 0 || (j == 0 && i < 0)))) : i < 0;
        if (before) n.causal.emplace_back(float(i), float(j), float(k));
      }
  for (int k = -rc; k <= rc; ++k)
    for (int j = -rc; j <= rc; ++j)
      for (int i = -rc; i <= rc; ++i) n.coarse.emplace_back(float(i), float(j), float(k));
  return n;
}

// One level's view of a side of the analogy: the "before" volume (A or B),
// the "after" volume (A' or B', being written for B'), and their next-coarser
// levels (null at the coarsest). Coarse index = fine index / 2: pyramid
// levels keep voxel 0's centre.
struct Side {
  const Volume* before;
  const Volume* after;
  const Volume* before_coarse;
  const Volume* after_coarse;
};

inline Vec3 voxel_position(const Volume& v, std::uint32_t i) {
  const auto nx = std::uint32_t(v.nx()), ny = std::uint32_t(v.ny());
  return Vec3(float(i % nx), float((i / nx) % ny), float(i / (nx * ny)));
}

inline void causal_features(const Side& s, const Neighbourhoods& n, const Vec3& g, const Frame& f, float* out) {
  for (const Vec3& o : n.causal) {
    const Vec3 p = g + f * o;
    *out++ = trilinear(*s.after, p.x(), p.y(), p.z());
  }
}

inline void static_features(const Side& s, const Neighbourhoods& n, const Vec3& g, const Frame& f, float* out) {
  for (const Vec3& o : n.fine) {
    const Vec3 p = g + f * o;
    *out++ = trilinear(*s.before, p.x(), p.y(), p.z());
  }
  if (!s.before_coarse) return;
  const Vec3 gc = 0.5f * g;
  for (const Volume* v : {s.after_coarse, s.before_coarse})
    for (const Vec3& o : n.coarse) {
      const Vec3 p = gc + f * o;
      *out++ = trilinear(*v, p.x(), p.y(), p.z());
    }
}

}  // namespace exsynth::analogy
