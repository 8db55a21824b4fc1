// Preset direction fields, for meshes without a painted field.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/field.hpp"
#include "exsynth/parallel.hpp"
#include "field/tangent.hpp"

namespace exsynth {
namespace {

using Eigen::Vector3d;

// Area-weighted centroid of the surface: unlike the vertex mean it does not
// drift towards densely tessellated parts. Vertex mean if there is no area.
Vector3d surface_centroid(const TriangleMesh& mesh) {
  Vector3d sum = Vector3d::Zero();
  double area = 0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Vector3d a = mesh.vertices[f[0]].cast<double>(), b = mesh.vertices[f[1]].cast<double>(),
                   c = mesh.vertices[f[2]].cast<double>();
    const double w = (b - a).cross(c - a).norm();
    sum += w * (a + b + c) / 3.0;
    area += w;
  }
  if (area > 0) return sum / area;
  sum.setZero();
  for (const auto& v : mesh.vertices) sum += v.cast<double>();
  return sum / double(mesh.vertices.size());
}

// The polyline as segments with unit tangents at its points (the mean of the
// adjacent segments' directions), so the field turns smoothly at corners
// instead of jumping where the nearest segment changes.
struct Polyline {
  std::vector<Vector3d> a, b;            // segment ends
  std::vector<Vector3d> ta, tb;          // unit tangents at the ends
};

Polyline make_polyline(const std::vector<Eigen::Vector3f>& pts) {
  if (pts.size() < 2)
    throw InvalidInput("the along-curve preset needs a curve of at least 2 points, got " + std::to_string(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (!pts[i].allFinite())
      throw InvalidInput("curve point " + std::to_string(i) + " is not finite (NaN or Inf)");
  // Drop repeated points: a zero-length segment has no direction.
  std::vector<Vector3d> p{pts[0].cast<double>()};
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (pts[i].cast<double>() != p.back()) p.push_back(pts[i].cast<double>());
  if (p.size() < 2)
    throw InvalidInput("all " + std::to_string(pts.size()) + " curve points are the same point; the curve needs length");
  std::vector<Vector3d> dir(p.size() - 1), tangent(p.size());
  for (std::size_t i = 0; i + 1 < p.size(); ++i) dir[i] = (p[i + 1] - p[i]).normalized();
  // A closed curve (last point = first, up to rounding) turns smoothly
  // through its seam too.
  double length = 0;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) length += (p[i + 1] - p[i]).norm();
  const bool closed = p.size() > 3 && (p.back() - p.front()).norm() <= 1e-6 * length;
  const std::size_t last = dir.size() - 1;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vector3d in = i > 0 ? dir[i - 1] : (closed ? dir[last] : dir[0]);
    const Vector3d out = i + 1 < p.size() ? dir[i] : (closed ? dir[0] : dir[last]);
    const Vector3d mean = in + out;
    tangent[i] = mean.norm() > 1e-6 ? Vector3d(mean.normalized()) : out;  // a U-turn keeps the outgoing direction
  }
  Polyline l;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    l.a.push_back(p[i]);
    l.b.push_back(p[i + 1]);
    l.ta.push_back(tangent[i]);
    l.tb.push_back(tangent[i + 1]);
  }
  return l;
}

// Tangent of the polyline at the point nearest to q. Brute force over the
// segments (ties: the lower segment), O(vertices x segments): a 100k-vertex
// mesh and a 1000-point curve take ~0.1 s on 2 cores.
Vector3d curve_tangent(const Polyline& l, const Vector3d& q) {
  double best = std::numeric_limits<double>::infinity();
  Vector3d t = l.ta[0];
  for (std::size_t s = 0; s < l.a.size(); ++s) {
    const Vector3d d = l.b[s] - l.a[s];
    const double u = std::clamp((q - l.a[s]).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const double dist2 = (l.a[s] + u * d - q).squaredNorm();
    if (dist2 < best) {
      best = dist2;
      const Vector3d blend = (1 - u) * l.ta[s] + u * l.tb[s];
      t = blend.norm() > 1e-6 ? blend : d.normalized();
    }
  }
  return t;
}

}  // namespace

std::vector<Eigen::Vector3f> preset_direction_field(const TriangleMesh& mesh, FieldPreset preset,
                                                    const Eigen::Vector3f& axis,
                                                    const std::vector<Eigen::Vector3f>& curve_points,
                                                    ExecContext* ctx) {
  validate_mesh(mesh, "mesh");
  if (!axis.allFinite() || axis.norm() == 0) throw InvalidInput("'axis' must be a finite, non-zero vector");
  Polyline curve;
  if (preset == FieldPreset::AlongCurve) curve = make_polyline(curve_points);

  const std::size_t n = mesh.vertices.size();
  StageProgress progress(ctx, "direction field: preset", 0.0, 1.0, n);
  const std::vector<Vector3d> normal = field::vertex_normals_d(mesh);
  const Vector3d a = axis.cast<double>().normalized();
  // Degenerate spots (a pole of the rotation, a cap facing the axis) get one
  // fixed direction across the axis: constant over a flat cap.
  const Vector3d fallback = field::perpendicular(a);
  const Vector3d centre = surface_centroid(mesh);
  double radius = 0;
  for (const auto& v : mesh.vertices) radius = std::max(radius, (v.cast<double>() - centre).norm());

  std::vector<Eigen::Vector3f> out(n);
  parallel_chunks(n, preset == FieldPreset::AlongCurve ? 256 : 4096, progress, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t v = lo; v < hi; ++v) {
      const Vector3d p = mesh.vertices[v].cast<double>();
      Vector3d t;
      if (preset == FieldPreset::AroundAxis)
        t = a.cross(p - centre);  // |t| = distance to the axis
      else if (preset == FieldPreset::AlongAxis)
        t = a;
      else
        t = curve_tangent(curve, p);
      // Parallel to the normal, or (around an axis) on the axis itself,
      // where float positions leave no reliable direction.
      const double min_len = std::max(field::kParallelTolerance * t.norm(), 1e-7 * radius);
      out[v] = field::unit_tangent_or(t, normal[v], preset == FieldPreset::AroundAxis ? min_len
                                                                                      : field::kParallelTolerance,
                                      fallback)
                   .cast<float>();
    }
  });
  return out;
}

}  // namespace exsynth
