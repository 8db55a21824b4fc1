// exsynth._native.texture_surface / surface_limit_points / surface_face_resolutions
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/surface.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// vertices (V, 3) float, face_sizes (F,) int, face_vertices (sum,) int -> PolygonMesh.
/// Index range, manifoldness and areas are checked by the core.
PolygonMesh to_polygon_mesh(const py::handle& vertices_arg, const py::handle& face_sizes_arg,
                            const py::handle& face_vertices_arg) {
  const py::array vertices = array_arg(vertices_arg, "vertices", "a (V, 3) float32/float64 array");
  const py::array face_sizes = array_arg(face_sizes_arg, "face_sizes", "an (F,) int32/int64 array");
  const py::array face_vertices = array_arg(face_vertices_arg, "face_vertices", "a (sum of face_sizes,) int32/int64 array");
  check_shape(vertices, "vertices", {-1, 3}, "(V, 3) float32/float64");
  if (!vertices.dtype().is(py::dtype::of<float>()) && !vertices.dtype().is(py::dtype::of<double>()))
    throw InvalidInput("'vertices' must have dtype float32 or float64, got " + describe(vertices));
  check_shape(face_sizes, "face_sizes", {-1}, "(F,) int32/int64");
  check_shape(face_vertices, "face_vertices", {-1}, "(sum of face_sizes,) int32/int64");
  for (const auto* a : {&face_sizes, &face_vertices})
    if (a->dtype().kind() != 'i' && a->dtype().kind() != 'u')
      throw InvalidInput(std::string(a == &face_sizes ? "'face_sizes'" : "'face_vertices'") +
                         " must be an integer array, got " + describe(*a));
  PolygonMesh m;
  const auto v_arr = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(vertices);
  auto v = v_arr.unchecked<2>();
  m.vertices.resize(std::size_t(v.shape(0)));
  for (py::ssize_t i = 0; i < v.shape(0); ++i) m.vertices[std::size_t(i)] = Eigen::Vector3f(float(v(i, 0)), float(v(i, 1)), float(v(i, 2)));
  const auto fs_arr = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(face_sizes);
  auto fs = fs_arr.unchecked<1>();
  const auto fv_arr = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(face_vertices);
  auto fv = fv_arr.unchecked<1>();
  for (py::ssize_t i = 0; i < fs.shape(0); ++i) {
    if (fs(i) < 0 || fs(i) > 1 << 20) throw InvalidInput("face_sizes[" + std::to_string(i) + "] is out of range");
    m.face_sizes.push_back(int(fs(i)));
  }
  for (py::ssize_t i = 0; i < fv.shape(0); ++i) {
    if (fv(i) < 0 || fv(i) > (1ll << 31) - 1) throw InvalidInput("face_vertices[" + std::to_string(i) + "] is out of range");
    m.face_vertices.push_back(int(fv(i)));
  }
  return m;
}

std::vector<Eigen::Vector3f> to_field(const py::handle& arg, std::size_t vertices) {
  const py::array a = array_arg(arg, "field", "a (V, 3) float array, one vector per control vertex");
  check_shape(a, "field", {py::ssize_t(vertices), 3}, "(V, 3) float, one vector per control vertex");
  const auto d_arr = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  auto d = d_arr.unchecked<2>();
  std::vector<Eigen::Vector3f> out(vertices);
  for (py::ssize_t i = 0; i < d.shape(0); ++i) {
    out[std::size_t(i)] = Eigen::Vector3f(float(d(i, 0)), float(d(i, 1)), float(d(i, 2)));
    if (!out[std::size_t(i)].allFinite()) throw InvalidInput("row " + std::to_string(i) + " of 'field' is not finite");
  }
  return out;
}

constexpr const char* kOptionNames =
    "method, texels_per_unit, face_resolution, (min|max)_face_resolution, exemplar_scale, "
    "coherent_radius, coherent_passes, levels, fine_neighborhood, coarse_neighborhood, knn, knn_tolerance, coherence, "
    "pca_variance, max_pca_dims, tileable_exemplar, vertex_charts, field_axis, memory_budget, seed, gutter, segments, "
    "displacement_(channel, scale, midlevel)";  // compact: the whole message stays under 400 characters

