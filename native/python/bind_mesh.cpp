// exsynth._native.validate_mesh: the core's mesh checks, for callers that
// must refuse a mesh before a job starts (the analogy's B, A and A').
#include <pybind11/pybind11.h>

#include <string>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/mesh.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_mesh(py::module_& m) {
  m.def(
      "validate_mesh",
      [](const ArrayArg& vertices, const ArrayArg& faces, const StrArg& name_arg, const py::kwargs& extra) {
        reject_unknown(extra, "vertices, faces, name");
        const std::string name = string_arg(name_arg, "name", "how messages refer to the mesh");
        validate_mesh(to_mesh(vertices, faces), name.c_str());
      },
      py::arg("vertices"), py::arg("faces"), py::arg("name") = "mesh",
      R"doc(Raise InvalidInputError unless the mesh can be used by the engine.

vertices: V by 3 float32/float64; faces: F by 3 int32/int64. Checks: at least one
vertex and one face, finite coordinates, face indices in range. `name` is how the
message refers to the mesh (e.g. "--b" or "'Bunny'").)doc");
}

}  // namespace exsynth::py_bind
