// exsynth._native: point-set geometry texture synthesis (make_point_exemplar,
// height_field_exemplar, sample_mesh_points, synthesize_points,
// synthesize_points_on_mesh, point_texture_preset).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/points.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// N by 3 float32/float64 -> vectors (finiteness is the core's check, with the row).
std::vector<Eigen::Vector3f> to_rows3(const py::object& obj, const char* name, const char* expected) {
  const py::array a = py::array::ensure(obj);
  if (!a) throw InvalidInput(std::string("'") + name + "' must be " + expected);
  check_shape(a, name, {-1, 3}, expected);
  if (!a.dtype().is(py::dtype::of<float>()) && !a.dtype().is(py::dtype::of<double>()))
    throw InvalidInput(std::string("'") + name + "' must have dtype float32 or float64, got " + describe(a));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  auto r = d.unchecked<2>();
  std::vector<Eigen::Vector3f> out(std::size_t(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[i] = Eigen::Vector3f(float(r(i, 0)), float(r(i, 1)), float(r(i, 2)));
  return out;
}

Eigen::Vector2d to_vec2(const py::object& obj, const char* name) {
  const auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!v || v.ndim() != 1 || v.shape(0) != 2)
    throw InvalidInput(std::string("'") + name + "' must be two numbers (x, y)");
  return {v.at(0), v.at(1)};
}

py::array rows3(const std::vector<Eigen::Vector3f>& v) {
  std::vector<float> flat(v.size() * 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) flat[3 * i + k] = v[i][k];
  return take_vector(std::move(flat), {py::ssize_t(v.size()), 3});
}

PointExemplar to_exemplar(const py::object& positions, const py::object& normals, const py::object& box_min,
                          const py::object& box_max) {
  PointExemplar ex;
  ex.points.positions = to_rows3(positions, "positions", "an N by 3 float32 or float64 array of points");
  if (normals.is_none())
    throw InvalidInput("'normals' is missing: the exemplar must be an oriented point set (one unit normal per point)");
  ex.points.normals = to_rows3(normals, "normals", "an N by 3 float32 or float64 array of unit normals");
  ex.box_min = to_vec2(box_min, "box_min");
  ex.box_max = to_vec2(box_max, "box_max");
  return ex;
}

py::dict exemplar_dict(PointExemplar&& ex) {
  py::dict d;
  d["positions"] = rows3(ex.points.positions);
  d["normals"] = rows3(ex.points.normals);
  d["box_min"] = py::make_tuple(ex.box_min.x(), ex.box_min.y());
  d["box_max"] = py::make_tuple(ex.box_max.x(), ex.box_max.y());
  return d;
}

// The options struct <-> a dict with the same names; unknown keys are an error.
#define EXSYNTH_POINT_OPTIONS(X)                                                                          \
  X(patch_size, double) X(extra, double) X(epsilon, double) X(grid_resolution, int) X(w_sdf, double)     \
  X(w_gradient, double) X(w_p, double) X(w_n, double) X(w_v, double) X(max_pair_distance, double)        \
  X(min_pair_normal_dot, double) X(max_pair_variation, double) X(w_l, double) X(w_d, double)             \
  X(pairing_iterations, int) X(max_pairs, int) X(tps_regularization, double) X(blend_iterations, int)    \
  X(relax_iterations, int) X(bandwidth, double)

py::dict options_dict(const PointTextureOptions& o) {
  py::dict d;
#define X(name, type) d[#name] = o.name;
  EXSYNTH_POINT_OPTIONS(X)
#undef X
  return d;
}

PointTextureOptions to_options(const py::object& obj, std::size_t memory_budget, std::uint64_t seed) {
  PointTextureOptions o;
  if (!obj.is_none()) {
    const py::dict d = py::reinterpret_borrow<py::dict>(obj);
    for (const auto& [k, v] : d) {
      const std::string key = py::str(k);
      bool known = false;
#define X(name, type)                                                                          \
  if (key == #name) {                                                                          \
    try {                                                                                      \
      o.name = v.cast<type>();                                                                 \
    } catch (const py::cast_error&) {                                                          \
      throw InvalidInput("point texture option '" #name "' must be a number");                 \
    }                                                                                          \
    known = true;                                                                              \
  }
      EXSYNTH_POINT_OPTIONS(X)
#undef X
      if (!known) throw InvalidInput("unknown point texture option '" + key + "' (see point_texture_preset())");
    }
  }
  o.memory_budget = memory_budget ? memory_budget : kDefaultMemoryBudget;
  o.seed = seed;
  return o;
}

py::dict result_dict(PointTextureResult&& r) {
  py::dict d;
  d["positions"] = rows3(r.points.positions);
  d["normals"] = rows3(r.points.normals);
  d["patches"] = r.patches;
  d["pairs"] = r.pairs;
  d["fallbacks"] = r.fallbacks;
  d["spacing"] = r.spacing;
  d["density"] = r.density;
  py::dict t;
  t["search"] = r.times.search;
  t["warp"] = r.times.warp;
  t["blend"] = r.times.blend;
  t["other"] = r.times.other;
  d["times"] = t;
  return d;
}

}  // namespace

void bind_points(py::module_& m) {
  m.def("point_texture_preset", [](const std::string& name) { return options_dict(point_texture_preset(name)); },
        py::arg("name") = "default",
        "The synthesis options (a dict) tuned for a built-in texture: default, bumps, chainmail, weave, flowers.");

  m.def(
      "make_point_exemplar",
      [](const std::string& name, double density, double padding, std::uint64_t seed, ExecContext* ctx) {
        PointExemplar ex;
        {
          py::gil_scoped_release release;
          ex = make_point_exemplar(name, density, padding, seed, ctx);
        }
        return exemplar_dict(std::move(ex));
      },
      py::arg("name"), py::kw_only(), py::arg("density") = 20000.0, py::arg("padding") = 0.35,
      py::arg("seed") = std::uint64_t(0), py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "A built-in geometry texture (bumps, chainmail, weave, flowers): box [0, 1]^2 plus `padding`, `density`\n"
      "points per unit surface area. Returns {'positions' N by 3, 'normals' N by 3, 'box_min', 'box_max'}.");

  m.def(
      "height_field_exemplar",
      [](const py::array& heights, double pixel_size, double density, int padding, std::uint64_t seed,
         ExecContext* ctx) {
        check_shape(heights, "heights", {-1, -1}, "a (rows, cols) float array of heights (row = y)");
        auto h = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(heights);
        std::vector<float> v(h.data(), h.data() + h.size());
        const int rows = int(heights.shape(0)), cols = int(heights.shape(1));
        PointExemplar ex;
        {
          py::gil_scoped_release release;
          ex = height_field_exemplar(v, rows, cols, pixel_size, density, padding, seed, ctx);
        }
        return exemplar_dict(std::move(ex));
      },
      py::arg("heights"), py::kw_only(), py::arg("pixel_size") = 1.0, py::arg("density") = 4.0,
      py::arg("padding") = 8, py::arg("seed") = std::uint64_t(0), py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "An oriented point set sampled evenly (density per unit area) from a height field (rows = y, one pixel =\n"
      "pixel_size units); the box leaves `padding` pixels on every side as padding.");

  m.def(
      "sample_mesh_points",
      [](const py::array& vertices, const py::array& faces, double density, std::uint64_t seed,
         std::size_t memory_budget, ExecContext* ctx) {
        const TriangleMesh mesh = to_mesh(vertices, faces);
        OrientedPoints p;
        {
          py::gil_scoped_release release;
          p = sample_mesh_points(mesh, density, seed, memory_budget ? memory_budget : kDefaultMemoryBudget, ctx);
        }
        return py::make_tuple(rows3(p.positions), rows3(p.normals));
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("density"), py::arg("seed") = std::uint64_t(0),
      py::arg("memory_budget") = std::size_t(0), py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "Even samples of a mesh's surface (V by 3 vertices, F by 3 faces): density points per unit area,\n"
      "area-weighted random candidates thinned by sample elimination (blue noise). Returns (positions, normals).");

  m.def(
      "synthesize_points",
      [](const py::object& positions, const py::object& normals, const py::object& box_min, const py::object& box_max,
         const py::object& size, const py::object& options, std::size_t memory_budget, std::uint64_t seed,
         ExecContext* ctx) {
        const PointExemplar ex = to_exemplar(positions, normals, box_min, box_max);
        const Eigen::Vector2d wd = to_vec2(size, "size");
        const PointTextureOptions o = to_options(options, memory_budget, seed);
        PointTextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_points(ex, wd.x(), wd.y(), o, ctx);
        }
        return result_dict(std::move(r));
      },
      py::arg("positions"), py::arg("normals"), py::kw_only(), py::arg("box_min") = py::make_tuple(0.0, 0.0),
      py::arg("box_max") = py::make_tuple(1.0, 1.0), py::arg("size") = py::make_tuple(2.0, 2.0),
      py::arg("options") = py::none(), py::arg("memory_budget") = std::size_t(0), py::arg("seed") = std::uint64_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "Grow an oriented point set (positions, normals: N by 3; its box in the reference plane z = 0) over\n"
      "[0, size[0]] x [0, size[1]]. options: a dict of point_texture_preset()'s keys. Returns {'positions',\n"
      "'normals', 'patches', 'pairs', 'fallbacks', 'spacing', 'density', 'times': {search, warp, blend, other}}.");

  m.def(
      "synthesize_points_on_mesh",
      [](const py::object& positions, const py::object& normals, const py::array& vertices, const py::array& faces,
         const py::object& field, const py::object& box_min, const py::object& box_max, double scale,
         const py::object& options, std::size_t memory_budget, std::uint64_t seed, ExecContext* ctx) {
        const PointExemplar ex = to_exemplar(positions, normals, box_min, box_max);
        const TriangleMesh mesh = to_mesh(vertices, faces);
        const std::vector<Eigen::Vector3f> f =
            to_rows3(field, "field", "a V by 3 float32 or float64 array: one tangent direction per vertex");
        const PointTextureOptions o = to_options(options, memory_budget, seed);
        PointTextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_points_on_mesh(ex, mesh, f, scale, o, ctx);
        }
        return result_dict(std::move(r));
      },
      py::arg("positions"), py::arg("normals"), py::arg("vertices"), py::arg("faces"), py::kw_only(),
      py::arg("field"), py::arg("box_min") = py::make_tuple(0.0, 0.0), py::arg("box_max") = py::make_tuple(1.0, 1.0),
      py::arg("scale") = 1.0, py::arg("options") = py::none(), py::arg("memory_budget") = std::size_t(0),
      py::arg("seed") = std::uint64_t(0), py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "Grow the point texture over a target mesh (V by 3 vertices, F by 3 faces), its x axis along `field`\n"
      "(V by 3 tangents), `scale` target units per exemplar unit. Same result dict as synthesize_points.");
  m.def(
      "points_to_mesh",
      [](const py::object& positions, const py::object& normals, double spacing, double radius, double voxel,
         int smoothing, std::size_t memory_budget, ExecContext* ctx) {
        OrientedPoints pts;
        pts.positions = to_rows3(positions, "positions", "an N by 3 float32 or float64 array of points");
        if (normals.is_none()) throw InvalidInput("'normals' is missing: points_to_mesh needs oriented points");
        pts.normals = to_rows3(normals, "normals", "an N by 3 float32 or float64 array of unit normals");
        PointMeshOptions o;
        o.radius = radius;
        o.voxel = voxel;
        o.smoothing = smoothing;
        o.memory_budget = memory_budget ? memory_budget : kDefaultMemoryBudget;
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = points_to_mesh(pts, spacing, o, ctx);
        }
        std::vector<std::int32_t> faces(mesh.faces.size() * 3);
        for (std::size_t i = 0; i < mesh.faces.size(); ++i)
          for (int k = 0; k < 3; ++k) faces[3 * i + k] = mesh.faces[i][k];
        return py::make_tuple(rows3(mesh.vertices), take_vector(std::move(faces), {py::ssize_t(mesh.faces.size()), 3}));
      },
      py::arg("positions"), py::arg("normals"), py::kw_only(), py::arg("spacing") = 0.0, py::arg("radius") = 1.5,
      py::arg("voxel") = 0.75, py::arg("smoothing") = 1, py::arg("memory_budget") = std::size_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      "A mesh from oriented points (OpenVDB particles -> level set -> mesh): spheres of `radius` spacings inset\n"
      "along the normals, voxels of `voxel` spacings (spacing <= 0: measured). Returns (vertices V by 3, faces F by 3).");
}

}  // namespace exsynth::py_bind
