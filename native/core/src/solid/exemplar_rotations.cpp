#include "solid/exemplar_rotations.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "exsynth/errors.hpp"
#include "exsynth/solid.hpp"

namespace exsynth::solid {

int quarter_turn_tile(int square) { return std::max(std::min(square, kMaxTurnedTile), square / 2); }

Image quarter_turn_mosaic(const Image& ex) {
  const int s = std::min(ex.width(), ex.height()), c = ex.channels();
  const int t = quarter_turn_tile(s);
  const int x0 = (ex.width() - s) / 2, y0 = (ex.height() - s) / 2;  // the central square
  Image out(2 * t, 2 * t, c);
  // Quarter q at (qx, qy) is the t x t corner (qx, qy) of the central square
  // turned q x 90 degrees clockwise: its pixel (x, y) is the corner's pixel
  // at the inverse turn of (x, y).
  for (int q = 0; q < 4; ++q) {
    const int qx = (q & 1) * t, qy = (q >> 1) * t;
    const int cx = x0 + (q & 1) * (s - t), cy = y0 + (q >> 1) * (s - t);
    for (int y = 0; y < t; ++y)
      for (int x = 0; x < t; ++x) {
        int sx = x, sy = y;
        for (int k = 0; k < q; ++k) {  // undo one clockwise turn: (x, y) <- (y, t - 1 - x)
          const int nx = sy, ny = t - 1 - sx;
          sx = nx;
          sy = ny;
        }
        std::copy_n(ex.data() + ex.offset(cx + sx, cy + sy), c, out.data() + out.offset(qx + x, qy + y));
      }
  }
  return out;
}

}  // namespace exsynth::solid

namespace exsynth {

namespace {

// Luminance (mean of the first `channels` channels), blurred by a Gaussian
// of one pixel (periodic, radius 4), with its mean removed.
std::vector<double> blurred_luminance(const Image& ex, int channels) {
  const int w = ex.width(), h = ex.height(), c = ex.channels();
  std::vector<double> lum(std::size_t(w) * h), tmp(lum.size());
  for (std::size_t p = 0; p < lum.size(); ++p) {
    double s = 0.0;
    for (int k = 0; k < channels; ++k) s += ex.data()[p * std::size_t(c) + std::size_t(k)];
    lum[p] = s / channels;
  }
  constexpr int kRadius = 4;
  double g[2 * kRadius + 1], gs = 0.0;
  for (int k = -kRadius; k <= kRadius; ++k) gs += g[k + kRadius] = std::exp(-0.5 * k * k);
  for (double& v : g) v /= gs;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -kRadius; k <= kRadius; ++k) s += g[k + kRadius] * lum[std::size_t(y) * w + wrap(x + k, w)];
      tmp[std::size_t(y) * w + x] = s;
    }
  double mean = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -kRadius; k <= kRadius; ++k) s += g[k + kRadius] * tmp[std::size_t(wrap(y + k, h)) * w + x];
      lum[std::size_t(y) * w + x] = s;
      mean += s;
    }
  mean /= double(lum.size());
  for (double& v : lum) v -= mean;
  return lum;
}

}  // namespace

// The autocorrelation is needed only on the lobe and its rim (tens of lags),
// so each lag's sum is computed when the flood fill reaches it: O(lobe x
// pixels) instead of an FFT of the padded image (no FFT in the stack).
double exemplar_feature_stretch(const Image& ex) {
  const int w = ex.width(), h = ex.height();
  if (w < 1 || h < 1 || ex.channels() < 1) return 1.0;
  const std::vector<double> a = blurred_luminance(ex, ex.channels());
  double energy = 0.0;
  for (double v : a) energy += v * v;
  if (energy <= 0.0) return 1.0;  // flat: no features, no direction
  auto correlation = [&](int du, int dv) {  // zero padded: only overlapping pixels
    double s = 0.0;
    for (int y = std::max(0, -dv); y < std::min(h, h - dv); ++y)
      for (int x = std::max(0, -du); x < std::min(w, w - du); ++x)
        s += a[std::size_t(y) * w + x] * a[std::size_t(y + dv) * w + x + du];
    return s / energy;
  };
  constexpr double kLobeLevel = 0.3;
  const int rw = 2 * w - 1;  // lags (du, dv) in (-w, w) x (-h, h)
  std::vector<signed char> state(std::size_t(rw) * (2 * h - 1), 0);  // 0 unseen, 1 lobe, -1 below
  std::vector<std::pair<int, int>> stack{{0, 0}};
  state[std::size_t(h - 1) * rw + (w - 1)] = 1;
  double sw = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
  while (!stack.empty()) {
    const auto [du, dv] = stack.back();
    stack.pop_back();
    const double c = (du == 0 && dv == 0) ? 1.0 : correlation(du, dv);
    sw += c, suu += c * du * du, svv += c * dv * dv, suv += c * du * dv;
    const int next[4][2] = {{du + 1, dv}, {du - 1, dv}, {du, dv + 1}, {du, dv - 1}};
    for (const auto& n : next) {
      if (n[0] <= -w || n[0] >= w || n[1] <= -h || n[1] >= h) continue;
      signed char& s = state[std::size_t(n[1] + h - 1) * rw + (n[0] + w - 1)];
      if (s != 0) continue;
      s = correlation(n[0], n[1]) > kLobeLevel ? 1 : -1;
      if (s > 0) stack.push_back({n[0], n[1]});
    }
  }
  // Eigenvalues of the 2 x 2 second-moment matrix.
  const double t_uu = suu / sw, t_vv = svv / sw, t_uv = suv / sw;
  const double mid = 0.5 * (t_uu + t_vv), rad = std::sqrt(0.25 * (t_uu - t_vv) * (t_uu - t_vv) + t_uv * t_uv);
  const double big = mid + rad, small = std::max(mid - rad, 1e-12);
  return big <= 0.0 ? 1.0 : std::sqrt(big / small);
}

namespace {

// In RotateExemplar's order.
const std::vector<std::string> kRotateNames{"off", "on", "auto"};

}  // namespace

const std::vector<std::string>& rotate_exemplar_names() { return kRotateNames; }
const char* rotate_exemplar_name(RotateExemplar r) { return kRotateNames[std::size_t(r)].c_str(); }

RotateExemplar rotate_exemplar_from_name(const std::string& name) {
  for (std::size_t i = 0; i < kRotateNames.size(); ++i)
    if (kRotateNames[i] == name) return RotateExemplar(i);
  throw InvalidInput("rotate_exemplar must be 'off', 'on' or 'auto', got '" + name + "'");
}

}  // namespace exsynth
