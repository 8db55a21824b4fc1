#pragma once
// Synthetic exemplars for C++ tests (PNG exemplars are used in the Python
// tier): random soft discs on a background, in C channels; uniform noise;
// one image as every view of a solid.
#include <algorithm>
#include <cmath>

#include "exsynth/grid.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/solid.hpp"

namespace exsynth::testing {

inline Image disc_texture(int w, int h, int channels, std::uint64_t seed, int discs = 14, float radius = 3.5f) {
  Image img(w, h, channels, 0.15f);
  for (int k = 0; k < discs; ++k) {
    IndexRng r(seed, std::uint64_t(k));
    const float cx = float(r.uniform() * w), cy = float(r.uniform() * h);
    const float rad = radius * float(0.7 + 0.6 * r.uniform());
    float colour[16];
    for (int c = 0; c < channels; ++c) colour[c] = float(0.5 + 0.5 * r.uniform());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float d = std::hypot(x - cx, y - cy);
        const float a = std::clamp(rad + 0.5f - d, 0.0f, 1.0f);
        for (int c = 0; c < channels; ++c) img.at(x, y, c) = (1 - a) * img.at(x, y, c) + a * colour[c];
      }
  }
  return img;
}

/// Values uniform in [0, 1), seeded per value index.
inline Image random_image(int w, int h, int c, std::uint64_t seed) {
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.values().size(); ++i) img.values()[i] = float(IndexRng(seed, i).uniform());
  return img;
}

/// `img` as the x view; the other views reuse it.
inline SolidExemplars one_exemplar(const Image& img) {
  SolidExemplars ex;
  ex.views[0] = img;
  return ex;
}

/// `img` as every view of a size^3 solid whose constraint pins the corner
/// cube [0, edge)^3 to the C values `target` (weight 1) and leaves the rest free.
inline SolidExemplars pinned_corner(const Image& img, int size, int edge, const float* target) {
  SolidExemplars ex = one_exemplar(img);
  const int C = img.channels();
  ex.constraint = Volume(size, size, size, C + 1, 0.0f);
  for (int z = 0; z < edge; ++z)
    for (int y = 0; y < edge; ++y)
      for (int x = 0; x < edge; ++x) {
        for (int c = 0; c < C; ++c) ex.constraint.at(x, y, z, c) = target[c];
        ex.constraint.at(x, y, z, C) = 1.0f;
      }
  return ex;
}

}  // namespace exsynth::testing
