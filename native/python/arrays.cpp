#include "arrays.hpp"

#include <cmath>
#include <sstream>

#include "arguments.hpp"
#include "exsynth/errors.hpp"

namespace exsynth::py_bind {

std::string describe(const py::array& a) {
  std::ostringstream s;
  s << py::str(a.dtype()).cast<std::string>() << " array of shape (";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

void check_shape(const py::array& a, const char* name, std::initializer_list<py::ssize_t> shape,
                 const char* expected) {
  bool ok = a.ndim() == py::ssize_t(shape.size());
  py::ssize_t i = 0;
  for (auto it = shape.begin(); ok && it != shape.end(); ++it, ++i) ok = *it < 0 || a.shape(i) == *it;
  if (!ok)
    throw InvalidInput(std::string("'") + name + "' must be " + expected + ", got a " + describe(a));
}

namespace {

template <class T>
void copy_vertices(const py::array& a, TriangleMesh& m) {
  auto v = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  auto r = v.template unchecked<2>();
  m.vertices.resize(std::size_t(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i)
    m.vertices[i] = Eigen::Vector3f(float(r(i, 0)), float(r(i, 1)), float(r(i, 2)));
}

template <class T>
void copy_faces(const py::array& a, TriangleMesh& m) {
  auto f = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  auto r = f.template unchecked<2>();
  m.faces.resize(std::size_t(r.shape(0)));
  const T limit = T(std::numeric_limits<int>::max());
  for (py::ssize_t i = 0; i < r.shape(0); ++i) {
    for (int k = 0; k < 3; ++k) {
      // Anything outside int range is out of range for any mesh we accept;
      // map it to -1 so validate_mesh reports it with the face number.
      const T x = r(i, k);
      m.faces[i][k] = (x < 0 || x > limit) ? -1 : int(x);
    }
  }
}

}  // namespace

TriangleMesh to_mesh(const py::handle& vertices_arg, const py::handle& faces_arg) {
  const py::array vertices = array_arg(vertices_arg, "vertices", "a V by 3 float32 or float64 array");
  const py::array faces = array_arg(faces_arg, "faces", "an F by 3 int32 or int64 array of vertex indices");
  check_shape(vertices, "vertices", {-1, 3}, "a V by 3 float32 or float64 array");
  check_shape(faces, "faces", {-1, 3}, "an F by 3 int32 or int64 array of vertex indices");
  TriangleMesh m;
  const auto vk = vertices.dtype();
  if (vk.is(py::dtype::of<float>()))
    copy_vertices<float>(vertices, m);
  else if (vk.is(py::dtype::of<double>()))
    copy_vertices<double>(vertices, m);
  else
    throw InvalidInput("'vertices' must have dtype float32 or float64, got " + describe(vertices));
  const auto fk = faces.dtype();
  if (fk.is(py::dtype::of<std::int32_t>()))
    copy_faces<std::int32_t>(faces, m);
  else if (fk.is(py::dtype::of<std::int64_t>()))
    copy_faces<std::int64_t>(faces, m);
  else
    throw InvalidInput("'faces' must have dtype int32 or int64, got " + describe(faces) +
                       " (convert with faces.astype(numpy.int32))");
  return m;
}

Volume to_volume(const py::handle& arg, const char* name, const GridTransform& xform) {
  const py::array a = array_arg(arg, name, "a (Z, Y, X) or (Z, Y, X, C) float32 array");
  if (a.ndim() != 3 && a.ndim() != 4)
    throw InvalidInput(std::string("'") + name + "' must be a (Z, Y, X) or (Z, Y, X, C) float32 array, got a " +
                       describe(a));
  if (!a.dtype().is(py::dtype::of<float>()) && !a.dtype().is(py::dtype::of<double>()))
    throw InvalidInput(std::string("'") + name + "' must have dtype float32 or float64, got " + describe(a));
  for (py::ssize_t i = 0; i < a.ndim(); ++i)
    if (a.shape(i) < 1)
      throw InvalidInput(std::string("'") + name + "' is empty (" + describe(a) + "); every axis needs at least 1 voxel");
  const int channels = a.ndim() == 4 ? int(a.shape(3)) : 1;
  Volume v(int(a.shape(2)), int(a.shape(1)), int(a.shape(0)), channels, 0.0f, xform);
  auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  const float* src = f.data();
  for (std::size_t i = 0; i < v.values().size(); ++i) {
    if (!std::isfinite(src[i]))
      throw InvalidInput(std::string("'") + name + "' contains a non-finite value (NaN or Inf) at flat index " +
                         std::to_string(i) + "; replace it with numpy.nan_to_num");
    v.values()[i] = src[i];
  }
  return v;
}

Eigen::Vector3d to_point(const py::handle& h, const char* name, const char* meaning) {
  auto o = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!o || o.ndim() != 1 || o.shape(0) != 3)
    throw InvalidInput(std::string("'") + name + "' must be 3 numbers (" + meaning + ")");
  const Eigen::Vector3d p(o.at(0), o.at(1), o.at(2));
  if (!p.allFinite()) throw InvalidInput(std::string("'") + name + "' must be finite");
  return p;
}

GridTransform to_transform(const py::handle& origin, double voxel_size) {
  const Eigen::Vector3d o = to_point(origin, "origin", "the world position of voxel (0, 0, 0)'s centre");
  GridTransform t;
  for (int k = 0; k < 3; ++k) t.origin[k] = o[k];
  if (!std::isfinite(voxel_size) || voxel_size <= 0)
    throw InvalidInput("'voxel_size' must be a finite number > 0, got " + std::to_string(voxel_size));
  t.voxel_size = voxel_size;
  return t;
}

GridTransform to_transform(const py::handle& origin, const py::handle& voxel_size) {
  return to_transform(origin, real_arg(voxel_size, "voxel_size", 0.0, kInf, Ends::OpenLow));
}

py::array from_volume(Volume&& v) {
  std::vector<py::ssize_t> shape = {v.nz(), v.ny(), v.nx()};
  if (v.channels() != 1) shape.push_back(v.channels());
  return take_vector(std::move(v.values()), shape);
}

// (H, W) or (H, W, C) uint8 / uint16 / float32 / float64 -> Image in [0, 1]
// for integer types (8- and 16-bit exemplars), unchanged for floats.
Image to_image(const py::handle& arg, const std::string& name) {
  const py::array a = array_arg(arg, name, "an (H, W) or (H, W, C) image array");
  if (a.ndim() != 2 && a.ndim() != 3)
    throw InvalidInput("'" + name + "' must be an (H, W) or (H, W, C) image array, got a " + describe(a));
  const int h = int(a.shape(0)), w = int(a.shape(1)), c = a.ndim() == 3 ? int(a.shape(2)) : 1;
  if (h < 1 || w < 1 || c < 1) throw InvalidInput("'" + name + "' is empty (" + describe(a) + ")");
  Image img(w, h, c);
  float* out = img.data();
  const std::size_t count = img.values().size();
  auto copy = [&](auto tag, float scale) {
    using T = decltype(tag);
    auto arr = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
    const T* src = arr.data();
    for (std::size_t i = 0; i < count; ++i) out[i] = float(src[i]) * scale;
  };
  const auto dt = a.dtype();
  if (dt.is(py::dtype::of<std::uint8_t>())) copy(std::uint8_t{}, 1.0f / 255.0f);
  else if (dt.is(py::dtype::of<std::uint16_t>())) copy(std::uint16_t{}, 1.0f / 65535.0f);
  else if (dt.is(py::dtype::of<float>())) copy(float{}, 1.0f);
  else if (dt.is(py::dtype::of<double>())) copy(double{}, 1.0f);
  else
    throw InvalidInput("'" + name + "' must have dtype uint8, uint16, float32 or float64, got " + describe(a));
  return img;
}

}  // namespace exsynth::py_bind
