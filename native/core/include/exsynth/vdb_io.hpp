#pragma once
// .vdb files of named grids (OpenVDB), with the world transform, so Blender,
// Houdini and any OpenVDB tool read what exsynth writes.
#include <map>
#include <string>
#include <vector>

#include "exsynth/grid.hpp"

namespace exsynth {

/// Writes each volume as named grid(s), with its transform:
///   1 channel  -> FloatGrid `name`
///   3 channels -> Vec3SGrid `name`
///   C channels -> C FloatGrids `name_0` ... `name_{C-1}`
/// A grid named "sdf" is written as a level set (background = the largest
/// value, all voxels active); the others as fog volumes whose zero voxels are
/// inactive. Throws InvalidInput for an empty map, empty volume or a bad path.
void write_vdb(const std::string& path, const std::map<std::string, Volume>& grids);

/// Reads the named grids (all float and vec3 grids when `names` is empty) into
/// dense volumes over one box: the union of the grids' active voxels. Every
/// returned volume has that box's transform. Throws InvalidInput when the
/// file is missing or unreadable or a requested grid is absent.
std::map<std::string, Volume> read_vdb(const std::string& path,
                                       const std::vector<std::string>& names = {});

}  // namespace exsynth
