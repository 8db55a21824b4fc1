#pragma once
// Bilinear / trilinear / tricubic sampling in index coordinates (pixel or
// voxel centres at integer positions).
#include <string>
#include <vector>

#include "exsynth/grid.hpp"

namespace exsynth {

/// How a volume is read between voxel centres when it is put on a surface.
/// Linear: trilinear (8 voxels). Cubic: tricubic Catmull-Rom (64 voxels)
/// limited to the range of the 8 surrounding voxels, so it adds no halos and
/// no values outside them (crisper: voxel-scale detail keeps its contrast).
enum class Interpolation { Linear, Cubic };
/// The default wherever a solid is put on a surface (sample_volume, BakeOptions, the bindings).
constexpr Interpolation kDefaultInterpolation = Interpolation::Cubic;
/// The names the bindings, add-on and CLI take, in enum order ("linear", "cubic").
const std::vector<std::string>& interpolation_names();
/// The Interpolation a name gives; InvalidInput naming `what` and the choices otherwise.
Interpolation interpolation_from_name(const std::string& name, const std::string& what);

/// Bilinear sample of channel c at index position (x, y).
float sample_bilinear(const Image& img, double x, double y, int c, Boundary b = Boundary::Clamp);

/// Trilinear sample of channel c at index position (x, y, z).
float sample_trilinear(const Volume& vol, double x, double y, double z, int c,
                       Boundary b = Boundary::Clamp);

/// All channels at once into out[0 .. channels).
void sample_trilinear(const Volume& vol, double x, double y, double z, float* out,
                      Boundary b = Boundary::Clamp);

/// Tricubic (Catmull-Rom) sample of all channels at index position (x, y, z),
/// each channel limited to the min/max of the 8 voxels around the point.
void sample_tricubic(const Volume& vol, double x, double y, double z, float* out,
                     Boundary b = Boundary::Clamp);

/// sample_trilinear or sample_tricubic.
void sample_volume_at(const Volume& vol, double x, double y, double z, float* out, Interpolation interp,
                      Boundary b = Boundary::Clamp);

/// Resamples to a new size by trilinear interpolation (grid corners aligned
/// at voxel centres scaled by the size ratio); used to upsample between levels.
Volume resize_trilinear(const Volume& vol, int nx, int ny, int nz, Boundary b = Boundary::Clamp);

}  // namespace exsynth
