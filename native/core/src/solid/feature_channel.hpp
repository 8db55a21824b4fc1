#pragma once
// The feature-distance channel of Kopf et al. 2007 (after Lefebvre & Hoppe
// 2006): for exemplars with strong structure (mortar lines, cracks), matching
// on colour alone lets features break up; an extra channel holding the
// signed distance to the nearest feature edge makes neighbourhoods with the
// same structure match, and is dropped from the output.
#include "exsynth/grid.hpp"

namespace exsynth::solid {

/// Appends one channel: features = pixels darker than the mean luminance of
/// the (2 scale + 1)^2 window around them (cracks, mortar, grain lines; not a
/// whole darker region: against the exemplar's global mean, drkwood2's dark
/// half became the whole solid, contrast 0.49; docs/solid.md, ninth pass);
/// value = weight * (0.5 + 0.5 * clamp(signed distance to the feature edge /
/// `scale` pixels, -1, 1)), positive outside features. Exact Euclidean
/// distances (separable transform). threshold > 0: a feature must be darker
/// than that mean by threshold x the exemplar's luminance standard deviation.
Image with_feature_channel(const Image& exemplar, float weight, int scale, double threshold = 0.0);

}  // namespace exsynth::solid
