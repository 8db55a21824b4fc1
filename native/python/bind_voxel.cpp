// exsynth._native.voxelize
#include <pybind11/pybind11.h>

#include "arrays.hpp"
#include "exsynth/voxelize.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_voxel(py::module_& m) {
  m.def(
      "voxelize",
      [](const py::array& vertices, const py::array& faces, int resolution, double voxel_size, int padding,
         int supersample, bool compute_sdf, std::size_t memory_budget, std::uint64_t seed, ExecContext* ctx) {
        TriangleMesh mesh = to_mesh(vertices, faces);
        VoxelizeOptions opt;
        opt.resolution = resolution;
        opt.voxel_size = voxel_size;
        opt.padding = padding;
        opt.supersample = supersample;
        opt.compute_sdf = compute_sdf;
        opt.memory_budget = memory_budget ? memory_budget : kDefaultMemoryBudget;
        opt.seed = seed;
        VoxelizeResult r;
        {
          py::gil_scoped_release release;
          r = voxelize(mesh, opt, ctx);
        }
        const GridTransform t = r.density.transform();
        py::dict out;
        out["origin"] = take_vector(std::vector<double>(t.origin.begin(), t.origin.end()), {3});
        out["voxel_size"] = t.voxel_size;
        out["density"] = from_volume(std::move(r.density));
        out["sdf"] = r.sdf.empty() ? py::object(py::none()) : py::object(from_volume(std::move(r.sdf)));
        return out;
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("resolution") = 128, py::arg("voxel_size") = 0.0,
      py::arg("padding") = 2, py::arg("supersample") = 2, py::arg("compute_sdf") = true,
      py::arg("memory_budget") = std::size_t(0), py::arg("seed") = std::uint64_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      R"doc(Voxelize a triangle mesh into density and signed distance.

vertices: V by 3 float32/float64; faces: F by 3 int32/int64 (indices into vertices).
resolution: voxels along the longest bounding-box axis (used when voxel_size == 0).
Returns a dict: density (Z, Y, X) float32 in [0, 1]; sdf (Z, Y, X) float32, mesh units,
positive outside (None if compute_sdf=False); origin (3,) float64, the centre of voxel
[0, 0, 0]; voxel_size. Inside/outside is a 2-of-3 parity vote along the axes, so open
meshes still give a solid. Releases the GIL; reports to ctx; raises CancelledError.)doc");
}

}  // namespace exsynth::py_bind
