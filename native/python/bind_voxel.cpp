// exsynth._native.voxelize
#include <pybind11/pybind11.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/thickness.hpp"
#include "exsynth/voxelize.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_voxel(py::module_& m) {
  m.attr("EMBREE_LIBRARY") = embree_library();  // what ./exsynth package must bundle
  m.def(
      "voxelize",
      [](const ArrayArg& vertices, const ArrayArg& faces, const IntArg& resolution,
         const RealArg& voxel_size, const IntArg& padding, const IntArg& supersample,
         const BoolArg& compute_sdf, const IntArg& memory_budget, const IntArg& seed,
         const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "resolution, voxel_size, padding, supersample, compute_sdf, memory_budget, seed, ctx");
        TriangleMesh mesh = to_mesh(vertices, faces);
        VoxelizeOptions opt;
        opt.resolution = int_arg(resolution, "resolution", 1, kMaxVoxelResolution, "voxels along the longest axis");
        opt.voxel_size = real_arg(voxel_size, "voxel_size", 0.0, kInf, Ends::Closed, "mesh units; 0 = use resolution");
        opt.padding = int_arg(padding, "padding", 0, kMaxVoxelPadding, "voxels");
        opt.supersample = int_arg(supersample, "supersample", 1, kMaxSupersample, "sub-rays per voxel edge");
        opt.compute_sdf = bool_arg(compute_sdf, "compute_sdf");
        opt.memory_budget = memory_budget_arg(memory_budget);
        opt.seed = seed_arg(seed);
        ExecContext* ctx = context_arg(ctx_arg);
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
      py::arg("memory_budget") = 0, py::arg("seed") = 0, py::arg("ctx") = py::none(),
      R"doc(Voxelize a triangle mesh into density and signed distance.

vertices: V by 3 float32/float64; faces: F by 3 int32/int64 (indices into vertices).
resolution: voxels along the longest bounding-box axis (used when voxel_size == 0).
Returns a dict: density (Z, Y, X) float32 in [0, 1]; sdf (Z, Y, X) float32, mesh units,
positive outside (None if compute_sdf=False); origin (3,) float64, the centre of voxel
[0, 0, 0]; voxel_size. Inside/outside is a 2-of-3 parity vote along the axes, so open
meshes still give a solid. Releases the GIL; reports to ctx; raises CancelledError.)doc");

  m.def(
      "voxel_grid",
      [](const Vec3Arg& lo, const Vec3Arg& hi, const IntArg& resolution, const RealArg& voxel_size,
         const IntArg& padding, const py::kwargs& extra) {
        reject_unknown(extra, "resolution, voxel_size, padding");
        VoxelizeOptions opt;
        opt.resolution = int_arg(resolution, "resolution", 1, kMaxVoxelResolution, "voxels along the longest axis");
        opt.voxel_size = real_arg(voxel_size, "voxel_size", 0.0, kInf, Ends::Closed, "mesh units; 0 = use resolution");
        opt.padding = int_arg(padding, "padding", 0, kMaxVoxelPadding, "voxels");
        const VoxelGridSpec g = voxel_grid_spec(to_point(lo, "lo", "the bounding box's low corner"),
                                                to_point(hi, "hi", "the bounding box's high corner"), opt);
        py::dict out;
        out["shape"] = py::make_tuple(g.nz, g.ny, g.nx);
        out["origin"] = py::make_tuple(g.transform.origin[0], g.transform.origin[1], g.transform.origin[2]);
        out["voxel_size"] = g.transform.voxel_size;
        return out;
      },
      py::arg("lo"), py::arg("hi"), py::kw_only(), py::arg("resolution") = 128, py::arg("voxel_size") = 0.0,
      py::arg("padding") = 2,
      R"doc(The grid voxelize would make for a mesh whose bounding box is [lo, hi], without voxelizing.

Returns {'shape': (Z, Y, X), 'origin': (x, y, z) of voxel [0, 0, 0]'s centre, 'voxel_size'}:
the voxel is the longest side / resolution unless voxel_size > 0; padding empty voxels on
every side. For estimates and for voxelizing several meshes at one voxel size.)doc");

  m.def(
      "model_thickness",
      [](const ArrayArg& vertices, const ArrayArg& faces, const IntArg& resolution, const RealArg& percentile,
         const RealArg& pattern_per_thickness, const IntArg& memory_budget, const IntArg& seed,
         const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "resolution, percentile, pattern_per_thickness, memory_budget, seed, ctx");
        TriangleMesh mesh = to_mesh(vertices, faces);
        ThicknessOptions opt;
        opt.resolution = int_arg(resolution, "resolution", kMinThicknessResolution, kMaxThicknessResolution,
                                 "voxels along the longest axis");
        opt.percentile = real_arg(percentile, "percentile", 0.0, 100.0, Ends::Closed, "of the surface samples");
        opt.pattern_per_thickness = real_arg(pattern_per_thickness, "pattern_per_thickness", 0.0, 100.0,
                                             Ends::OpenLow, "pattern size / thickness");
        opt.memory_budget = memory_budget_arg(memory_budget);
        opt.seed = seed_arg(seed);
        ExecContext* ctx = context_arg(ctx_arg);
        ThicknessResult r;
        {
          py::gil_scoped_release release;
          r = model_thickness(mesh, opt, ctx);
        }
        py::dict out;
        out["thickness"] = r.thickness;
        out["median"] = r.median;
        out["low"] = r.low;
        out["high"] = r.high;
        out["pattern_size"] = r.pattern_size;
        out["voxel_size"] = r.voxel_size;
        out["samples"] = r.samples;
        return out;
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("resolution") = ThicknessOptions{}.resolution,
      py::arg("percentile") = ThicknessOptions{}.percentile,
      py::arg("pattern_per_thickness") = ThicknessOptions{}.pattern_per_thickness, py::arg("memory_budget") = 0,
      py::arg("seed") = 0,
      py::arg("ctx") = py::none(),
      R"doc(How thick a closed mesh is where its surface is.

vertices: V by 3 float32/float64; faces: F by 3 int32/int64. For each surface sample (the
voxels just inside the surface at `resolution` voxels along the longest side), the diameter
of the largest ball inside the mesh that touches the surface there; thickness is the
`percentile` (0..100, default the median) of those over the surface, so thin parts count by
their area. Returns a dict: thickness, median, low (10th), high (90th percentile), all in mesh
units; pattern_size (thickness * pattern_per_thickness, default 2: Geometric Texture's default
pattern size); voxel_size; samples. Releases the GIL; reports to ctx; raises CancelledError.)doc");
}

}  // namespace exsynth::py_bind
