// exsynth._native.diffuse_direction_field / preset_direction_field
#include <pybind11/pybind11.h>

#include <cmath>
#include <string>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/field.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// (rows, 3) float32/float64 -> vectors, finite; rows = -1: any.
std::vector<Eigen::Vector3f> to_vectors(const py::handle& arg, const char* name, py::ssize_t rows, const std::string& expected) {
  const py::array a = array_arg(arg, name, expected);
  check_shape(a, name, {rows, 3}, expected.c_str());
  // A list of numbers may hold ints (a curve typed in by hand); an integer
  // array is refused (it is usually indices passed by mistake).
  const char kind = a.dtype().kind();
  const bool listed = !py::isinstance<py::array>(arg);
  if (kind != 'f' && !(listed && (kind == 'i' || kind == 'u')))
    throw InvalidInput(std::string("'") + name + "' must have dtype float32 or float64, got " + describe(a));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  auto r = d.unchecked<2>();
  std::vector<Eigen::Vector3f> out(std::size_t(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) {
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(r(i, k)))
        throw InvalidInput(std::string("row ") + std::to_string(i) + " of '" + name +
                           "' is not finite (NaN or Inf); use a zero vector for a free vertex");
    out[i] = Eigen::Vector3f(float(r(i, 0)), float(r(i, 1)), float(r(i, 2)));
  }
  return out;
}

Eigen::Vector3f to_vec3(const py::handle& h, const char* name) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 1 || a.shape(0) != 3)
    throw InvalidInput(std::string("'") + name + "' must be 3 numbers (x, y, z)");
  const Eigen::Vector3f v(float(a.at(0)), float(a.at(1)), float(a.at(2)));
  if (!v.allFinite() || v.norm() == 0)
    throw InvalidInput(std::string("'") + name + "' must be a finite, non-zero vector");
  return v;
}

py::array from_vectors(const std::vector<Eigen::Vector3f>& v) {
  std::vector<float> flat(v.size() * 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) flat[3 * i + k] = v[i][k];
  return take_vector(std::move(flat), {py::ssize_t(v.size()), 3});
}

DirectionFieldOptions to_options(const py::kwargs& kw) {
  DirectionFieldOptions o;
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    if (k == "weights") {
      const std::string w = string_arg(item.second, "weights", "'cotangent' or 'uniform'");
      if (w == "cotangent") o.weights = FieldWeights::Cotangent;
      else if (w == "uniform") o.weights = FieldWeights::Uniform;
      else throw InvalidInput("weights must be 'cotangent' or 'uniform', got '" + w + "'");
    } else if (k == "fallback_axis") {
      o.fallback_axis = to_vec3(item.second, "fallback_axis");
    } else if (k == "seed") {
      o.seed = seed_arg(item.second);
    } else {
      throw InvalidInput("unknown option '" + k + "'; options: weights, fallback_axis, seed");
    }
  }
  return o;
}

FieldPreset to_preset(const std::string& s) {
  if (s == "around_axis") return FieldPreset::AroundAxis;
  if (s == "along_axis") return FieldPreset::AlongAxis;
  if (s == "along_curve") return FieldPreset::AlongCurve;
  throw InvalidInput("preset must be 'around_axis', 'along_axis' or 'along_curve', got '" + s + "'");
}

}  // namespace

void bind_field(py::module_& m) {
  m.def(
      "diffuse_direction_field",
      [](const ArrayArg& vertices, const ArrayArg& faces, const ArrayArg& given, const ContextArg& ctx_arg,
         const py::kwargs& kw) {
        ExecContext* ctx = context_arg(ctx_arg);
        const TriangleMesh mesh = to_mesh(vertices, faces);
        const py::ssize_t v = py::ssize_t(mesh.vertices.size());
        const std::vector<Eigen::Vector3f> g = to_vectors(
            given, "given", v, "a " + std::to_string(v) + " by 3 float32 or float64 array (one vector per vertex; zero = free)");
        const DirectionFieldOptions opt = to_options(kw);
        std::vector<Eigen::Vector3f> field;
        {
          py::gil_scoped_release release;
          field = diffuse_direction_field(mesh, g, opt, ctx);
        }
        return from_vectors(field);
      },
      py::arg("vertices"), py::arg("faces"), py::arg("given"), py::kw_only(),
      py::arg("ctx") = py::none(),
      R"doc(Interpolate painted vectors into a unit tangent field over the surface (as Turk 2001).

vertices: V by 3 float32/float64; faces: F by 3 int32/int64. given: V by 3 float32/float64, one
vector per vertex: zero = free, non-zero = a painted constraint (only its direction in the
tangent plane counts). Options (keywords): weights='cotangent'|'uniform', fallback_axis=(0, 0, 1)
(projected where nothing was painted on a connected part), seed=0 (unused).
Returns a V by 3 float32 array of unit vectors orthogonal to the area-weighted vertex normals;
painted vertices keep their projected direction. Releases the GIL; reports to ctx.)doc");

  m.def(
      "preset_direction_field",
      [](const ArrayArg& vertices, const ArrayArg& faces, const StrArg& preset, const Vec3Arg& axis,
         const OptionalArrayArg& curve, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "preset, axis, curve, ctx");
        const TriangleMesh mesh = to_mesh(vertices, faces);
        const FieldPreset p = to_preset(string_arg(preset, "preset", "'around_axis', 'along_axis' or 'along_curve'"));
        ExecContext* ctx = context_arg(ctx_arg);
        const Eigen::Vector3f a = to_vec3(axis, "axis");
        std::vector<Eigen::Vector3f> points;
        if (!curve.is_none()) {
          // Any numeric sequence: a Blender curve's points often arrive as a list.
          points = to_vectors(curve, "curve", -1, "an N by 3 float32 or float64 array of points (N >= 2)");
        } else if (p == FieldPreset::AlongCurve) {
          throw InvalidInput("'curve' is required for preset='along_curve': an N by 3 array of points (N >= 2)");
        }
        std::vector<Eigen::Vector3f> field;
        {
          py::gil_scoped_release release;
          field = preset_direction_field(mesh, p, a, points, ctx);
        }
        return from_vectors(field);
      },
      py::arg("vertices"), py::arg("faces"), py::arg("preset") = "around_axis", py::kw_only(),
      py::arg("axis") = py::make_tuple(0.0, 0.0, 1.0), py::arg("curve") = py::none(),
      py::arg("ctx") = py::none(),
      R"doc(A unit tangent field from a preset, for meshes without a painted field.

preset: 'around_axis' (circles around `axis` through the surface centroid), 'along_axis'
(`axis` projected into each tangent plane) or 'along_curve' (tangent of the nearest point of
`curve`, an N by 3 polyline in the mesh's coordinates; repeat the first point to close it).
axis: 3 numbers, non-zero. Degenerate spots (poles, caps facing the axis) get a fixed
direction across the axis. Returns a V by 3 float32 array of unit vectors.)doc");
}

}  // namespace exsynth::py_bind
