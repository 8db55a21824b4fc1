#pragma once
// Embree 3 or 4 (whichever CMake found: EXSYNTH_EMBREE_MAJOR), reached
// through function pointers looked up in the libembree the module was linked
// with (dlopen by SONAME, then dlsym on that handle), never through the
// process's global symbol scope. This file is the one seam between the two
// Embree versions: the voxelizer's ray code uses only what is declared here.
//
// Why function pointers: official Blender ships Embree 4 and its executable
// loads it as its own dependency, so it sits in the global scope, which the
// dynamic loader searches before the module's own libraries. Embree 3 and 4
// export the same unversioned C names (rtcNewDevice, rtcIntersect1, ...) with
// different ABIs: bound by name, the module's Embree 3 calls land in
// Blender's Embree 4 and Voxelize silently returns an empty grid (seen with
// the 4.5 bpy module when its libraries are loaded into the global scope as
// the executable has them; tests/package/test_extension.py). Once entered,
// Embree stays in itself: Debian's Embree 3 calls none of its exported
// functions through the PLT, Embree 4 only rtcForward* (user geometry
// forwarding rays to instances, which the voxelizer does not use).
#if EXSYNTH_EMBREE_MAJOR == 4
#include <embree4/rtcore.h>
#elif EXSYNTH_EMBREE_MAJOR == 3
#include <embree3/rtcore.h>
#else
#error "EXSYNTH_EMBREE_MAJOR must be 3 or 4 (set by CMakeLists.txt)"
#endif

namespace exsynth::voxel {

/// What a filter callback receives as `args->context`: callers put their own
/// data behind it (a struct whose first member is a RayContext).
#if EXSYNTH_EMBREE_MAJOR == 4
using RayContext = RTCRayQueryContext;
#else
using RayContext = RTCIntersectContext;
#endif

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
/// library or function when Embree cannot be found.
const EmbreeApi& embree();

/// A context for one query (Embree 3: rtcInitIntersectContext; 4:
/// rtcInitRayQueryContext).
void init_context(RayContext& ctx);

/// Closest-hit query of one ray; the geometry's filter callbacks see `ctx`.
void intersect1(RTCScene scene, RayContext& ctx, RTCRayHit& rayhit);

}  // namespace exsynth::voxel
