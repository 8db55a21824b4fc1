#include "voxel/embree_api.hpp"

#include <dlfcn.h>

#include <string>

#include "exsynth/errors.hpp"

namespace exsynth::voxel {
namespace {

constexpr const char* kLibrary = "libembree3.so.3";

// Called from here, dlopen searches this object's run path first ($ORIGIN/lib
// in a packaged add-on) and returns the copy already loaded as the module's
// dependency.
void* open_library() {
  void* handle = dlopen(kLibrary, RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw Error(std::string("cannot load Embree 3 (") + kLibrary + "): " + dlerror());
  return handle;
}

template <class F>
void bind(void* handle, const char* name, F& slot) {
  void* f = dlsym(handle, name);  // this library's definition, not the global scope's
  if (!f) throw Error(std::string("Embree 3 (") + kLibrary + ") has no " + name);
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
