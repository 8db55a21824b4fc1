#include "exsynth/mesh.hpp"

#include <cmath>
#include <string>

#include "exsynth/errors.hpp"

namespace exsynth {

void validate_mesh(const TriangleMesh& mesh, const char* what) {
  const std::string name = what ? what : "mesh";
  if (mesh.vertices.empty()) {
    throw InvalidInput(name + " has no vertices; give a mesh with at least one triangle");
  }
  if (mesh.faces.empty()) {
    throw InvalidInput(name + " has no faces; give a mesh with at least one triangle "
                       "(a point cloud or loose edges cannot be used here)");
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(v[k])) {
        const char* kind = std::isnan(v[k]) ? "nan" : "inf";
        throw InvalidInput("vertex " + std::to_string(i) + " of " + name + " is not finite (" +
                           kind + "); remove or fix it");
      }
    }
  }
  const long long n = static_cast<long long>(mesh.vertices.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const long long idx = mesh.faces[f][k];
      if (idx < 0 || idx >= n) {
        throw InvalidInput("face " + std::to_string(f) + " of " + name + " refers to vertex " +
                           std::to_string(idx) + " but the mesh has " + std::to_string(n) +
                           " vertices");
      }
    }
  }
}

double enclosed_volume(const TriangleMesh& mesh) {
  // Sum of signed tetrahedra (origin, a, b, c); in double so that large,
  // finely tessellated meshes do not lose the small per-face terms.
  double six_v = 0.0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[f[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[f[2]].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

}  // namespace exsynth
