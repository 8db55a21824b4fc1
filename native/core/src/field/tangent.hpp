#pragma once
// Tangent-plane projection with deterministic fallbacks, shared by the
// diffusion and the presets. Doubles throughout: float normals of nearly flat
// regions would otherwise turn rounding noise into directions.
#include <vector>

#include <Eigen/Core>

#include "exsynth/mesh.hpp"

namespace exsynth::field {

/// Relative length below which a projected vector is taken to be parallel to
/// the normal: float vertex positions give normals good to ~1e-7.
constexpr double kParallelTolerance = 1e-5;

/// Area-weighted unit normals in double (zero where a vertex has no area).
std::vector<Eigen::Vector3d> vertex_normals_d(const TriangleMesh& mesh);

/// v minus its component along the unit normal n (n = 0: v unchanged).
inline Eigen::Vector3d project(const Eigen::Vector3d& v, const Eigen::Vector3d& n) { return v - v.dot(n) * n; }

/// The unit vector along the coordinate axis least aligned with d (ties: lowest axis).
Eigen::Vector3d least_aligned_axis(const Eigen::Vector3d& d);

/// A fixed unit vector perpendicular to the unit vector a.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& a);

/// `preferred` (unit) projected and normalised; where it is (nearly) parallel
/// to n, the coordinate axis least aligned with n instead, which always
/// projects to a length of at least sqrt(2/3). Never zero, never NaN.
Eigen::Vector3d fallback_tangent(const Eigen::Vector3d& n, const Eigen::Vector3d& preferred);

/// v projected and normalised when the projection is longer than min_len,
/// else fallback_tangent(n, preferred).
Eigen::Vector3d unit_tangent_or(const Eigen::Vector3d& v, const Eigen::Vector3d& n, double min_len,
                                const Eigen::Vector3d& preferred);

}  // namespace exsynth::field
