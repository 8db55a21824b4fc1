#pragma once
// Local frames in a volume (Bhat et al. 2004, §4): at every voxel N from the
// geometry (the normalised gradient of the signed distance), T from the
// direction field (projected perpendicular to N), B = T x N. The field is
// given on the mesh's vertices; voxels near the surface take the field of
// their nearest vertex, and every other voxel that of its nearest surface
// voxel (a feature transform), smoothed by a few fix-and-diffuse steps.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth {

/// Limit of FrameOptions::smoothing_steps (each step is one pass over the volume).
constexpr int kMaxSmoothingSteps = 1000;

struct FrameOptions {
  double band = 1.5;        ///< surface voxels: |sdf| <= band voxels; their T is fixed from the field
  int smoothing_steps = 4;  ///< fix-and-diffuse steps after the nearest-surface propagation
  std::uint64_t seed = 0;   ///< unused: the computation is deterministic
};

struct VolumeFrames {
  Volume t, n, b;  ///< 3 channels each, unit vectors, right-handed: b = t x n
};

/// sdf: 1 channel, world units, positive outside (its transform places it).
/// field_points / field_vectors: the field's sample positions (world) and
/// directions, e.g. a mesh's vertices and its `exsynth_field`.
VolumeFrames volume_frames(const Volume& sdf, const std::vector<Eigen::Vector3f>& field_points,
                           const std::vector<Eigen::Vector3f>& field_vectors, const FrameOptions& opt = {},
                           ExecContext* ctx = nullptr);

}  // namespace exsynth