// Per-face resolutions above this would not fit a memory budget anyway; the
// core checks min <= face <= max between them.
constexpr int kMaxFaceResolution = 1 << 14;

void set_options(SurfaceSynthesisOptions& o, SurfaceOutputOptions& out, const py::kwargs& kw) {
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    // Ranges as surface/synthesize.cpp's validate_options and atlas.cpp (which check them again).
    if (k == "method") {
      const std::string m = string_arg(v, k, "'coherent' or 'multiscale'");
      if (m == "coherent") o.method = SurfaceMethod::Coherent;
      else if (m == "multiscale") o.method = SurfaceMethod::Multiscale;
      else throw InvalidInput("method must be 'coherent' or 'multiscale', got '" + m + "'");
    } else if (k == "texels_per_unit") o.texels_per_unit = real_arg(v, k, 0.0, kInf, Ends::Closed, "0 = face_resolution");
    else if (k == "face_resolution") o.face_resolution = int_arg(v, k, 1, kMaxFaceResolution, "texels per face edge");
    else if (k == "min_face_resolution") o.min_face_resolution = int_arg(v, k, 1, kMaxFaceResolution, "texels per face edge");
    else if (k == "max_face_resolution") o.max_face_resolution = int_arg(v, k, 1, kMaxFaceResolution, "texels per face edge");
    else if (k == "exemplar_scale") o.exemplar_scale = real_arg(v, k, 0.0, kInf, Ends::OpenLow);
    else if (k == "coherent_radius") o.coherent_radius = int_arg(v, k, 1, 5);
    else if (k == "coherent_passes") o.coherent_passes = int_arg(v, k, 1, 8);
    else if (k == "levels") o.levels = int_arg(v, k, 0, 6, "0 = automatic");
    else if (k == "fine_neighborhood") o.fine_neighborhood = int_arg(v, k, 3, 11, "odd");
    else if (k == "coarse_neighborhood") o.coarse_neighborhood = int_arg(v, k, 1, 11, "odd");
    else if (k == "knn") o.knn = int_arg(v, k, 1, 64);
    else if (k == "knn_tolerance") o.knn_tolerance = real_arg(v, k, 0.0, kInf);
    else if (k == "coherence") o.coherence = real_arg(v, k, 0.0, kInf);
    else if (k == "pca_variance") o.pca_variance = real_arg(v, k, 0.0, 1.0, Ends::OpenLow);
    else if (k == "max_pca_dims") o.max_pca_dims = int_arg(v, k, 1, 4096);
    else if (k == "tileable_exemplar") o.tileable_exemplar = bool_arg(v, k);
    else if (k == "vertex_charts") o.vertex_charts = bool_arg(v, k);
    else if (k == "field_axis") {
      const char* expected = "3 finite numbers, not all zero";
      const py::array given = array_arg(v, k, expected);
      auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(given);
      if (!a || a.ndim() != 1 || a.shape(0) != 3)
        throw InvalidInput("'field_axis' must be " + std::string(expected) + ", got " + short_repr(v));
      o.field_axis = Eigen::Vector3f(float(a.at(0)), float(a.at(1)), float(a.at(2)));
      if (!o.field_axis.allFinite() || o.field_axis.norm() == 0)
        throw InvalidInput("'field_axis' must be " + std::string(expected) + ", got " + short_repr(v));
    } else if (k == "memory_budget") o.memory_budget = memory_budget_arg(v, k);
    else if (k == "seed") o.seed = seed_arg(v, k);
    else if (k == "gutter") out.gutter = int_arg(v, k, 0, 16, "texels");
    else if (k == "segments") out.segments = int_arg(v, k, 1, kMaxSurfaceSegments, "per face");
    else if (k == "displacement_channel") out.displacement_channel = int_arg(v, k, -1, 15, "-1 = none");
    else if (k == "displacement_scale") out.displacement_scale = real_arg(v, k);
    else if (k == "displacement_midlevel") out.displacement_midlevel = real_arg(v, k);
    else throw InvalidInput("unknown option '" + k + "'; options: " + kOptionNames);
  }
}

