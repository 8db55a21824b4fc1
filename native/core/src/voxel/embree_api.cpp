#include "voxel/embree_api.hpp"

#include <dlfcn.h>

#include <string>

#include "exsynth/errors.hpp"

namespace exsynth::voxel {

#if EXSYNTH_EMBREE_MAJOR == 4
constexpr const char* kLibrary = "libembree4.so.4";
#else
constexpr const char* kLibrary = "libembree3.so.3";
#endif

namespace {

// Called from here, dlopen searches this object's run path first ($ORIGIN/lib
// in a packaged add-on) and returns the copy already loaded as the module's
// dependency.
void* open_library() {
  void* handle = dlopen(kLibrary, RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw Error(std::string("cannot load Embree (") + kLibrary + "): " + dlerror());
  return handle;
}

template <class F>
void bind(void* handle, const char* name, F& slot) {
  void* f = dlsym(handle, name);  // this library's definition, not the global scope's
  if (!f) throw Error(std::string("Embree (") + kLibrary + ") has no " + name);
  slot = reinterpret_cast<F>(f);
}

EmbreeApi load() {
  void* h = open_library();  // kept open for the process's life
  EmbreeApi api{};
  bind(h, "rtcNewDevice", api.NewDevice);
  bind(h, "rtcGetDeviceError", api.GetDeviceError);
  bind(h, "rtcReleaseDevice", api.ReleaseDevice);
  bind(h, "rtcNewScene", api.NewScene);
  bind(h, "rtcSetSceneFlags", api.SetSceneFlags);
  bind(h, "rtcSetSceneBuildQuality", api.SetSceneBuildQuality);
  bind(h, "rtcCommitScene", api.CommitScene);
  bind(h, "rtcReleaseScene", api.ReleaseScene);
  bind(h, "rtcNewGeometry", api.NewGeometry);
  bind(h, "rtcSetNewGeometryBuffer", api.SetNewGeometryBuffer);
  bind(h, "rtcSetGeometryIntersectFilterFunction", api.SetGeometryIntersectFilterFunction);
  bind(h, "rtcCommitGeometry", api.CommitGeometry);
  bind(h, "rtcAttachGeometry", api.AttachGeometry);
  bind(h, "rtcReleaseGeometry", api.ReleaseGeometry);
  bind(h, "rtcIntersect1", api.Intersect1);
  return api;
}

}  // namespace

const EmbreeApi& embree() {
  static const EmbreeApi api = load();
  return api;
}

}  // namespace exsynth::voxel

namespace exsynth {
const char* embree_library() { return voxel::kLibrary; }
}  // namespace exsynth

namespace exsynth::voxel {

#if EXSYNTH_EMBREE_MAJOR == 4
void init_context(RayContext& ctx) { rtcInitRayQueryContext(&ctx); }

void intersect1(RTCScene scene, RayContext& ctx, RTCRayHit& rayhit) {
  RTCIntersectArguments args;
  rtcInitIntersectArguments(&args);
  args.context = &ctx;
  embree().Intersect1(scene, &rayhit, &args);
}
#else
void init_context(RayContext& ctx) { rtcInitIntersectContext(&ctx); }

void intersect1(RTCScene scene, RayContext& ctx, RTCRayHit& rayhit) { embree().Intersect1(scene, &ctx, &rayhit); }
#endif

}  // namespace exsynth::voxel
