// exsynth._native: point-set geometry texture synthesis (make_point_exemplar,
// height_field_exemplar, sample_mesh_points, synthesize_points,
// synthesize_points_on_mesh, point_texture_preset).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/points.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// N by 3 float32/float64 -> vectors (finiteness is the core's check, with the row).
std::vector<Eigen::Vector3f> to_rows3(const py::handle& obj, const char* name, const char* expected) {
  const py::array a = array_arg(obj, name, expected);
  check_shape(a, name, {-1, 3}, expected);
  if (!a.dtype().is(py::dtype::of<float>()) && !a.dtype().is(py::dtype::of<double>()))
    throw InvalidInput(std::string("'") + name + "' must have dtype float32 or float64, got " + describe(a));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  auto r = d.unchecked<2>();
  std::vector<Eigen::Vector3f> out(std::size_t(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[i] = Eigen::Vector3f(float(r(i, 0)), float(r(i, 1)), float(r(i, 2)));
  return out;
}

Eigen::Vector2d to_vec2(const py::handle& obj, const char* name) {
  const char* expected = "two finite numbers (x, y)";
  const py::array a = array_arg(obj, name, expected);
  const auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!v || v.ndim() != 1 || v.shape(0) != 2)
    throw InvalidInput(std::string("'") + name + "' must be " + expected + ", got " + short_repr(obj));
  const Eigen::Vector2d out(v.at(0), v.at(1));
  if (!out.allFinite()) throw InvalidInput(std::string("'") + name + "' must be " + expected + ", got " + short_repr(obj));
  return out;
}

py::array rows3(const std::vector<Eigen::Vector3f>& v) {
  std::vector<float> flat(v.size() * 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) flat[3 * i + k] = v[i][k];
  return take_vector(std::move(flat), {py::ssize_t(v.size()), 3});
}

PointExemplar to_exemplar(const py::handle& positions, const py::handle& normals, const py::handle& box_min,
                          const py::handle& box_max) {
  PointExemplar ex;
  ex.points.positions = to_rows3(positions, "positions", "an N by 3 float32 or float64 array of points");
  if (normals.is_none())
    throw InvalidInput("'normals' is missing: the exemplar must be an oriented point set (one unit normal per point)");
  ex.points.normals = to_rows3(normals, "normals", "an N by 3 float32 or float64 array of unit normals");
  ex.box_min = to_vec2(box_min, "box_min");
  ex.box_max = to_vec2(box_max, "box_max");
  return ex;
}

constexpr const char* kPresetNames = kPointPresetNames;
// Bounds the core leaves open (it checks padding against the image and smoothing >= 0).
constexpr int kMaxHeightFieldPadding = 1 << 20;
constexpr int kMaxPointMeshSmoothing = 64;

py::dict exemplar_dict(PointExemplar&& ex) {
  py::dict d;
  d["positions"] = rows3(ex.points.positions);
  d["normals"] = rows3(ex.points.normals);
  d["box_min"] = py::make_tuple(ex.box_min.x(), ex.box_min.y());
  d["box_max"] = py::make_tuple(ex.box_max.x(), ex.box_max.y());
  return d;
}

// The options struct <-> a dict with the same names; unknown keys are an error.
// Ranges as points/patch_solver.cpp's check_options (which checks them again);
// the pairing limits it does not check are only required to be finite.
#define EXSYNTH_POINT_OPTIONS(R, I)                                                                       \
  R(patch_size, 0.0, kInf, Ends::OpenLow, "exemplar units") R(extra, 0.05, 0.5, Ends::OpenLow,          \
  "a fraction of patch_size") R(epsilon, 0.0, kInf, Ends::Closed, "") I(grid_resolution, 4, 64)         \
  R(w_sdf, 0.0, kInf, Ends::Closed, "") R(w_gradient, 0.0, kInf, Ends::Closed, "")                      \
  R(w_p, 0.0, kInf, Ends::Closed, "") R(w_n, 0.0, kInf, Ends::Closed, "") R(w_v, 0.0, kInf, Ends::Closed, "") \
  R(max_pair_distance, -kInf, kInf, Ends::Closed, "point spacings")                                     \
  R(min_pair_normal_dot, -kInf, kInf, Ends::Closed, "") R(max_pair_variation, -kInf, kInf, Ends::Closed, "") \
  R(w_l, 0.0, kInf, Ends::Closed, "") R(w_d, 0.0, kInf, Ends::Closed, "") I(pairing_iterations, 1, 20)  \
  I(max_pairs, 4, 2000) R(tps_regularization, -kInf, kInf, Ends::Closed, "") I(blend_iterations, 1, 20) \
  I(relax_iterations, 0, 20) R(bandwidth, 0.5, 10.0, Ends::Closed, "point spacings")

py::dict options_dict(const PointTextureOptions& o) {
  py::dict d;
#define R(name, lo, hi, ends, unit) d[#name] = o.name;
#define I(name, lo, hi) d[#name] = o.name;
  EXSYNTH_POINT_OPTIONS(R, I)
#undef R
#undef I
  return d;
}

PointTextureOptions to_options(const py::handle& obj, std::size_t memory_budget, std::uint64_t seed) {
  PointTextureOptions o;
  if (!obj.is_none()) {
    const py::dict d = dict_arg(obj, "options", "a dict of point_texture_preset()'s keys, or None");
    for (const auto& [k, v] : d) {
      const std::string key = py::str(k);
      bool known = false;
#define R(name, lo, hi, ends, unit)                  \
  if (key == #name) {                                \
    o.name = real_arg(v, #name, lo, hi, ends, unit); \
    known = true;                                    \
  }
#define I(name, lo, hi)                \
  if (key == #name) {                  \
    o.name = int_arg(v, #name, lo, hi); \
    known = true;                      \
  }
      EXSYNTH_POINT_OPTIONS(R, I)
#undef R
#undef I
      if (!known) throw InvalidInput("unknown point texture option '" + key + "' (see point_texture_preset())");
    }
  }
  o.memory_budget = memory_budget;
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
  {
    py::list names;
    for (const char* name : kPointBuiltins) names.append(name);
    m.attr("POINT_BUILTINS") = py::tuple(names);
  }
  m.attr("POINTS_DEFAULT_DENSITY") = kDefaultPointDensity;
  m.def(
      "point_texture_preset",
      [](const StrArg& name, const py::kwargs& extra) {
        reject_unknown(extra, "name");
        return options_dict(point_texture_preset(string_arg(name, "name", kPresetNames)));
      },
      py::arg("name") = "default",
      "The synthesis options (a dict) for a built-in texture: default, heightfield (= bumps), chainmail, weave, "
      "flowers; the pairing weights are the paper's Table 1 rows.");

  m.def(
      "make_point_exemplar",
      [](const StrArg& name_arg, const RealArg& density_arg, const RealArg& padding_arg, const IntArg& seed_a,
         const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "name, density, padding, seed, ctx");
        const std::string name = string_arg(name_arg, "name", "bumps, chainmail, weave or flowers");
        const double density = real_arg(density_arg, "density", 0.0, kInf, Ends::OpenLow, "points per unit area");
        // Range as points/exemplars.cpp's make_point_exemplar.
        const double padding = real_arg(padding_arg, "padding", 0.0, 2.0, Ends::Closed, "box units");
        const std::uint64_t seed = seed_arg(seed_a);
        ExecContext* ctx = context_arg(ctx_arg);
        PointExemplar ex;
        {
          py::gil_scoped_release release;
          ex = make_point_exemplar(name, density, padding, seed, ctx);
        }
        return exemplar_dict(std::move(ex));
      },
      py::arg("name"), py::kw_only(), py::arg("density") = 20000.0, py::arg("padding") = 0.35,
      py::arg("seed") = 0, py::arg("ctx") = py::none(),
      "A built-in geometry texture (bumps, chainmail, weave, flowers): box [0, 1]^2 plus `padding`, `density`\n"
      "points per unit surface area. Returns {'positions' N by 3, 'normals' N by 3, 'box_min', 'box_max'}.");

  m.def(
      "height_field_exemplar",
      [](const ArrayArg& heights_arg, const RealArg& pixel_size_arg, const RealArg& density_arg,
         const IntArg& padding_arg, const IntArg& seed_a, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "heights, pixel_size, density, padding, seed, ctx");
        const double pixel_size = real_arg(pixel_size_arg, "pixel_size", 0.0, kInf, Ends::OpenLow, "units per pixel");
        const double density = real_arg(density_arg, "density", 0.0, kInf, Ends::OpenLow, "points per unit area");
        // The core checks that the padding leaves a box inside the image.
        const int padding = int_arg(padding_arg, "padding", 0, kMaxHeightFieldPadding, "pixels per side");
        const std::uint64_t seed = seed_arg(seed_a);
        ExecContext* ctx = context_arg(ctx_arg);
        const py::array heights = array_arg(heights_arg, "heights", "a (rows, cols) float array of heights");
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
      py::arg("padding") = 8, py::arg("seed") = 0, py::arg("ctx") = py::none(),
      "An oriented point set sampled evenly (density per unit area) from a height field (rows = y, one pixel =\n"
      "pixel_size units); the box leaves `padding` pixels on every side as padding.");

  m.def(
      "sample_mesh_points",
      [](const ArrayArg& vertices, const ArrayArg& faces, const RealArg& density_arg, const IntArg& seed_a,
         const IntArg& budget_arg, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "vertices, faces, density, seed, memory_budget, ctx");
        const double density = real_arg(density_arg, "density", 0.0, kInf, Ends::OpenLow, "points per unit area");
        const std::uint64_t seed = seed_arg(seed_a);
        const std::size_t budget = memory_budget_arg(budget_arg);
        ExecContext* ctx = context_arg(ctx_arg);
        const TriangleMesh mesh = to_mesh(vertices, faces);
        OrientedPoints p;
        {
          py::gil_scoped_release release;
          p = sample_mesh_points(mesh, density, seed, budget, ctx);
        }
        return py::make_tuple(rows3(p.positions), rows3(p.normals));
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("density"), py::arg("seed") = 0,
      py::arg("memory_budget") = 0, py::arg("ctx") = py::none(),
      "Even samples of a mesh's surface (V by 3 vertices, F by 3 faces): density points per unit area,\n"
      "area-weighted random candidates thinned by sample elimination (blue noise). Returns (positions, normals).");

  m.def(
      "synthesize_points",
      [](const ArrayArg& positions, const OptionalArrayArg& normals, const py::object& box_min,
         const py::object& box_max, const py::object& size, const py::object& options, const IntArg& budget_arg,
         const IntArg& seed_a, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "positions, normals, box_min, box_max, size, options, memory_budget, seed, ctx");
        const std::size_t budget = memory_budget_arg(budget_arg);
        const std::uint64_t seed = seed_arg(seed_a);
        ExecContext* ctx = context_arg(ctx_arg);
        const PointExemplar ex = to_exemplar(positions, normals, box_min, box_max);
        const Eigen::Vector2d wd = to_vec2(size, "size");
        const PointTextureOptions o = to_options(options, budget, seed);
        PointTextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_points(ex, wd.x(), wd.y(), o, ctx);
        }
        return result_dict(std::move(r));
      },
      py::arg("positions"), py::arg("normals"), py::kw_only(), py::arg("box_min") = py::make_tuple(0.0, 0.0),
      py::arg("box_max") = py::make_tuple(1.0, 1.0), py::arg("size") = py::make_tuple(2.0, 2.0),
      py::arg("options") = py::none(), py::arg("memory_budget") = 0, py::arg("seed") = 0,
      py::arg("ctx") = py::none(),
      "Grow an oriented point set (positions, normals: N by 3; its box in the reference plane z = 0) over\n"
      "[0, size[0]] x [0, size[1]]. options: a dict of point_texture_preset()'s keys. Returns {'positions',\n"
      "'normals', 'patches', 'pairs', 'fallbacks', 'spacing', 'density', 'times': {search, warp, blend, other}}.");

  m.def(
      "synthesize_points_on_mesh",
      [](const ArrayArg& positions, const OptionalArrayArg& normals, const ArrayArg& vertices, const ArrayArg& faces,
         const ArrayArg& field, const py::object& box_min, const py::object& box_max, const RealArg& scale_arg,
         const py::object& options, const IntArg& budget_arg, const IntArg& seed_a, const ContextArg& ctx_arg,
         const py::kwargs& extra) {
        reject_unknown(extra,
                       "positions, normals, vertices, faces, field, box_min, box_max, scale, options, memory_budget, "
                       "seed, ctx");
        const double scale = real_arg(scale_arg, "scale", 0.0, kInf, Ends::OpenLow, "target units per exemplar unit");
        const std::size_t budget = memory_budget_arg(budget_arg);
        const std::uint64_t seed = seed_arg(seed_a);
        ExecContext* ctx = context_arg(ctx_arg);
        const PointExemplar ex = to_exemplar(positions, normals, box_min, box_max);
        const TriangleMesh mesh = to_mesh(vertices, faces);
        const std::vector<Eigen::Vector3f> f =
            to_rows3(field, "field", "a V by 3 float32 or float64 array: one tangent direction per vertex");
        const PointTextureOptions o = to_options(options, budget, seed);
        PointTextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_points_on_mesh(ex, mesh, f, scale, o, ctx);
        }
        return result_dict(std::move(r));
      },
      py::arg("positions"), py::arg("normals"), py::arg("vertices"), py::arg("faces"), py::kw_only(),
      py::arg("field"), py::arg("box_min") = py::make_tuple(0.0, 0.0), py::arg("box_max") = py::make_tuple(1.0, 1.0),
      py::arg("scale") = 1.0, py::arg("options") = py::none(), py::arg("memory_budget") = 0,
      py::arg("seed") = 0, py::arg("ctx") = py::none(),
      "Grow the point texture over a target mesh (V by 3 vertices, F by 3 faces), its x axis along `field`\n"
      "(V by 3 tangents), `scale` target units per exemplar unit. Same result dict as synthesize_points.");
  m.def(
      "estimate_points_on_mesh",
      [](const RealArg& density_arg, const RealArg& area_arg, const RealArg& scale_arg, const py::object& options,
         const py::kwargs& extra) {
        reject_unknown(extra, "density, area, scale, options");
        const double density = real_arg(density_arg, "density", 0.0, kInf, Ends::OpenLow, "exemplar points per unit area");
        const double area = real_arg(area_arg, "area", 0.0, kInf, Ends::OpenLow, "target surface area");
        const double scale = real_arg(scale_arg, "scale", 0.0, kInf, Ends::OpenLow, "target units per exemplar unit");
        const PointTextureEstimate e = estimate_points_on_mesh(density, area, scale, to_options(options, 0, 0));
        py::dict d;
        d["patches"] = e.patches;
        d["points"] = e.points;
        d["bytes"] = e.bytes;
        d["seconds"] = e.seconds;
        return d;
      },
      py::arg("density"), py::kw_only(), py::arg("area"), py::arg("scale"), py::arg("options") = py::none(),
      "What synthesize_points_on_mesh makes, before any work: {'patches', 'points', 'bytes', 'seconds'} for an\n"
      "exemplar of `density` points per unit of its box over a target of surface `area` at `scale`.");
  m.def(
      "default_points_scale",
      [](const RealArg& density_arg, const RealArg& area_arg, const py::kwargs& extra) {
        reject_unknown(extra, "density, area");
        return default_points_scale(real_arg(density_arg, "density", 0.0, kInf, Ends::OpenLow, "points per unit area"),
                                    real_arg(area_arg, "area", 0.0, kInf, Ends::OpenLow, "target surface area"));
      },
      py::arg("density"), py::kw_only(), py::arg("area"),
      "The scale giving about POINTS_DEFAULT_OUTPUT points over a target of surface `area`.");
  m.def(
      "point_exemplar_surface_ratio",
      [](const StrArg& name, const py::kwargs& extra) {
        reject_unknown(extra, "name");
        return point_exemplar_surface_ratio(string_arg(name, "name", "bumps, chainmail, weave or flowers"));
      },
      py::arg("name"), "A built-in exemplar's surface area per unit of its box: its points per box area / density.");
  m.attr("POINTS_DEFAULT_OUTPUT") = kDefaultPointsOnMesh;
  m.attr("POINTS_SECONDS_PER_POINT") = kPointSecondsPerPoint;

  m.def(
      "points_to_mesh",
      [](const ArrayArg& positions, const OptionalArrayArg& normals, const RealArg& spacing_arg,
         const RealArg& radius_arg, const RealArg& voxel_arg, const IntArg& smoothing_arg, const IntArg& budget_arg,
         const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "positions, normals, spacing, radius, voxel, smoothing, memory_budget, ctx");
        const double spacing = real_arg(spacing_arg, "spacing", -kInf, kInf, Ends::Closed, "0 or less = measured");
        PointMeshOptions o;
        o.radius = real_arg(radius_arg, "radius", 0.0, kInf, Ends::OpenLow, "point spacings");
        o.voxel = real_arg(voxel_arg, "voxel", 0.0, kInf, Ends::OpenLow, "point spacings");
        o.smoothing = int_arg(smoothing_arg, "smoothing", 0, kMaxPointMeshSmoothing, "passes");
        o.memory_budget = memory_budget_arg(budget_arg);
        ExecContext* ctx = context_arg(ctx_arg);
        OrientedPoints pts;
        pts.positions = to_rows3(positions, "positions", "an N by 3 float32 or float64 array of points");
        if (normals.is_none()) throw InvalidInput("'normals' is missing: points_to_mesh needs oriented points");
        pts.normals = to_rows3(normals, "normals", "an N by 3 float32 or float64 array of unit normals");
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
      py::arg("voxel") = 0.75, py::arg("smoothing") = 1, py::arg("memory_budget") = 0,
      py::arg("ctx") = py::none(),
      "A mesh from oriented points (OpenVDB particles -> level set -> mesh): spheres of `radius` spacings inset\n"
      "along the normals, voxels of `voxel` spacings (spacing <= 0: measured). Returns (vertices V by 3, faces F by 3).");
}

}  // namespace exsynth::py_bind
