#pragma once
// Axis-aligned ray stabbing with Embree: all crossings of a mesh along a
// line parallel to a coordinate axis, built once per mesh and queried for
// many lines from many threads.
#include <array>
#include <cstdint>
#include <vector>

#include "exsynth/mesh.hpp"
#include "voxel/embree_api.hpp"

namespace exsynth::voxel {

/// One surface crossing along a line: position along the axis and whether
/// the surface faces along (+1) or against (-1) the ray direction.
struct Crossing {
  float t;
  std::int8_t facing;
  bool operator<(const Crossing& o) const { return t < o.t || (t == o.t && facing < o.facing); }
};

class AxisRayCaster {
 public:
  /// `mesh` vertices are in the caller's coordinates (the voxelizer uses
  /// voxel-index space); they are copied into Embree's buffers.
  explicit AxisRayCaster(const TriangleMesh& mesh);
  ~AxisRayCaster();
  AxisRayCaster(const AxisRayCaster&) = delete;
  AxisRayCaster& operator=(const AxisRayCaster&) = delete;

  /// Crossings of the line {coordinate `axis` free, the other two fixed at
  /// (u, v)} (u, v = the next two axes in cyclic order), sorted by position
  /// and with duplicates merged: Embree's watertight test may report a hit
  /// on an edge for both triangles that share it, and that must count once.
  /// Two crossings at one spot with opposite facing (a silhouette fold) are
  /// both kept. Thread-safe; `out` is cleared first.
  void crossings(int axis, float u, float v, std::vector<Crossing>& out) const;

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<std::array<float, 3>> normals_;  // unnormalised face normals (b-a)x(c-a)
  float start_[3];                             // ray start per axis, before the mesh
  float merge_eps_;
};

}  // namespace exsynth::voxel
