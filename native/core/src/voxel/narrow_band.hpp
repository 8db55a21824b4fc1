#pragma once
// Exact squared distances (voxel units) and nearest-triangle ids for every
// voxel within one voxel of the surface: the seeds of the distance
// transform. A voxel within distance 1 of the mesh lies inside the 1-voxel
// dilated bounding box of its nearest triangle, so these are exact.
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth::voxel {

/// `mesh` in voxel-index coordinates. Fills dist2 (kFarAway outside the band)
/// and label (triangle id, -1 outside), both nx*ny*nz, x fastest. Ties go to
/// the lower triangle id, so the result does not depend on scheduling.
void narrow_band(const TriangleMesh& mesh, int nx, int ny, int nz, std::vector<float>& dist2,
                 std::vector<std::int32_t>& label, StageProgress& progress);

}  // namespace exsynth::voxel
