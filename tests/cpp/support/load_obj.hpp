#pragma once
// Minimal OBJ reader for tests and benchmarks only (v / f lines, polygons
// fanned into triangles). The product reads meshes through Blender.
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "exsynth/mesh.hpp"

namespace exsynth::testing {

inline TriangleMesh load_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  TriangleMesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      float x, y, z;
      s >> x >> y >> z;
      m.vertices.emplace_back(x, y, z);
    } else if (tag == "f") {
      std::vector<int> idx;
      std::string tok;
      while (s >> tok) idx.push_back(std::stoi(tok.substr(0, tok.find('/'))) - 1);
      for (std::size_t k = 1; k + 1 < idx.size(); ++k) m.faces.emplace_back(idx[0], idx[k], idx[k + 1]);
    }
  }
  return m;
}

inline std::string asset(const std::string& rel) { return std::string(EXSYNTH_ASSETS_DIR) + "/" + rel; }

}  // namespace exsynth::testing
