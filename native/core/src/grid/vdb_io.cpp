#include "exsynth/vdb_io.hpp"
#include "exsynth/format.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "exsynth/errors.hpp"

namespace exsynth {
namespace {

// Our volumes are x-fastest ((z*ny + y)*nx + x), which OpenVDB calls LayoutXYZ.
template <class T>
using DenseXYZ = openvdb::tools::Dense<T, openvdb::tools::LayoutXYZ>;

void ensure_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::CoordBBox index_box(const Volume& v) {
  return openvdb::CoordBBox(openvdb::Coord(0, 0, 0),
                            openvdb::Coord(v.nx() - 1, v.ny() - 1, v.nz() - 1));
}

openvdb::math::Transform::Ptr make_transform(const GridTransform& t) {
  // OpenVDB index coordinates are voxel centres, as ours are, so index 0
  // simply maps to the origin.
  openvdb::math::Transform::Ptr xf;
  try {
    xf = openvdb::math::Transform::createLinearTransform(t.voxel_size);
  } catch (const openvdb::ArithmeticError&) {
    // OpenVDB refuses scales whose cube is near zero (voxels below ~1.4e-5 units).
    throw InvalidInput("the voxel size " + format_number(t.voxel_size) +
                       " is too small for an OpenVDB file (about 1.5e-5 units at least); scale the model up "
                       "(e.g. work in millimetres instead of metres) or use fewer voxels");
  }
  xf->postTranslate(openvdb::Vec3d(t.origin[0], t.origin[1], t.origin[2]));
  return xf;
}

std::vector<float> channel_of(const Volume& v, int c) {
  std::vector<float> out(v.voxel_count());
  const float* d = v.data();
  const std::size_t nc = std::size_t(v.channels());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = d[i * nc + std::size_t(c)];
  return out;
}

openvdb::FloatGrid::Ptr float_grid(const Volume& v, int c, bool level_set) {
  std::vector<float> values = channel_of(v, c);
  float background = 0.0f;
  if (level_set) {
    for (float x : values) background = std::max(background, std::fabs(x));
  }
  auto grid = openvdb::FloatGrid::create(background);
  DenseXYZ<float> dense(index_box(v), values.data());
  // A negative tolerance keeps every voxel of a level set active; zero makes
  // the fog's zero voxels inactive background.
  openvdb::tools::copyFromDense(dense, *grid, level_set ? -1.0f : 0.0f);
  grid->setGridClass(level_set ? openvdb::GRID_LEVEL_SET : openvdb::GRID_FOG_VOLUME);
  return grid;
}

openvdb::Vec3SGrid::Ptr vec3_grid(const Volume& v) {
  std::vector<openvdb::Vec3s> values(v.voxel_count());
  const float* d = v.data();
  for (std::size_t i = 0; i < values.size(); ++i) {
    values[i] = openvdb::Vec3s(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
  }
  auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  DenseXYZ<openvdb::Vec3s> dense(index_box(v), values.data());
  openvdb::tools::copyFromDense(dense, *grid, openvdb::Vec3s(0.0f));
  return grid;
}

std::string join_names(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
  return s;
}

// The grid's transform as ours; rejects what GridTransform cannot express.
GridTransform read_transform(const openvdb::GridBase& grid, const std::string& path) {
  const openvdb::math::Transform& xf = grid.transform();
  const std::string where = "grid '" + grid.getName() + "' of '" + path + "'";
  if (!xf.isLinear()) {
    throw InvalidInput(where + " has a non-linear (frustum) transform; resample it to a linear one");
  }
  const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
  const openvdb::Vec3d vs = xf.voxelSize();
  const double h = vs[0];
  const double tol = 1e-9 * std::max(1.0, std::fabs(h));
  if (!(h > 0) || std::fabs(vs[1] - h) > tol || std::fabs(vs[2] - h) > tol) {
    throw InvalidInput(where + " has non-uniform voxel sizes (" + std::to_string(vs[0]) + ", " +
                       std::to_string(vs[1]) + ", " + std::to_string(vs[2]) +
                       "); resample it to cubic voxels");
  }
  for (int a = 0; a < 3; ++a) {
    openvdb::Vec3d unit(0, 0, 0);
    unit[a] = 1.0;
    const openvdb::Vec3d step = xf.indexToWorld(unit) - o;
    for (int k = 0; k < 3; ++k) {
      const double expect = k == a ? h : 0.0;
      if (std::fabs(step[k] - expect) > tol) {
        throw InvalidInput(where + " is rotated or sheared; only axis-aligned grids are supported");
      }
    }
  }
  GridTransform t;
  t.origin = {o[0], o[1], o[2]};
  t.voxel_size = h;
  return t;
}

bool same_transform(const GridTransform& a, const GridTransform& b) {
  const double tol = 1e-9 * std::max(1.0, std::fabs(a.voxel_size));
  if (std::fabs(a.voxel_size - b.voxel_size) > tol) return false;
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(a.origin[k] - b.origin[k]) > tol) return false;
  }
  return true;
}

}  // namespace

