// exsynth._native.volume_frames
#include <pybind11/pybind11.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/frames.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_frames(py::module_& m) {
  m.def(
      "volume_frames",
      [](const ArrayArg& sdf_arg, const Vec3Arg& origin, const RealArg& voxel_size,
         const ArrayArg& points_arg, const ArrayArg& vectors_arg, const RealArg& band,
         const IntArg& smoothing_steps, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "band, smoothing_steps, ctx");
        const py::array sdf = array_arg(sdf_arg, "sdf", "a (Z, Y, X) float32 signed distance volume");
        check_shape(sdf, "sdf", {-1, -1, -1}, "a (Z, Y, X) float32 signed distance volume");
        const Volume v = to_volume(sdf, "sdf", to_transform(origin, voxel_size));
        const py::array points = array_arg(points_arg, "points", "an N by 3 float array of field positions");
        const py::array vectors = array_arg(vectors_arg, "vectors", "an N by 3 float array of field directions");
        check_shape(points, "points", {-1, 3}, "an N by 3 float array of field positions");
        check_shape(vectors, "vectors", {-1, 3}, "an N by 3 float array of field directions");
        auto as_vectors = [](const py::array& a) {
          auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
          std::vector<Eigen::Vector3f> out(std::size_t(a.shape(0)));
          for (std::size_t i = 0; i < out.size(); ++i) out[i] = Eigen::Vector3f(f.at(i, 0), f.at(i, 1), f.at(i, 2));
          return out;
        };
        const auto p = as_vectors(points), d = as_vectors(vectors);
        FrameOptions opt;
        opt.band = real_arg(band, "band", 0.0, kInf, Ends::OpenLow, "voxels");
        opt.smoothing_steps = int_arg(smoothing_steps, "smoothing_steps", 0, kMaxSmoothingSteps);
        ExecContext* ctx = context_arg(ctx_arg);
        VolumeFrames fr;
        {
          py::gil_scoped_release release;
          fr = volume_frames(v, p, d, opt, ctx);
        }
        py::dict out;
        out["t"] = from_volume(std::move(fr.t));
        out["n"] = from_volume(std::move(fr.n));
        out["b"] = from_volume(std::move(fr.b));
        return out;
      },
      py::arg("sdf"), py::arg("origin"), py::arg("voxel_size"), py::arg("points"), py::arg("vectors"), py::kw_only(),
      py::arg("band") = 1.5, py::arg("smoothing_steps") = 4, py::arg("ctx") = py::none(),
      "Local frames in a volume: N = normalised sdf gradient, T = the field (given at N by 3 points) of\n"
      "the nearest surface voxel, projected perpendicular to N, B = T x N. Returns {'t', 'n', 'b'},\n"
      "each (Z, Y, X, 3) float32.");
}

}  // namespace exsynth::py_bind