template <class T, int N>
py::array flatten(const std::vector<Eigen::Matrix<T, N, 1>>& v) {
  std::vector<T> flat(v.size() * N);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < N; ++k) flat[i * N + std::size_t(k)] = v[i][k];
  return take_vector(std::move(flat), {py::ssize_t(v.size()), N});
}

}  // namespace

void bind_surface(py::module_& m) {
  m.attr("SURFACE_MAX_FACE_RESOLUTION") = SurfaceSynthesisOptions{}.max_face_resolution;
  m.attr("SURFACE_DEFAULT_FACE_RESOLUTION") = SurfaceSynthesisOptions{}.face_resolution;
  m.attr("SURFACE_DEFAULT_SEGMENTS") = SurfaceOutputOptions{}.segments;
  m.attr("SURFACE_MAX_SEGMENTS") = kMaxSurfaceSegments;
  m.def(
      "texture_surface",
      [](const ArrayArg& vertices, const ArrayArg& face_sizes, const ArrayArg& face_vertices,
         const ArrayArg& exemplar, const OptionalArrayArg& field, const ContextArg& ctx_arg, const py::kwargs& kw) {
        SurfaceSynthesisOptions opt;
        SurfaceOutputOptions out;
        set_options(opt, out, kw);
        ExecContext* ctx = context_arg(ctx_arg);
        const PolygonMesh mesh = to_polygon_mesh(vertices, face_sizes, face_vertices);
        const Image ex = to_image(exemplar, "exemplar");
        if (!field.is_none()) opt.field = to_field(field, mesh.vertices.size());
        SurfaceResult r;
        {
          py::gil_scoped_release release;
          r = texture_surface(mesh, ex, opt, out, ctx);
        }
        py::dict d;
        Image& a = r.atlas.image;
        d["atlas"] = take_vector(std::move(a.values()), {a.height(), a.width(), a.channels()});
        d["vertices"] = flatten(r.mesh.vertices);
        d["normals"] = flatten(r.mesh.normals);
        d["quads"] = flatten(r.mesh.quads);
        d["corner_uvs"] = flatten(r.mesh.corner_uvs);
        SurfaceTexture& t = r.texture;
        const std::size_t n = t.texel_count();
        d["texels"] = take_vector(std::move(t.texels), {py::ssize_t(n), t.channels});
        d["source"] = take_vector(std::move(t.source), {py::ssize_t(n), 2});
        std::vector<long long> offset(t.face_offset.begin(), t.face_offset.end());
        d["face_offset"] = take_vector(std::move(offset), {py::ssize_t(t.face_offset.size())});
        d["face_resolution"] = take_vector(std::move(t.face_resolution), {py::ssize_t(t.face_offset.size()) - 1});
        d["sample_spacing"] = t.sample_spacing;
        d["chart_samples"] = t.chart_samples;
        d["walked_samples"] = t.walked_samples;
        return d;
      },
      py::arg("vertices"), py::arg("face_sizes"), py::arg("face_vertices"), py::arg("exemplar"), py::kw_only(),
      py::arg("field") = py::none(), py::arg("ctx") = py::none(),
      R"doc(Texture synthesis on the Catmull-Clark limit surface of a control mesh (Ying et al. 2001).

vertices (V, 3) float; face_sizes (F,) int; face_vertices (sum face_sizes,) int, counter-clockwise.
exemplar (H, W) or (H, W, C): uint8/uint16 (scaled to [0, 1]) or float; all channels are
synthesized together (colour, alpha, height). field (V, 3): tangent vector per vertex (the mesh's
exsynth_field or a preset); None = a smooth field from field_axis.
Options (keywords): method='coherent'|'multiscale', texels_per_unit=0 (0 = face_resolution),
face_resolution=16, min_face_resolution=2, max_face_resolution=512, exemplar_scale=1,
coherent_radius=2, coherent_passes=2, levels=0 (auto), fine_neighborhood=9, coarse_neighborhood=5, knn=4,
knn_tolerance=0, coherence=1.0, pca_variance=0.97, max_pca_dims=24, tileable_exemplar=False,
vertex_charts=True (False: walk every neighbourhood sample on the limit surface), field_axis=(0, 0, 1), memory_budget=0 (default), seed=0; output: gutter=2, segments=2 (per n-gon
sub-face; quads get 2x), displacement_channel=-1, displacement_scale=0, displacement_midlevel=0.5.
Returns {'atlas': (H, W, C) float32 (row 0 = top), 'vertices': (N, 3), 'normals': (N, 3),
'quads': (Q, 4) int32, 'corner_uvs': (4 Q, 2) (origin bottom-left), 'texels': (T, C),
'source': (T, 2), 'face_offset': (P + 1,), 'face_resolution': (P,), 'sample_spacing': float, 'chart_samples' / 'walked_samples': int (neighbourhood samples placed through vertex charts / walked)}.)doc");

  m.def(
      "surface_limit_points",
      [](const ArrayArg& vertices, const ArrayArg& face_sizes, const ArrayArg& face_vertices,
         const ArrayArg& faces_arg, const ArrayArg& uv_arg, const py::kwargs& extra) {
        reject_unknown(extra, "vertices, face_sizes, face_vertices, faces, uv");
        const PolygonMesh mesh = to_polygon_mesh(vertices, face_sizes, face_vertices);
        const py::array faces = array_arg(faces_arg, "faces", "an (N,) int array of ptex face indices");
        const py::array uv = array_arg(uv_arg, "uv", "an (N, 2) float array in [0, 1]");
        check_shape(faces, "faces", {-1}, "(N,) int ptex face indices");
        check_shape(uv, "uv", {faces.shape(0), 2}, "(N, 2) float in [0, 1]");
        const auto f_arr = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(faces);
  auto f = f_arr.unchecked<1>();
        const auto u_arr = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(uv);
  auto u = u_arr.unchecked<2>();
        std::vector<double> pos(std::size_t(f.shape(0)) * 3), du(pos.size()), dv(pos.size());
        {
          py::gil_scoped_release release;
          const SubdivSurface s(mesh);
          for (py::ssize_t i = 0; i < f.shape(0); ++i) {
            if (f(i) < 0 || f(i) >= s.ptex_face_count())
              throw InvalidInput("faces[" + std::to_string(i) + "] is not a ptex face (there are " +
                                 std::to_string(s.ptex_face_count()) + ")");
            if (!(u(i, 0) >= 0 && u(i, 0) <= 1 && u(i, 1) >= 0 && u(i, 1) <= 1))
              throw InvalidInput("uv[" + std::to_string(i) + "] is outside [0, 1]^2");
            const LimitFrame lf = s.evaluate({int(f(i)), u(i, 0), u(i, 1)});
            for (int k = 0; k < 3; ++k) {
              pos[std::size_t(i) * 3 + std::size_t(k)] = lf.position[k];
              du[std::size_t(i) * 3 + std::size_t(k)] = lf.du[k];
              dv[std::size_t(i) * 3 + std::size_t(k)] = lf.dv[k];
            }
          }
        }
        py::dict d;
        const py::ssize_t n = f.shape(0);
        d["position"] = take_vector(std::move(pos), {n, 3});
        d["du"] = take_vector(std::move(du), {n, 3});
        d["dv"] = take_vector(std::move(dv), {n, 3});
        return d;
      },
      py::arg("vertices"), py::arg("face_sizes"), py::arg("face_vertices"), py::arg("faces"), py::arg("uv"),
      "Limit positions and first derivatives at (ptex face, u, v): {'position', 'du', 'dv'}: (N, 3) float64.\n"
      "Ptex faces: a quad is one face, an n-gon n sub-faces, in face order.");

  m.def(
      "surface_texel_count",
      [](const ArrayArg& vertices, const ArrayArg& face_sizes, const ArrayArg& face_vertices,
         const py::kwargs& kw) {
        SurfaceSynthesisOptions opt;
        SurfaceOutputOptions out;
        set_options(opt, out, kw);
        const PolygonMesh mesh = to_polygon_mesh(vertices, face_sizes, face_vertices);
        std::vector<int> res;
        {
          py::gil_scoped_release release;
          res = surface_face_resolutions(SubdivSurface(mesh), opt);
        }
        double total = 0;
        for (int r : res) total += double(r) * r;
        return total;
      },
      py::arg("vertices"), py::arg("face_sizes"), py::arg("face_vertices"),
      "Texels texture_surface would synthesize for these options (same keywords).");
}

}  // namespace exsynth::py_bind
