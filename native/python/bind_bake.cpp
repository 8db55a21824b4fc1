// exsynth._native.sample_volume / bake_volume_to_uv
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/bake.hpp"
#include "exsynth/errors.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// (N, 3) float -> points; (F, 3, K) float -> per-corner vectors.
std::vector<Eigen::Vector3f> to_points(const py::handle& arg, const char* name) {
  const py::array a = array_arg(arg, name, "an N by 3 float32 or float64 array");
  check_shape(a, name, {-1, 3}, "an N by 3 float32 or float64 array");
  auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!f) throw InvalidInput(std::string("'") + name + "' must be a float array, got a " + describe(a));
  std::vector<Eigen::Vector3f> out(std::size_t(a.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Eigen::Vector3f(f.at(i, 0), f.at(i, 1), f.at(i, 2));
  return out;
}

template <int K>
std::vector<std::array<Eigen::Matrix<float, K, 1>, 3>> to_corners(const py::handle& arg, const char* name,
                                                                  const char* expected) {
  const py::array a = array_arg(arg, name, expected);
  check_shape(a, name, {-1, 3, K}, expected);
  auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!f) throw InvalidInput(std::string("'") + name + "' must be a float array, got a " + describe(a));
  std::vector<std::array<Eigen::Matrix<float, K, 1>, 3>> out(std::size_t(a.shape(0)));
  const float* d = f.data();
  for (std::size_t t = 0; t < out.size(); ++t)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < K; ++k) out[t][c][k] = d[(t * 3 + c) * K + k];
  return out;
}

Interpolation interpolation_arg(const py::handle& v) {
  return interpolation_from_name(string_arg(v, "interpolation", "'linear' or 'cubic'"), "interpolation");
}

}  // namespace

void bind_bake(py::module_& m) {
  m.attr("INTERPOLATION_CHOICES") = py::tuple(py::cast(interpolation_names()));
  const std::string default_interp = interpolation_names()[std::size_t(kDefaultInterpolation)];
  m.attr("DEFAULT_INTERPOLATION") = default_interp;
  m.attr("BAKE_DEFAULT_SIZE") = BakeOptions{}.width;
  m.attr("BAKE_MAX_SIZE") = kMaxBakeSize;
  m.def(
      "sample_volume",
      [](const ArrayArg& volume, const Vec3Arg& origin, const RealArg& voxel_size, const ArrayArg& points,
         const BoolArg& wrap_arg, const StrArg& interp_arg, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "wrap, interpolation, ctx");
        const Volume v = to_volume(volume, "volume", to_transform(origin, voxel_size));
        const std::vector<Eigen::Vector3f> p = to_points(points, "points");
        const bool wrap = bool_arg(wrap_arg, "wrap");
        const Interpolation interp = interpolation_arg(interp_arg);
        ExecContext* ctx = context_arg(ctx_arg);
        std::vector<float> out(p.size() * v.channels());
        {
          py::gil_scoped_release release;
          sample_volume(v, p, wrap, out.data(), ctx, interp);
        }
        return take_vector(std::move(out), {py::ssize_t(p.size()), py::ssize_t(v.channels())});
      },
      py::arg("volume"), py::arg("origin"), py::arg("voxel_size"), py::arg("points"), py::kw_only(),
      py::arg("wrap") = true, py::arg("interpolation") = default_interp, py::arg("ctx") = py::none(),
      "Samples of a (Z,Y,X) or (Z,Y,X,C) volume at N by 3 points (the volume's space)\n"
      "-> (N, C) float32. wrap=True repeats the volume (a tiling solid). interpolation: 'cubic'\n"
      "(tricubic Catmull-Rom limited to the 8 surrounding voxels' range: crisper) or 'linear' (trilinear).");

  m.def(
      "bake_volume_to_uv",
      [](const ArrayArg& volume, const Vec3Arg& origin, const RealArg& voxel_size, const ArrayArg& positions,
         const ArrayArg& uvs, const IntArg& width_arg, const IntArg& height_arg, const BoolArg& wrap,
         const IntArg& margin, const StrArg& interp_arg, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "wrap, margin, interpolation, ctx");
        const int width = int_arg(width_arg, "width", 1, kMaxBakeSize, "texels");
        const int height = int_arg(height_arg, "height", 1, kMaxBakeSize, "texels");
        const Volume v = to_volume(volume, "volume", to_transform(origin, voxel_size));
        const auto pos = to_corners<3>(positions, "positions", "an (F, 3, 3) float array: each triangle's corner positions");
        const auto uv = to_corners<2>(uvs, "uvs", "an (F, 3, 2) float array: each triangle's corner UVs");
        BakeOptions opt;
        opt.width = width;
        opt.height = height;
        opt.wrap = bool_arg(wrap, "wrap");
        opt.margin = int_arg(margin, "margin", 0, kMaxBakeMargin, "texels");
        opt.interpolation = interpolation_arg(interp_arg);
        ExecContext* ctx = context_arg(ctx_arg);
        BakeResult r;
        {
          py::gil_scoped_release release;
          r = bake_volume_to_uv(v, pos, uv, opt, ctx);
        }
        const py::ssize_t h = height, w = width, c = r.image.channels();
        return py::make_tuple(take_vector(std::move(r.image.values()), {h, w, c}), take_vector(std::move(r.mask), {h, w}));
      },
      py::arg("volume"), py::arg("origin"), py::arg("voxel_size"), py::arg("positions"), py::arg("uvs"),
      py::arg("width"), py::arg("height"), py::kw_only(), py::arg("wrap") = true, py::arg("margin") = 4,
      py::arg("interpolation") = default_interp, py::arg("ctx") = py::none(),
      "Bake a volume into a UV-mapped image: positions (F,3,3) corner positions in the volume's space,\n"
      "uvs (F,3,2) corner UVs. Returns (image (H,W,C) float32 with row 0 at v = 0, mask (H,W) uint8:\n"
      "1 covered, 2 margin, 0 empty). interpolation: 'cubic' (default) or 'linear', as sample_volume.");
}

}  // namespace exsynth::py_bind
