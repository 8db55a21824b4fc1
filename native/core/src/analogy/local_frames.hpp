#pragma once
// Per-voxel local frames and the sweep distance used by the analogy at one
// pyramid level. Private to the analogy.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth::analogy {

/// Columns: T (the field), B = T x N, N (the sdf gradient), in index units
/// of the level's grid (the grid is isotropic, so unit vectors stay unit).
using Frame = Eigen::Matrix3f;

/// Fast trilinear sample with clamping at the border (index coordinates).
inline float trilinear(const Volume& v, float x, float y, float z) {
  const int nx = v.nx(), ny = v.ny(), nz = v.nz();
  x = x < 0 ? 0 : (x > nx - 1 ? float(nx - 1) : x);
  y = y < 0 ? 0 : (y > ny - 1 ? float(ny - 1) : y);
  z = z < 0 ? 0 : (z > nz - 1 ? float(nz - 1) : z);
  const int x0 = int(x), y0 = int(y), z0 = int(z);
  const int x1 = x0 + (x0 + 1 < nx), y1 = y0 + (y0 + 1 < ny), z1 = z0 + (z0 + 1 < nz);
  const float fx = x - float(x0), fy = y - float(y0), fz = z - float(z0);
  const float* d = v.data();
  const std::size_t sy = std::size_t(nx), sz = std::size_t(nx) * ny;
  auto at = [&](int i, int j, int k) { return d[std::size_t(k) * sz + std::size_t(j) * sy + std::size_t(i)]; };
  const float c00 = at(x0, y0, z0) + fx * (at(x1, y0, z0) - at(x0, y0, z0));
  const float c10 = at(x0, y1, z0) + fx * (at(x1, y1, z0) - at(x0, y1, z0));
  const float c01 = at(x0, y0, z1) + fx * (at(x1, y0, z1) - at(x0, y0, z1));
  const float c11 = at(x0, y1, z1) + fx * (at(x1, y1, z1) - at(x0, y1, z1));
  const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

/// Frames at the given voxels of `sdf` (one pyramid level). `field` is the
/// direction field on the finest grid (3 channels) or empty for the global
/// frame (identity). `scale` = 2^level: fine index = level index * scale.
/// Returns false in *bad (the voxel's index) when the field is zero or not
/// finite at a voxel; the frame there falls back to an arbitrary tangent.
std::vector<Frame> frames_at(const Volume& sdf, const Volume& field, int scale,
                             const std::vector<std::uint32_t>& voxels, std::size_t* bad_count,
                             StageProgress& progress);

/// Sweep distance at the given voxels (sorted by index) of a grid of
/// nx x ny x nz: least-squares phi with grad phi = T (voxel units) over the
/// voxels' 6-neighbour graph, by conjugate gradient from `guess` (empty =
/// zeros) for at most `iterations` steps, so that visiting voxels by
/// increasing phi moves along the field (the paper's sweep distance; across
/// the surface T has no component, so phi is constant along N). `progress`
/// (total: iterations + 1) is checked for a cancel on every iteration.
std::vector<float> sweep_distance(int nx, int ny, int nz, const std::vector<std::uint32_t>& voxels,
                                  const std::vector<Frame>& frames, const std::vector<float>& guess,
                                  int iterations, StageProgress& progress);

}  // namespace exsynth::analogy
