#pragma once
// Array checks and conversions shared by the binding files. Every check
// names the Python argument so the message tells the user what to fix.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "exsynth/grid.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth::py_bind {

namespace py = pybind11;

/// "float64 array of shape (10, 4)" for messages.
std::string describe(const py::array& a);

/// Checks ndim and the fixed extents (-1 = any); throws InvalidInput.
void check_shape(const py::array& a, const char* name, std::initializer_list<py::ssize_t> shape,
                 const char* expected);

/// V by 3 float32/float64 vertices and F by 3 int32/int64 faces -> mesh.
/// Finiteness and index range are checked by the core (validate_mesh).
/// Lists and tuples are converted by NumPy (see array_arg).
TriangleMesh to_mesh(const py::handle& vertices, const py::handle& faces);

/// A (Z, Y, X) or (Z, Y, X, C) float32/float64 array -> Volume (copied).
/// Lists and tuples are converted by NumPy (see array_arg).
Volume to_volume(const py::handle& a, const char* name, const GridTransform& xform);

/// (H, W) or (H, W, C) uint8 / uint16 / float32 / float64 -> Image, in
/// [0, 1] for integer types (8- and 16-bit exemplars), unchanged for floats.
/// Finiteness and channel limits are the core's to check. The message names
/// the argument.
Image to_image(const py::handle& arg, const std::string& name);

/// 3 finite numbers; the message names the argument and says what it means.
Eigen::Vector3d to_point(const py::handle& h, const char* name, const char* meaning);

/// Origin (3 floats) and voxel size -> transform; checks finiteness, size > 0.
GridTransform to_transform(const py::handle& origin, double voxel_size);
/// The same with voxel_size a Python number (checked: finite, > 0).
GridTransform to_transform(const py::handle& origin, const py::handle& voxel_size);

/// Volume -> (Z, Y, X) array when it has one channel, else (Z, Y, X, C);
/// the buffer is moved, not copied.
py::array from_volume(Volume&& v);

/// std::vector -> 1-D or 2-D array without copying.
template <class T>
py::array_t<T> take_vector(std::vector<T>&& data, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(data));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owner->data(), free_when_done);
}

}  // namespace exsynth::py_bind
