#pragma once
// Rotation-invariant exemplars: for textures with no preferred direction
// (cracks, stones, granite) the optimiser may use the exemplar in its four
// quarter turns. Without them a mildly anisotropic exemplar's features line
// up in 3D: the three slice views agree on a stretched direction only along
// one diagonal, and the optimiser amplifies the exemplar's slight lean there
// into parallel sheets (crackedground at feature_threshold 1: 3D
// elongation 2.4-2.5; docs/solid.md, fourteenth pass). With every quarter turn
// in the candidate pool, each view can match a feature whatever its
// direction.
#include "exsynth/grid.hpp"

namespace exsynth::solid {

/// The exemplar's central square (edge = the shorter side) in its four
/// quarter turns, as one 2s x 2s image: top left as given, top right turned
/// 90 degrees clockwise, bottom left 180, bottom right 270. Windows that
/// straddle two quarters mix two turns: about (n - 1) / s of the windows (n
/// the neighbourhood; 5 % at s = 128, n = 8), which the search may pick.
Image quarter_turn_mosaic(const Image& exemplar);

}  // namespace exsynth::solid
