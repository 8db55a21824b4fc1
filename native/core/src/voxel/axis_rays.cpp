#include "voxel/axis_rays.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

#include "exsynth/errors.hpp"
#include "voxel/embree_api.hpp"

namespace exsynth::voxel {
namespace {

// Embree hands the filter our context; the collector rides behind it.
struct CollectContext {
  RayContext base;
  const std::vector<std::array<float, 3>>* normals;
  int axis;
  std::vector<Crossing>* out;
};

// Records every hit and rejects it, so traversal continues to the next one.
void collect_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const CollectContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const float n = (*ctx->normals)[prim][ctx->axis];
    if (n != 0.0f) ctx->out->push_back({RTCRayN_tfar(args->ray, args->N, i), std::int8_t(n > 0 ? 1 : -1)});
    args->valid[i] = 0;
  }
}

}  // namespace

AxisRayCaster::AxisRayCaster(const TriangleMesh& mesh) {
  device_ = embree().NewDevice("verbose=0");
  if (!device_) throw Error("Embree could not create a device (error " + std::to_string(embree().GetDeviceError(nullptr)) + ")");
  scene_ = embree().NewScene(device_);
  // Robust mode makes the ray-triangle test watertight: a ray through a
  // shared edge hits at least one of the two triangles, never neither.
  embree().SetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  embree().SetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);

  RTCGeometry geom = embree().NewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(embree().SetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), mesh.vertices.size()));
  auto* ib = static_cast<unsigned*>(embree().SetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), mesh.faces.size()));
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = mesh.vertices[i][k];
    lo = lo.cwiseMin(mesh.vertices[i]);
    hi = hi.cwiseMax(mesh.vertices[i]);
  }
  normals_.resize(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    for (int k = 0; k < 3; ++k) ib[3 * f + k] = unsigned(t[k]);
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    normals_[f] = {n.x(), n.y(), n.z()};
  }
  embree().SetGeometryIntersectFilterFunction(geom, collect_filter);
  embree().CommitGeometry(geom);
  embree().AttachGeometry(scene_, geom);
  embree().ReleaseGeometry(geom);
  embree().CommitScene(scene_);

  const float extent = (hi - lo).maxCoeff();
  for (int k = 0; k < 3; ++k) start_[k] = lo[k] - 1.0f - 0.01f * extent;
  // Crossings closer than this are one crossing seen twice (shared edge).
  merge_eps_ = 1e-5f * std::max(1.0f, extent);
}

AxisRayCaster::~AxisRayCaster() {
  if (scene_) embree().ReleaseScene(scene_);
  if (device_) embree().ReleaseDevice(device_);
}

void AxisRayCaster::crossings(int axis, float u, float v, std::vector<Crossing>& out) const {
  out.clear();
  CollectContext ctx;
  init_context(ctx.base);
  ctx.normals = &normals_;
  ctx.axis = axis;
  ctx.out = &out;

  float org[3], dir[3] = {0, 0, 0};
  org[axis] = start_[axis];
  org[(axis + 1) % 3] = u;
  org[(axis + 2) % 3] = v;
  dir[axis] = 1.0f;

  RTCRayHit rh;
  rh.ray.org_x = org[0];
  rh.ray.org_y = org[1];
  rh.ray.org_z = org[2];
  rh.ray.dir_x = dir[0];
  rh.ray.dir_y = dir[1];
  rh.ray.dir_z = dir[2];
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  intersect1(scene_, ctx.base, rh);

  std::sort(out.begin(), out.end());
  // Merge same-facing crossings at (nearly) the same position.
  std::size_t w = 0;
  for (std::size_t r = 0; r < out.size(); ++r) {
    bool dup = false;
    for (std::size_t q = w; q-- > 0;) {
      if (out[r].t - out[q].t > merge_eps_) break;
      if (out[q].facing == out[r].facing) {
        dup = true;
        break;
      }
    }
    if (!dup) out[w++] = out[r];
  }
  out.resize(w);
  for (auto& c : out) c.t += start_[axis];  // absolute coordinate along the axis
}

}  // namespace exsynth::voxel
