#include "voxel/narrow_band.hpp"

#include <algorithm>
#include <cmath>

#include "exsynth/parallel.hpp"
#include "voxel/distance_transform.hpp"
#include "voxel/triangle_distance.hpp"

namespace exsynth::voxel {
namespace {

constexpr int kSlab = 4;  // z-slab thickness: slabs are processed in parallel and never share voxels

struct Box {
  int lo[3], hi[3];  // inclusive voxel range
};

Box dilated_box(const TriangleMesh& mesh, const Eigen::Vector3i& t, const int n[3]) {
  Box b;
  for (int k = 0; k < 3; ++k) {
    const float lo = std::min({mesh.vertices[t[0]][k], mesh.vertices[t[1]][k], mesh.vertices[t[2]][k]});
    const float hi = std::max({mesh.vertices[t[0]][k], mesh.vertices[t[1]][k], mesh.vertices[t[2]][k]});
    b.lo[k] = std::max(0, int(std::floor(lo)) - 1);
    b.hi[k] = std::min(n[k] - 1, int(std::ceil(hi)) + 1);
  }
  return b;
}

}  // namespace

void narrow_band(const TriangleMesh& mesh, int nx, int ny, int nz, std::vector<float>& dist2,
                 std::vector<std::int32_t>& label, StageProgress& progress) {
  const int n[3] = {nx, ny, nz};
  const std::size_t voxels = std::size_t(nx) * ny * nz;
  dist2.assign(voxels, kFarAway);
  label.assign(voxels, -1);

  // Bin triangles (in ascending id order) by the z-slabs their boxes touch.
  const int slabs = (nz + kSlab - 1) / kSlab;
  std::vector<std::vector<std::int32_t>> bins(slabs);
  std::vector<Box> boxes(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    boxes[f] = dilated_box(mesh, mesh.faces[f], n);
    for (int s = boxes[f].lo[2] / kSlab; s <= boxes[f].hi[2] / kSlab; ++s) bins[s].push_back(std::int32_t(f));
  }

  parallel_chunks(std::size_t(slabs), 1, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const int z0 = int(s) * kSlab, z1 = std::min(nz - 1, z0 + kSlab - 1);
      for (std::int32_t f : bins[s]) {
        const Box& b = boxes[f];
        const auto& t = mesh.faces[f];
        const Eigen::Vector3f &A = mesh.vertices[t[0]], &B = mesh.vertices[t[1]], &C = mesh.vertices[t[2]];
        for (int z = std::max(z0, b.lo[2]); z <= std::min(z1, b.hi[2]); ++z)
          for (int y = b.lo[1]; y <= b.hi[1]; ++y)
            for (int x = b.lo[0]; x <= b.hi[0]; ++x) {
              const float d2 = point_triangle_distance2(Eigen::Vector3f(float(x), float(y), float(z)), A, B, C);
              if (d2 > 1.0f) continue;  // outside the band: not guaranteed exact
              const std::size_t v = (std::size_t(z) * ny + y) * nx + x;
              if (d2 < dist2[v]) {  // strict: equal distance keeps the lower id
                dist2[v] = d2;
                label[v] = f;
              }
            }
      }
    }
  });
}

}  // namespace exsynth::voxel
