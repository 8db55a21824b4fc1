// A smooth tangent field on the control mesh when the user painted none.
#include <algorithm>
#include <cmath>

#include "exsynth/errors.hpp"
#include "exsynth/surface.hpp"

namespace exsynth {

namespace {

/// Unit normals per control vertex: sum of the incident faces' Newell vectors.
std::vector<Eigen::Vector3f> control_normals(const PolygonMesh& m) {
  std::vector<Eigen::Vector3f> n(m.vertices.size(), Eigen::Vector3f::Zero());
  std::size_t at = 0;
  for (int size : m.face_sizes) {
    Eigen::Vector3f a = Eigen::Vector3f::Zero();
    for (int i = 0; i < size; ++i)
      a += m.vertices[std::size_t(m.face_vertices[at + std::size_t(i)])].cross(
          m.vertices[std::size_t(m.face_vertices[at + std::size_t((i + 1) % size)])]);
    for (int i = 0; i < size; ++i) n[std::size_t(m.face_vertices[at + std::size_t(i)])] += a;
    at += std::size_t(size);
  }
  for (auto& v : n)
    if (v.norm() > 0) v.normalize();
  return n;
}

Eigen::Vector3f project_unit(const Eigen::Vector3f& v, const Eigen::Vector3f& n, const Eigen::Vector3f& axis) {
  Eigen::Vector3f p = v - v.dot(n) * n;
  if (p.norm() > 1e-6f) return p.normalized();
  // Parallel to the normal: the axis, then the coordinate axis least aligned with n.
  p = axis - axis.dot(n) * n;
  if (p.norm() > 1e-3f) return p.normalized();
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) < std::abs(n[k])) k = i;
  Eigen::Vector3f e = Eigen::Vector3f::Zero();
  e[k] = 1;
  p = e - e.dot(n) * n;
  return p.norm() > 0 ? p.normalized() : Eigen::Vector3f(1, 0, 0);
}

}  // namespace

std::vector<Eigen::Vector3f> smooth_surface_field(const PolygonMesh& m, const Eigen::Vector3f& axis, int iterations,
                                                  ExecContext* ctx) {
  if (!axis.allFinite() || !(axis.norm() > 0)) throw InvalidInput("field axis must be finite and non-zero");
  const std::size_t nv = m.vertices.size();
  const std::vector<Eigen::Vector3f> normals = control_normals(m);
  // Edge neighbours of each vertex (both directions; duplicates only weigh an edge twice).
  std::vector<std::vector<int>> nbrs(nv);
  std::size_t at = 0;
  for (int size : m.face_sizes) {
    for (int i = 0; i < size; ++i) {
      const int a = m.face_vertices[at + std::size_t(i)], b = m.face_vertices[at + std::size_t((i + 1) % size)];
      nbrs[std::size_t(a)].push_back(b);
      nbrs[std::size_t(b)].push_back(a);
    }
    at += std::size_t(size);
  }
  const Eigen::Vector3f ax = axis.normalized();
  std::vector<Eigen::Vector3f> v(nv), next(nv);
  for (std::size_t i = 0; i < nv; ++i) v[i] = project_unit(ax, normals[i], ax);
  // Each sweep sets every vector to the projected mean of itself and its
  // neighbours: a Jacobi step on sum (1 - cos) with the unit constraint.
  for (int it = 0; it < iterations; ++it) {
    if (ctx) ctx->check();
    for (std::size_t i = 0; i < nv; ++i) {
      Eigen::Vector3f s = v[i];
      for (int j : nbrs[i]) s += v[std::size_t(j)];
      next[i] = project_unit(s, normals[i], v[i]);
    }
    v.swap(next);
  }
  return v;
}

}  // namespace exsynth
