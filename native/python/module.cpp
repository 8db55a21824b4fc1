// exsynth._native: bindings only. Each area registers itself; see
// docs/python_api.md for the Python-side contract.
#include <pybind11/pybind11.h>

namespace py = pybind11;

namespace exsynth::py_bind {
void bind_core(py::module_& m);
void bind_voxel(py::module_& m);
void bind_grid(py::module_& m);
void bind_solid(py::module_& m);
void bind_bake(py::module_& m);
void bind_field(py::module_& m);
void bind_pairs(py::module_& m);
void bind_analogy(py::module_& m);
void bind_frames(py::module_& m);
void bind_mesh(py::module_& m);
void bind_points(py::module_& m);
void bind_surface(py::module_& m);
}  // namespace exsynth::py_bind

PYBIND11_MODULE(_native, m) {
  m.doc() = "exsynth engine (C++): voxelization, volumes, isosurfaces, solid and 2D texture synthesis. Arrays are NumPy, C order.";
  exsynth::py_bind::bind_core(m);
  exsynth::py_bind::bind_voxel(m);
  exsynth::py_bind::bind_grid(m);
  exsynth::py_bind::bind_solid(m);
  exsynth::py_bind::bind_bake(m);
  exsynth::py_bind::bind_field(m);
  exsynth::py_bind::bind_pairs(m);
  exsynth::py_bind::bind_analogy(m);
  exsynth::py_bind::bind_frames(m);
  exsynth::py_bind::bind_mesh(m);
  exsynth::py_bind::bind_points(m);
  exsynth::py_bind::bind_surface(m);
}
