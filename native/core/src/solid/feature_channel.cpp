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

// Mean of the (2r + 1)^2 window around every pixel (edges clamped), by two
// separable running sums: O(pixels) for any r.
std::vector<float> local_mean(const std::vector<float>& v, int w, int h, int r) {
  std::vector<double> rows(v.size());
  for (int y = 0; y < h; ++y) {
    double sum = 0.0;
    auto at = [&](int x) { return double(v[std::size_t(y) * w + std::clamp(x, 0, w - 1)]); };
    for (int x = -r; x <= r; ++x) sum += at(x);
    for (int x = 0; x < w; ++x) {
      rows[std::size_t(y) * w + x] = sum;
      sum += at(x + r + 1) - at(x - r);
    }
  }
  std::vector<float> out(v.size());
  const double area = double(2 * r + 1) * (2 * r + 1);
  for (int x = 0; x < w; ++x) {
    double sum = 0.0;
    auto at = [&](int y) { return rows[std::size_t(std::clamp(y, 0, h - 1)) * w + x]; };
    for (int y = -r; y <= r; ++y) sum += at(y);
    for (int y = 0; y < h; ++y) {
      out[std::size_t(y) * w + x] = float(sum / area);
      sum += at(y + r + 1) - at(y - r);
    }
  }
  return out;
}

// Standard deviation of the luminance over the whole exemplar.
double deviation(const std::vector<float>& lum) {
  double sum = 0.0, sum2 = 0.0;
  for (float v : lum) {
    sum += v;
    sum2 += double(v) * v;
  }
  const double mean = sum / double(lum.size());
  return std::sqrt(std::max(0.0, sum2 / double(lum.size()) - mean * mean));
}

}  // namespace

Image with_feature_channel(const Image& ex, float weight, int scale, double threshold) {
  const int w = ex.width(), h = ex.height(), C = ex.channels(), L = std::min(C, 3);
  std::vector<float> lum(ex.pixel_count());
  for (std::size_t p = 0; p < lum.size(); ++p) {
    float s = 0.0f;
    for (int c = 0; c < L; ++c) s += ex.data()[p * C + c];
    lum[p] = s / L;
  }
  const std::vector<float> mean = local_mean(lum, w, h, scale);
  std::vector<std::uint8_t> feature(lum.size());
  const float margin = threshold > 0.0 ? float(threshold * deviation(lum)) : 0.0f;
  for (std::size_t p = 0; p < lum.size(); ++p) feature[p] = lum[p] < mean[p] - margin ? 1 : 0;
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
