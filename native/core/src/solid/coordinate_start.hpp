#pragma once
// SolidOptions::coordinate_start: the optimiser's level that starts from a
// coordinates solid (SolidMethod::Coordinates) instead of the upsampled
// coarser level (docs/solid.md, eighth pass).
#include <array>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/solid.hpp"

namespace exsynth::solid {

/// The coordinates solid of `opt` (at opt.size), Gaussian-downsampled
/// `halvings` times to the optimiser's level size (the level's exemplar is
/// the pyramid's, downsampled the same way), values times 2^-exponent (the
/// optimiser's value scale). `views`: the exemplar per view, nullptr =
/// inactive. Cancellation goes through `ctx`; its progress is not advanced.
Volume coordinate_start_texture(const std::array<const Image*, 3>& views, const SolidOptions& opt, int halvings,
                                int exponent, ExecContext* ctx);

}  // namespace exsynth::solid
