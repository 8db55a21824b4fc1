#include "field/tangent.hpp"

#include <cmath>

#include "exsynth/field.hpp"

namespace exsynth::field {

std::vector<Eigen::Vector3d> vertex_normals_d(const TriangleMesh& mesh) {
  // The cross product's length is twice the face area: summing it weights by
  // area, so a fan of slivers does not outvote one large face. Serial scatter
  // in face order: deterministic, and a few ms for 200k faces.
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    const Eigen::Vector3d c = (mesh.vertices[f[1]].cast<double>() - a).cross(mesh.vertices[f[2]].cast<double>() - a);
    for (int k = 0; k < 3; ++k) n[f[k]] += c;
  }
  for (Eigen::Vector3d& v : n) {
    const double len = v.norm();
    v = len > 0 && std::isfinite(len) ? Eigen::Vector3d(v / len) : Eigen::Vector3d::Zero();
  }
  return n;
}

Eigen::Vector3d least_aligned_axis(const Eigen::Vector3d& d) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(d[i]) < std::abs(d[k])) k = i;
  return Eigen::Vector3d::Unit(k);
}

Eigen::Vector3d perpendicular(const Eigen::Vector3d& a) { return a.cross(least_aligned_axis(a)).normalized(); }

Eigen::Vector3d fallback_tangent(const Eigen::Vector3d& n, const Eigen::Vector3d& preferred) {
  const Eigen::Vector3d p = project(preferred, n);
  if (p.norm() > kParallelTolerance) return p.normalized();
  return project(least_aligned_axis(n), n).normalized();
}

Eigen::Vector3d unit_tangent_or(const Eigen::Vector3d& v, const Eigen::Vector3d& n, double min_len,
                                const Eigen::Vector3d& preferred) {
  const Eigen::Vector3d p = project(v, n);
  const double len = p.norm();
  return len > min_len ? Eigen::Vector3d(p / len) : fallback_tangent(n, preferred);
}

}  // namespace exsynth::field

namespace exsynth {

std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh) {
  validate_mesh(mesh, "mesh");
  const std::vector<Eigen::Vector3d> nd = field::vertex_normals_d(mesh);
  std::vector<Eigen::Vector3f> n(nd.size());
  for (std::size_t i = 0; i < nd.size(); ++i) n[i] = nd[i].cast<float>();
  return n;
}

}  // namespace exsynth
