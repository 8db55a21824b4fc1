#pragma once
// synthesize_solid's SolidMethod::Coordinates path (solid/coordinate_solver.hpp).
#include <array>

#include "exsynth/solid.hpp"

namespace exsynth::solid {

/// `views`: the exemplar per view, nullptr = inactive (two at least; the
/// caller resolved reused views and checked size and options).
TextureResult synthesize_coordinates(const std::array<const Image*, 3>& views, const Volume& constraint,
                                     const SolidOptions& opt, ExecContext* ctx);

}  // namespace exsynth::solid
