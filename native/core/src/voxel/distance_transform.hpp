#pragma once
// Separable exact distance transform of a sampled function (Felzenszwalb &
// Huttenlocher 2012) that carries a feature label: after the three passes,
// dist2[v] = min over seeds s of (|v - s|^2 + dist2_seed[s]) in voxel units,
// and label[v] = the label of the minimising seed. The voxelizer seeds the
// narrow band with exact squared distances and triangle ids, so every voxel
// ends up knowing a triangle that is (nearly always) its nearest one.
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"

namespace exsynth::voxel {

constexpr float kFarAway = 1e30f;  ///< "no seed here"

/// dist2 / label: nx*ny*nz voxels, x fastest. Entries with dist2 >= kFarAway
/// are not seeds. Both arrays are updated in place.
void distance_transform(int nx, int ny, int nz, std::vector<float>& dist2,
                        std::vector<std::int32_t>& label, StageProgress& progress);

/// 1-D transform (exposed for tests): f and lab in, d and out_lab out; n
/// values. Scratch: v and g hold n entries, z n + 1.
void distance_transform_1d(const float* f, const std::int32_t* lab, int n, float* d, std::int32_t* out_lab,
                           int* v_scratch, double* g_scratch, double* z_scratch);

}  // namespace exsynth::voxel
