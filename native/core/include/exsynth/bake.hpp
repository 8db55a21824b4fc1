#pragma once
// Volume -> surface: sample a volume at points (colour attributes) or bake
// it into a UV-mapped image (every texel gets the volume's value at the
// texel's 3D position), as solid textures are put on meshes.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/sample.hpp"

namespace exsynth {

/// out[i * C + c] = channel c at world point i (the volume's transform),
/// read with `interp` (sample.hpp); wrap = the volume repeats (a tiling
/// solid), else clamp. Cubic is the default: a 128^3 crackedground solid
/// baked at 3.7 texels per voxel kept 0.52 of its nearest voxels' texel-to-
/// texel difference read trilinearly, 0.64 tricubically, with no blocks
/// (bench/bench_bake.py, docs/solid.md).
void sample_volume(const Volume& vol, const std::vector<Eigen::Vector3f>& points, bool wrap, float* out,
                   ExecContext* ctx = nullptr, Interpolation interp = kDefaultInterpolation);

/// Option limits, checked by bake_volume_to_uv.
constexpr int kMaxBakeSize = 16384;   ///< texels on a side
constexpr int kMaxBakeMargin = 64;    ///< texels

struct BakeOptions {
  int width = 1024;
  int height = 1024;
  int margin = 4;        ///< texels of padding grown around each UV island (hides seams when mip-mapping)
  bool wrap = true;      ///< the volume repeats
  Interpolation interpolation = kDefaultInterpolation;  ///< how texels read the volume (see sample_volume)
  std::uint64_t seed = 0;  ///< unused: baking is deterministic
};

struct BakeResult {
  Image image;                     ///< width x height x C; row 0 is v = 0 (bottom, as Blender stores pixels)
  std::vector<std::uint8_t> mask;  ///< per texel: 1 covered by a triangle, 2 filled by the margin, 0 empty
};

/// `positions[f]` = triangle f's corners in the volume's world space,
/// `uvs[f]` its corner UVs (texture space [0, 1]^2). A texel belongs to a
/// triangle when its centre is inside it; overlapping triangles: the later one wins.
BakeResult bake_volume_to_uv(const Volume& vol, const std::vector<std::array<Eigen::Vector3f, 3>>& positions,
                             const std::vector<std::array<Eigen::Vector2f, 3>>& uvs, const BakeOptions& opt = {},
                             ExecContext* ctx = nullptr);

}  // namespace exsynth