void write_vdb(const std::string& path, const std::map<std::string, Volume>& grids) {
  if (path.empty()) throw InvalidInput("write_vdb: the file path is empty");
  if (grids.empty()) throw InvalidInput("write_vdb: no grids to write to '" + path + "'");
  ensure_openvdb();

  openvdb::GridPtrVec out;
  std::set<std::string> written;
  auto add = [&](openvdb::GridBase::Ptr grid, const std::string& name, const Volume& v) {
    if (!written.insert(name).second) {
      throw InvalidInput("write_vdb: two grids would both be named '" + name +
                         "' (a multi-channel volume 'x' is written as 'x_0', 'x_1', ...); "
                         "rename one of them");
    }
    grid->setName(name);
    grid->setTransform(make_transform(v.transform()));
    out.push_back(grid);
  };
  for (const auto& [name, v] : grids) {
    if (name.empty()) throw InvalidInput("write_vdb: a grid has an empty name");
    if (v.empty() || v.channels() < 1) {
      throw InvalidInput("write_vdb: volume '" + name + "' is empty");
    }
    if (!(v.transform().voxel_size > 0) || !std::isfinite(v.transform().voxel_size)) {
      throw InvalidInput("write_vdb: volume '" + name + "' has a voxel size that is not positive");
    }
    if (v.channels() == 1) {
      add(float_grid(v, 0, name == "sdf"), name, v);
    } else if (v.channels() == 3) {
      add(vec3_grid(v), name, v);
    } else {
      for (int c = 0; c < v.channels(); ++c) {
        add(float_grid(v, c, false), name + "_" + std::to_string(c), v);
      }
    }
  }

  try {
    openvdb::io::File file(path);
    file.write(out);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw IoError("cannot write vdb file '" + path + "': " + e.what() +
                       "; check that the folder exists and is writable");
  }
}

std::map<std::string, Volume> read_vdb(const std::string& path,
                                       const std::vector<std::string>& names) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IoError("vdb file '" + path + "' not found");
  ensure_openvdb();

  std::vector<openvdb::GridBase::Ptr> grids;
  try {
    openvdb::io::File file(path);
    file.open();
    std::vector<std::string> present;
    for (auto it = file.beginName(); it != file.endName(); ++it) present.push_back(*it);
    if (names.empty()) {
      openvdb::GridPtrVecPtr meta = file.readAllGridMetadata();
      for (const auto& g : *meta) {
        if (g->isType<openvdb::FloatGrid>() || g->isType<openvdb::Vec3SGrid>()) {
          grids.push_back(file.readGrid(g->getName()));
        }
      }
      if (grids.empty()) {
        throw InvalidInput("vdb file '" + path + "' has no float or vector grids (grids present: " +
                           join_names(present) + ")");
      }
    } else {
      for (const std::string& name : names) {
        if (!file.hasGrid(name)) {
          throw InvalidInput("vdb file '" + path + "' has no grid named '" + name +
                             "'; grids present: " + join_names(present));
        }
        openvdb::GridBase::Ptr g = file.readGrid(name);
        if (!g->isType<openvdb::FloatGrid>() && !g->isType<openvdb::Vec3SGrid>()) {
          throw InvalidInput("grid '" + name + "' of '" + path + "' has type '" + g->type() +
                             "'; only float and vec3s grids are supported");
        }
        grids.push_back(g);
      }
    }
    file.close();
  } catch (const openvdb::Exception& e) {
    throw IoError("cannot read vdb file '" + path + "': " + e.what());
  }

  const GridTransform xf0 = read_transform(*grids.front(), path);
  openvdb::CoordBBox box;
  for (const auto& g : grids) {
    if (!same_transform(read_transform(*g, path), xf0)) {
      throw InvalidInput("grids '" + grids.front()->getName() + "' and '" + g->getName() + "' of '" +
                         path + "' have different transforms; read them separately");
    }
    box.expand(g->evalActiveVoxelBoundingBox());
  }
  if (box.empty()) {
    throw InvalidInput("the grids read from '" + path + "' have no active voxels");
  }

  const openvdb::Vec3d o = grids.front()->transform().indexToWorld(box.min());
  GridTransform xf = xf0;
  xf.origin = {o[0], o[1], o[2]};
  const openvdb::Coord dim = box.dim();
  std::map<std::string, Volume> result;
  for (const auto& g : grids) {
    if (auto fg = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
      Volume v(dim[0], dim[1], dim[2], 1, 0.0f, xf);
      DenseXYZ<float> dense(box, v.data());
      openvdb::tools::copyToDense(*fg, dense);
      result[g->getName()] = std::move(v);
    } else {
      auto vg = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g);
      DenseXYZ<openvdb::Vec3s> dense(box);
      openvdb::tools::copyToDense(*vg, dense);
      Volume v(dim[0], dim[1], dim[2], 3, 0.0f, xf);
      float* d = v.data();
      const openvdb::Vec3s* s = dense.data();
      for (std::size_t i = 0; i < v.voxel_count(); ++i) {
        for (int k = 0; k < 3; ++k) d[3 * i + k] = s[i][k];
      }
      result[g->getName()] = std::move(v);
    }
  }
  return result;
}

}  // namespace exsynth
