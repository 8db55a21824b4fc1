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

/// Edge of the mosaic's quarters for a central square of edge `square`:
/// the whole square up to kMaxTurnedTile pixels, then kMaxTurnedTile, then
/// half the square (its four quadrants), so that the mosaic never has more
/// windows than max(256^2, the square's).
int quarter_turn_tile(int square);

/// The exemplar's central square (edge s = the shorter side) in quarter
/// turns, as one 2t x 2t image, t = quarter_turn_tile(s): top left the
/// square's top-left t x t corner as given, top right its top-right corner
/// turned 90 degrees clockwise, bottom left its bottom-left corner turned
/// 180, bottom right its bottom-right corner turned 270. Up to s = 128 the
/// four corners are the whole square (four turns of it); from s = 256 they
/// are its quadrants, each in one turn: every texel once, at the cost of
/// the square unturned (a 256^2 exemplar, 128^3: 13.3 s CPU against 28.6 s
/// with four whole turns and 11.8 s unturned, under load; docs/solid.md,
/// fifteenth pass). Windows that straddle two quarters mix two turns: about
/// 2 (n - 1) / (2t) of the windows (n the neighbourhood; 5 % at t = 128, n = 8),
/// which the search may pick.
Image quarter_turn_mosaic(const Image& exemplar);

}  // namespace exsynth::solid
