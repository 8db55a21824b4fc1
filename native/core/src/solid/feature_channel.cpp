#include "solid/feature_channel.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "voxel/distance_transform.hpp"

namespace exsynth::solid {
namespace {

// Squared distance from every pixel to the nearest pixel with mask == want.
std::vector<float> distance_to(const std::vector<std::uint8_t>& mask, std::uint8_t want, int w, int h) {
  std::vector<float> d2(mask.size());
  std::vector<std::int32_t> label(mask.size(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) d2[i] = mask[i] == want ? 0.0f : voxel::kFarAway;
  StageProgress none(nullptr, "", 0, 1, 1);
  voxel::distance_transform(w, h, 1, d2, label, none);
  return d2;
}

}  // namespace

Image with_feature_channel(const Image& ex, float weight, int scale) {
  const int w = ex.width(), h = ex.height(), C = ex.channels(), L = std::min(C, 3);
  std::vector<float> lum(ex.pixel_count());
  double mean = 0.0;
  for (std::size_t p = 0; p < lum.size(); ++p) {
    float s = 0.0f;
    for (int c = 0; c < L; ++c) s += ex.data()[p * C + c];
    lum[p] = s / L;
    mean += lum[p] / double(lum.size());
  }
  std::vector<std::uint8_t> feature(lum.size());
  for (std::size_t p = 0; p < lum.size(); ++p) feature[p] = lum[p] < mean ? 1 : 0;
  const std::vector<float> to_feature = distance_to(feature, 1, w, h);
  const std::vector<float> to_background = distance_to(feature, 0, w, h);

  Image out(w, h, C + 1);
  for (std::size_t p = 0; p < lum.size(); ++p) {
    std::copy(ex.data() + p * C, ex.data() + (p + 1) * C, out.data() + p * (C + 1));
    // A uniform exemplar has no edge: both transforms report "far away".
    const float signed_distance = feature[p] ? -std::sqrt(std::min(to_background[p], 1e12f))
                                             : std::sqrt(std::min(to_feature[p], 1e12f));
    const float t = std::clamp(signed_distance / float(scale), -1.0f, 1.0f);
    out.data()[p * (C + 1) + C] = weight * (0.5f + 0.5f * t);
  }
  return out;
}

}  // namespace exsynth::solid
