#pragma once
// Analytic test meshes with known volumes and distances.
#include <cmath>
#include <map>
#include <utility>

#include "exsynth/mesh.hpp"

namespace exsynth::testing {

/// Axis-aligned box [lo, hi], 12 triangles, counter-clockwise from outside.
inline TriangleMesh box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& q : quads) {
    m.faces.emplace_back(q[0], q[1], q[2]);
    m.faces.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

/// Icosphere of the given radius (subdivided `levels` times), centred at c.
inline TriangleMesh icosphere(float radius, int levels, const Eigen::Vector3f& c = Eigen::Vector3f::Zero()) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  TriangleMesh m;
  const float v[12][3] = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1},   {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) m.vertices.push_back(Eigen::Vector3f(p[0], p[1], p[2]).normalized());
  m.faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
             {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      return mid[key] = int(m.vertices.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& f : m.faces) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c2 = midpoint(f[2], f[0]);
      next.insert(next.end(), {{f[0], a, c2}, {f[1], b, a}, {f[2], c2, b}, {a, b, c2}});
    }
    m.faces = std::move(next);
  }
  for (auto& p : m.vertices) p = p * radius + c;
  return m;
}

}  // namespace exsynth::testing
