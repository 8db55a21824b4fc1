#pragma once
// An indexed triangle mesh: the only mesh type the core takes and returns.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace exsynth {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> faces;  ///< counter-clockwise seen from outside
};

/// Checks vertices are finite and face indices in range; throws InvalidInput
/// naming `what` ("mesh 'vertices'") otherwise. Empty meshes are rejected.
void validate_mesh(const TriangleMesh& mesh, const char* what = "mesh");

/// Volume enclosed by a closed, consistently oriented mesh (divergence theorem).
double enclosed_volume(const TriangleMesh& mesh);

}  // namespace exsynth
