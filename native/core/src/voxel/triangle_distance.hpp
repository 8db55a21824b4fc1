#pragma once
// Exact squared distance from a point to a triangle (Ericson, "Real-Time
// Collision Detection", 5.1.5: closest point by Voronoi regions).
#include <Eigen/Core>

namespace exsynth::voxel {

inline float point_triangle_distance2(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                                      const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();  // vertex a
  const Eigen::Vector3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();  // vertex b
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge ab
    const float v = d1 / (d1 - d3);
    return (ap - v * ab).squaredNorm();
  }
  const Eigen::Vector3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();  // vertex c
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge ac
    const float w = d2 / (d2 - d6);
    return (ap - w * ac).squaredNorm();
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {  // edge bc
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (bp - w * (c - b)).squaredNorm();
  }
  const float denom = 1.0f / (va + vb + vc);  // interior
  const float v = vb * denom, w = vc * denom;
  return (ap - ab * v - ac * w).squaredNorm();
}

}  // namespace exsynth::voxel
