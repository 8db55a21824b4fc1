// Volume files, isosurfaces and pyramids.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/isosurface.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/vdb_io.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_grid(py::module_& m) {
  m.def(
      "write_vdb",
      [](const PathArg& path_arg_, const GridsArg& grids_arg, const Vec3Arg& origin,
         const RealArg& voxel_size, const py::kwargs& extra) {
        reject_unknown(extra, "path, grids, origin, voxel_size");
        const std::string path = path_arg(path_arg_, "path");
        const py::dict grids = dict_arg(grids_arg, "grids", "a dict of grid name -> (Z, Y, X) or (Z, Y, X, C) float32 array");
        const GridTransform t = to_transform(origin, voxel_size);
        if (grids.empty()) throw InvalidInput("'grids' is empty; pass at least one name -> array");
        std::map<std::string, Volume> volumes;
        for (auto item : grids) {
          const std::string name = py::str(item.first);
          if (!PyUnicode_Check(item.first.ptr()))
            throw InvalidInput("the keys of 'grids' must be grid names (str), got " + short_repr(item.first));
          volumes.emplace(name, to_volume(item.second, name.c_str(), t));
        }
        py::gil_scoped_release release;
        write_vdb(path, volumes);
      },
      py::arg("path"), py::arg("grids"), py::arg("origin"), py::arg("voxel_size"),
      "Write named grids (dict name -> (Z,Y,X) or (Z,Y,X,C) float32) to a .vdb file.\n"
      "origin: world position of voxel [0,0,0]'s centre. 'sdf' is stored as a level set.");

  m.def(
      "read_vdb",
      [](const PathArg& path_arg_, const NamesArg& names_arg, const py::kwargs& extra) {
        reject_unknown(extra, "path, names");
        const std::string path = path_arg(path_arg_, "path");
        const std::vector<std::string> names = names_arg.is_none() ? std::vector<std::string>{}
                                                                   : string_list_arg(names_arg, "names");
        std::map<std::string, Volume> volumes;
        {
          py::gil_scoped_release release;
          volumes = read_vdb(path, names);
        }
        py::dict grids;
        GridTransform t;
        for (auto& [name, v] : volumes) {
          t = v.transform();
          grids[py::str(name)] = from_volume(std::move(v));
        }
        py::dict out;
        out["grids"] = grids;
        out["origin"] = take_vector(std::vector<double>(t.origin.begin(), t.origin.end()), {3});
        out["voxel_size"] = t.voxel_size;
        return out;
      },
      py::arg("path"), py::arg("names") = py::none(),
      "Read float/vec3 grids (all, or `names`) from a .vdb into dense arrays over the union\n"
      "of their active voxels. Returns {'grids': {name: array}, 'origin', 'voxel_size'}.");

  m.def(
      "isosurface",
      [](const ArrayArg& volume_arg, const Vec3Arg& origin, const RealArg& voxel_size,
         const RealArg& isovalue, const RealArg& adaptivity, const BoolArg& invert, const ContextArg& ctx_arg,
         const py::kwargs& extra) {
        reject_unknown(extra, "isovalue, adaptivity, invert, ctx");
        const py::array volume = array_arg(volume_arg, "volume", "a (Z, Y, X) float32 array");
        check_shape(volume, "volume", {-1, -1, -1}, "a (Z, Y, X) float32 array");
        const Volume v = to_volume(volume, "volume", to_transform(origin, voxel_size));
        IsosurfaceOptions opt;
        opt.isovalue = real_arg(isovalue, "isovalue");
        opt.adaptivity = real_arg(adaptivity, "adaptivity", 0.0, 1.0);
        opt.invert = bool_arg(invert, "invert");
        ExecContext* ctx = context_arg(ctx_arg);
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = isosurface(v, opt, ctx);
        }
        std::vector<float> verts(mesh.vertices.size() * 3);
        for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
          for (int k = 0; k < 3; ++k) verts[3 * i + k] = mesh.vertices[i][k];
        std::vector<std::int32_t> tris(mesh.faces.size() * 3);
        for (std::size_t i = 0; i < mesh.faces.size(); ++i)
          for (int k = 0; k < 3; ++k) tris[3 * i + k] = mesh.faces[i][k];
        const auto nv = py::ssize_t(mesh.vertices.size()), nf = py::ssize_t(mesh.faces.size());
        return py::make_tuple(take_vector(std::move(verts), {nv, 3}), take_vector(std::move(tris), {nf, 3}));
      },
      py::arg("volume"), py::arg("origin"), py::arg("voxel_size"), py::kw_only(), py::arg("isovalue") = 0.0,
      py::arg("adaptivity") = 0.0, py::arg("invert") = false, py::arg("ctx") = py::none(),
      "OpenVDB volume -> mesh. Returns (verts (V,3) float32 world positions, tris (F,3) int32),\n"
      "counter-clockwise seen from outside; outside = values above isovalue (an SDF), or below\n"
      "with invert=True (a density).");

  m.def(
      "gaussian_pyramid",
      [](const ArrayArg& volume, const IntArg& levels, const BoolArg& wrap, const ContextArg& ctx_arg,
         const py::kwargs& extra) {
        reject_unknown(extra, "levels, wrap, ctx");
        const Volume v = to_volume(volume, "volume", GridTransform{});
        PyramidOptions opt;
        opt.levels = int_arg(levels, "levels", 1, kMaxPyramidLevels);
        opt.boundary = bool_arg(wrap, "wrap") ? Boundary::Wrap : Boundary::Clamp;
        ExecContext* ctx = context_arg(ctx_arg);
        std::vector<Volume> pyr;
        {
          py::gil_scoped_release release;
          pyr = gaussian_pyramid(v, opt, ctx);
        }
        py::list out;
        for (auto& level : pyr) out.append(from_volume(std::move(level)));
        return out;
      },
      py::arg("volume"), py::kw_only(), py::arg("levels") = 3, py::arg("wrap") = false,
      py::arg("ctx") = py::none(),
      "Gaussian pyramid of a (Z,Y,X) or (Z,Y,X,C) volume: list of levels, finest first.");
}

}  // namespace exsynth::py_bind
