#pragma once
// Bilinear / trilinear sampling in index coordinates (pixel or voxel centres
// at integer positions).
#include "exsynth/grid.hpp"

namespace exsynth {

/// Bilinear sample of channel c at index position (x, y).
float sample_bilinear(const Image& img, double x, double y, int c, Boundary b = Boundary::Clamp);

/// Trilinear sample of channel c at index position (x, y, z).
float sample_trilinear(const Volume& vol, double x, double y, double z, int c,
                       Boundary b = Boundary::Clamp);

/// All channels at once into out[0 .. channels).
void sample_trilinear(const Volume& vol, double x, double y, double z, float* out,
                      Boundary b = Boundary::Clamp);

/// Resamples to a new size by trilinear interpolation (grid corners aligned
/// at voxel centres scaled by the size ratio); used to upsample between levels.
Volume resize_trilinear(const Volume& vol, int nx, int ny, int nz, Boundary b = Boundary::Clamp);

}  // namespace exsynth
