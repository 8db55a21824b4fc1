#pragma once
// Gaussian pyramids: each level is the previous one blurred with the 5-tap
// binomial kernel [1 4 6 4 1]/16 (separable) and decimated by 2
// (size ceil(n/2)). Level 0 is the input. Volume levels keep a consistent
// world transform: voxel 0's centre stays put and the voxel size doubles.
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"

namespace exsynth {

/// Limit of PyramidOptions::levels (2^31 voxels halve to one in 31 steps).
constexpr int kMaxPyramidLevels = 32;

struct PyramidOptions {
  int levels = 3;                    ///< number of levels including the input (>= 1)
  Boundary boundary = Boundary::Clamp;  ///< Wrap for tileable (toroidal) data
  unsigned long long seed = 0;       ///< unused: the filter is deterministic
};

std::vector<Image> gaussian_pyramid(const Image& img, const PyramidOptions& opt = {},
                                    ExecContext* ctx = nullptr);
std::vector<Volume> gaussian_pyramid(const Volume& vol, const PyramidOptions& opt = {},
                                     ExecContext* ctx = nullptr);
/// The same as one stage of a longer job: progress goes from lo to hi.
std::vector<Volume> gaussian_pyramid(const Volume& vol, const PyramidOptions& opt, ExecContext* ctx, double lo,
                                     double hi);

/// One blur + decimate step (exposed for tests).
Image downsample(const Image& img, Boundary b);
Volume downsample(const Volume& vol, Boundary b);

}  // namespace exsynth
