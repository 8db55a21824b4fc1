#pragma once
// Direction fields on meshes: one unit tangent vector per vertex, the "which
// way the pattern runs" input of the analogy and surface methods.
//
// A user paints a few strokes (non-zero vectors on some vertices); the field
// is interpolated over the rest of the surface, as Turk 2001 does by
// repeatedly averaging neighbours, projecting into tangent planes and
// normalising. Here the averaging is solved to convergence in one sparse
// solve: each free vertex is the weighted average of its neighbours (a
// discrete harmonic interpolant of the 3D components with the painted
// vertices fixed), then every vertex is projected and normalised. Meshes
// without a painted field get one from a preset.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth {

// ---- tangent planes ---------------------------------------------------------

/// Unit area-weighted vertex normals (sum of incident face cross products).
/// Vertices with no incident area (unused, or only degenerate faces) get a
/// zero normal; every tangent-plane projection then leaves vectors unchanged.
std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh);

// ---- diffusing painted vectors ----------------------------------------------

/// Edge weights of the averaging (the Laplacian).
enum class FieldWeights {
  /// Cotangent weights, clamped to [1e-6, 100]: follow the geometry rather
  /// than the tessellation (linear fields are reproduced exactly), and the
  /// clamp keeps every weight positive so the result never overshoots the
  /// painted vectors (no sign flips on the obtuse or sliver triangles of
  /// scanned meshes). The floor is tiny so that the zero weights of
  /// triangulated quads stay (almost) zero, yet every edge still connects.
  Cotangent,
  Uniform,  ///< 1 per edge (graph Laplacian): depends on tessellation only
};

struct DirectionFieldOptions {
  FieldWeights weights = FieldWeights::Cotangent;
  /// Vertices in a connected component without any painted vector, and the
  /// rare spots where the interpolated vector is parallel to the normal, get
  /// this axis projected into their tangent plane (finite, non-zero).
  Eigen::Vector3f fallback_axis = Eigen::Vector3f(0, 0, 1);
  std::uint64_t seed = 0;  ///< unused: the field is deterministic
};

/// `given` has one vector per vertex: zero = free, non-zero = a constraint.
/// Constraints are projected into their tangent plane and normalised (their
/// length does not weigh); ones parallel to the normal carry no direction and
/// are treated as free. Returns a unit tangent vector per vertex; painted
/// vertices keep their projected direction. Throws InvalidInput for a wrong
/// size, a non-finite vector or no usable constraint; Cancelled via ctx.
std::vector<Eigen::Vector3f> diffuse_direction_field(const TriangleMesh& mesh,
                                                     const std::vector<Eigen::Vector3f>& given,
                                                     const DirectionFieldOptions& opt = {},
                                                     ExecContext* ctx = nullptr);

// ---- presets ----------------------------------------------------------------

enum class FieldPreset {
  AroundAxis,  ///< tangents of circles around the axis through the mesh's surface centroid
  AlongAxis,   ///< the axis projected into each tangent plane
  AlongCurve,  ///< the tangent of the nearest point of a polyline, projected
};

/// A unit tangent field from a preset. `axis`: finite, non-zero (also the
/// preference for degenerate spots). `curve_points`: AlongCurve's polyline
/// (>= 2 points, in the mesh's coordinates; repeat the first point to close
/// it). Where the preset's vector is parallel to the normal (a pole, a cap
/// facing the axis) a deterministic fallback is used: a fixed direction
/// perpendicular to the axis, then the coordinate axis least aligned with the
/// normal, projected.
std::vector<Eigen::Vector3f> preset_direction_field(const TriangleMesh& mesh, FieldPreset preset,
                                                    const Eigen::Vector3f& axis,
                                                    const std::vector<Eigen::Vector3f>& curve_points = {},
                                                    ExecContext* ctx = nullptr);

}  // namespace exsynth
