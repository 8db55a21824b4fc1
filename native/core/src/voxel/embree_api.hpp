#pragma once
// Embree 3 through function pointers looked up in the libembree3 the module
// was linked with (dlopen by SONAME, then dlsym on that handle), never through
// the process's global symbol scope.
//
// Why: official Blender ships Embree 4 and its executable loads it as its own
// dependency, so it sits in the global scope, which the dynamic loader
// searches before the module's own libraries. Embree 3 and 4 export the same
// unversioned C names (rtcNewDevice, rtcIntersect1, ...) with different
// ABIs: bound by name, the module's Embree 3 calls land in Blender's Embree 4
// and Voxelize silently returns an empty grid (seen with the 4.5 bpy module
// when its libraries are loaded into the global scope as the executable has
// them; tests/package/test_extension.py). Embree 3 never calls its own
// exported functions through the PLT (no relocations against rtc* in
// Debian's build), so once entered, it stays in itself.
#include <embree3/rtcore.h>

namespace exsynth::voxel {

struct EmbreeApi {
  decltype(&::rtcNewDevice) NewDevice;
  decltype(&::rtcGetDeviceError) GetDeviceError;
  decltype(&::rtcReleaseDevice) ReleaseDevice;
  decltype(&::rtcNewScene) NewScene;
  decltype(&::rtcSetSceneFlags) SetSceneFlags;
  decltype(&::rtcSetSceneBuildQuality) SetSceneBuildQuality;
  decltype(&::rtcCommitScene) CommitScene;
  decltype(&::rtcReleaseScene) ReleaseScene;
  decltype(&::rtcNewGeometry) NewGeometry;
  decltype(&::rtcSetNewGeometryBuffer) SetNewGeometryBuffer;
  decltype(&::rtcSetGeometryIntersectFilterFunction) SetGeometryIntersectFilterFunction;
  decltype(&::rtcCommitGeometry) CommitGeometry;
  decltype(&::rtcAttachGeometry) AttachGeometry;
  decltype(&::rtcReleaseGeometry) ReleaseGeometry;
  decltype(&::rtcIntersect1) Intersect1;
};

/// The table, loaded on first use (thread-safe); throws Error naming the
/// library or function when Embree 3 cannot be found.
const EmbreeApi& embree();

}  // namespace exsynth::voxel
