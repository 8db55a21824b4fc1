#pragma once
// Even sampling of a triangle mesh's surface (private): where each sample
// came from, so callers can interpolate per-vertex data (a direction field).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/mesh.hpp"
#include "exsynth/points.hpp"

namespace exsynth::points {

struct SurfaceSamples {
  OrientedPoints points;
  std::vector<std::uint32_t> face;       ///< source triangle per sample
  std::vector<Eigen::Vector3f> bary;     ///< barycentric coordinates in it
};

/// `count` samples: 3 x count area-weighted uniform candidates from (seed,
/// index), reduced to `count` by sample elimination (Yuksel 2015: drop the
/// candidate with the most close neighbours first), which gives blue-noise
/// spacing and an exact count. Normals: interpolated vertex normals.
SurfaceSamples sample_surface(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed, ExecContext* ctx);

double surface_area(const TriangleMesh& mesh);

}  // namespace exsynth::points
