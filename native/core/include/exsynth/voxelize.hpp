#pragma once
// Mesh -> voxels: inside/outside by Embree ray parity along the three axes
// with a majority vote (Nooruddin & Turk 2003), so open or slightly broken
// meshes still give a sensible solid; density = exact 1-D coverage of each
// voxel along sub-rays (median of the three axes); signed distance (positive
// outside, as Bhat et al. 2004) from an exact narrow band, a separable
// feature transform carrying the nearest triangle, and exact point-triangle
// distances.
#include <cstddef>
#include <cstdint>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth {

/// Option limits, checked by voxelize (exported for the bindings' messages).
constexpr int kMaxVoxelResolution = 1 << 14;
constexpr int kMaxVoxelPadding = 1024;
constexpr int kMaxSupersample = 8;

/// The Embree library the voxelizer loads at run time ("libembree3.so.3" or
/// "libembree4.so.4", by what the build found): a package must carry it.
const char* embree_library();

struct VoxelizeOptions {
  int resolution = 128;       ///< voxels along the longest bounding-box axis (when voxel_size == 0)
  double voxel_size = 0.0;    ///< > 0: voxel edge length in mesh units (overrides resolution)
  int padding = 2;            ///< empty voxels added on every side
  int supersample = 2;        ///< sub-rays per voxel edge for density (1..8)
  bool compute_sdf = true;    ///< also compute the signed distance field
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;     ///< unused: the voxelizer is deterministic
};

struct VoxelizeResult {
  Volume density;  ///< 1 channel in [0, 1]
  Volume sdf;      ///< 1 channel, mesh units, positive outside; empty if !compute_sdf
};

/// Grid placement the voxelizer would use (exposed for memory estimates and tests).
struct VoxelGridSpec {
  int nx = 0, ny = 0, nz = 0;
  GridTransform transform;
};
VoxelGridSpec voxel_grid_spec(const TriangleMesh& mesh, const VoxelizeOptions& opt);
/// The same placement from a bounding box [lo, hi] alone (the add-on's grid
/// estimates and voxel sizes, before any triangles are handed over).
VoxelGridSpec voxel_grid_spec(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const VoxelizeOptions& opt);

VoxelizeResult voxelize(const TriangleMesh& mesh, const VoxelizeOptions& opt = {},
                        ExecContext* ctx = nullptr);

}  // namespace exsynth
