#pragma once
// Volume -> mesh through OpenVDB's volumeToMesh.
#include <cstdint>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth {

struct IsosurfaceOptions {
  double isovalue = 0.0;
  double adaptivity = 0.0;  ///< 0 = uniform mesh, up to 1 = fewer polygons in flat areas
  bool invert = false;      ///< false: outside = values above isovalue (an SDF); true: below (a density)
  int channel = 0;          ///< which channel of the volume
  std::uint64_t seed = 0;   ///< unused: the extraction is deterministic
};

/// Triangles in world space (the volume's transform), counter-clockwise seen
/// from outside. An empty mesh when the isovalue is never crossed.
TriangleMesh isosurface(const Volume& volume, const IsosurfaceOptions& opt = {},
                        ExecContext* ctx = nullptr);

}  // namespace exsynth
