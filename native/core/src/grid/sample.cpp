#include "exsynth/sample.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"

namespace exsynth {
namespace {

// The two grid indices bracketing coordinate t on an axis of n samples, and
// the weight of the upper one. Clamping the coordinate before the floor is
// equivalent to clamping both indices and keeps huge inputs out of int range.
struct Span {
  int i0, i1;
  double w;
};

Span axis_span(double t, int n, Boundary b) {
  if (b == Boundary::Wrap) {
    t -= double(n) * std::floor(t / double(n));  // into [0, n], negative t included
    int i0 = int(std::floor(t));
    const double w = t - i0;
    if (i0 >= n) i0 -= n;  // t rounded up to exactly n
    const int i1 = i0 + 1 == n ? 0 : i0 + 1;
    return {i0, i1, w};
  }
  t = std::clamp(t, 0.0, double(n - 1));
  const int i0 = std::min(int(std::floor(t)), n - 1);
  const int i1 = std::min(i0 + 1, n - 1);
  return {i0, i1, t - i0};
}

// The four indices around t on an axis of n samples for a cubic (i0 - 1, i0,
// i1, i1 + 1, by the boundary) and the weight of i1 as axis_span gives it.
struct Taps {
  int i[4];
  double w;
};

Taps axis_taps(double t, int n, Boundary b) {
  const Span s = axis_span(t, n, b);
  if (b == Boundary::Wrap) return {{s.i0 == 0 ? n - 1 : s.i0 - 1, s.i0, s.i1, s.i1 + 1 == n ? 0 : s.i1 + 1}, s.w};
  return {{std::max(s.i0 - 1, 0), s.i0, s.i1, std::min(s.i1 + 1, n - 1)}, s.w};
}

// Catmull-Rom weights of the taps at -1, 0, 1, 2 for a point w in [0, 1].
void catmull_rom(double w, double out[4]) {
  const double w2 = w * w, w3 = w2 * w;
  out[0] = 0.5 * (-w3 + 2.0 * w2 - w);
  out[1] = 0.5 * (3.0 * w3 - 5.0 * w2 + 2.0);
  out[2] = 0.5 * (-3.0 * w3 + 4.0 * w2 + w);
  out[3] = 0.5 * (w3 - w2);
}

}  // namespace

const std::vector<std::string>& interpolation_names() {
  static const std::vector<std::string> names{"linear", "cubic"};
  return names;
}

Interpolation interpolation_from_name(const std::string& name, const std::string& what) {
  const auto& names = interpolation_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return Interpolation(i);
  throw InvalidInput(what + " must be 'linear' or 'cubic', got '" + name + "'");
}

float sample_bilinear(const Image& img, double x, double y, int c, Boundary b) {
  assert(!img.empty() && c >= 0 && c < img.channels());
  if (!std::isfinite(x) || !std::isfinite(y)) return std::numeric_limits<float>::quiet_NaN();
  const Span sx = axis_span(x, img.width(), b);
  const Span sy = axis_span(y, img.height(), b);
  const double v00 = img.at(sx.i0, sy.i0, c), v10 = img.at(sx.i1, sy.i0, c);
  const double v01 = img.at(sx.i0, sy.i1, c), v11 = img.at(sx.i1, sy.i1, c);
  const double top = v00 + sx.w * (v10 - v00);
  const double bottom = v01 + sx.w * (v11 - v01);
  return float(top + sy.w * (bottom - top));
}

void sample_trilinear(const Volume& vol, double x, double y, double z, float* out, Boundary b) {
  assert(!vol.empty());
  const int nc = vol.channels();
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    std::fill(out, out + nc, std::numeric_limits<float>::quiet_NaN());
    return;
  }
  const Span sx = axis_span(x, vol.nx(), b);
  const Span sy = axis_span(y, vol.ny(), b);
  const Span sz = axis_span(z, vol.nz(), b);
  const float* d = vol.data();
  const float* p000 = d + vol.offset(sx.i0, sy.i0, sz.i0);
  const float* p100 = d + vol.offset(sx.i1, sy.i0, sz.i0);
  const float* p010 = d + vol.offset(sx.i0, sy.i1, sz.i0);
  const float* p110 = d + vol.offset(sx.i1, sy.i1, sz.i0);
  const float* p001 = d + vol.offset(sx.i0, sy.i0, sz.i1);
  const float* p101 = d + vol.offset(sx.i1, sy.i0, sz.i1);
  const float* p011 = d + vol.offset(sx.i0, sy.i1, sz.i1);
  const float* p111 = d + vol.offset(sx.i1, sy.i1, sz.i1);
  for (int c = 0; c < nc; ++c) {
    const double x00 = p000[c] + sx.w * (double(p100[c]) - p000[c]);
    const double x10 = p010[c] + sx.w * (double(p110[c]) - p010[c]);
    const double x01 = p001[c] + sx.w * (double(p101[c]) - p001[c]);
    const double x11 = p011[c] + sx.w * (double(p111[c]) - p011[c]);
    const double y0 = x00 + sy.w * (x10 - x00);
    const double y1 = x01 + sy.w * (x11 - x01);
    out[c] = float(y0 + sz.w * (y1 - y0));
  }
}

float sample_trilinear(const Volume& vol, double x, double y, double z, int c, Boundary b) {
  assert(!vol.empty() && c >= 0 && c < vol.channels());
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    return std::numeric_limits<float>::quiet_NaN();
  }
  const Span sx = axis_span(x, vol.nx(), b);
  const Span sy = axis_span(y, vol.ny(), b);
  const Span sz = axis_span(z, vol.nz(), b);
  auto v = [&](int i, int j, int k) { return double(vol.at(i, j, k, c)); };
  const double x00 = v(sx.i0, sy.i0, sz.i0) + sx.w * (v(sx.i1, sy.i0, sz.i0) - v(sx.i0, sy.i0, sz.i0));
  const double x10 = v(sx.i0, sy.i1, sz.i0) + sx.w * (v(sx.i1, sy.i1, sz.i0) - v(sx.i0, sy.i1, sz.i0));
  const double x01 = v(sx.i0, sy.i0, sz.i1) + sx.w * (v(sx.i1, sy.i0, sz.i1) - v(sx.i0, sy.i0, sz.i1));
  const double x11 = v(sx.i0, sy.i1, sz.i1) + sx.w * (v(sx.i1, sy.i1, sz.i1) - v(sx.i0, sy.i1, sz.i1));
  const double y0 = x00 + sy.w * (x10 - x00);
  const double y1 = x01 + sy.w * (x11 - x01);
  return float(y0 + sz.w * (y1 - y0));
}

// Separable: 16 rows of 4 along x, then 4 along y, then z. OpenVDB's
// samplers (BoxSampler, QuadraticSampler) work on its sparse grids, not on
// our dense volumes; this is the one cubic we need, checked against a direct
// 64-tap sum in the tests.
void sample_tricubic(const Volume& vol, double x, double y, double z, float* out, Boundary b) {
  assert(!vol.empty());
  const int nc = vol.channels();
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    std::fill(out, out + nc, std::numeric_limits<float>::quiet_NaN());
    return;
  }
  const Taps tx = axis_taps(x, vol.nx(), b), ty = axis_taps(y, vol.ny(), b), tz = axis_taps(z, vol.nz(), b);
  double wx[4], wy[4], wz[4];
  catmull_rom(tx.w, wx);
  catmull_rom(ty.w, wy);
  catmull_rom(tz.w, wz);
  const float* d = vol.data();
  for (int c = 0; c < nc; ++c) {
    double sum = 0.0, lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < 4; ++k) {
      double plane = 0.0;
      for (int j = 0; j < 4; ++j) {
        double row = 0.0;
        for (int i = 0; i < 4; ++i) {
          const double v = d[vol.offset(tx.i[i], ty.i[j], tz.i[k]) + c];
          row += wx[i] * v;
          if (i >= 1 && i <= 2 && j >= 1 && j <= 2 && k >= 1 && k <= 2) lo = std::min(lo, v), hi = std::max(hi, v);
        }
        plane += wy[j] * row;
      }
      sum += wz[k] * plane;
    }
    out[c] = float(std::clamp(sum, lo, hi));
  }
}

void sample_volume_at(const Volume& vol, double x, double y, double z, float* out, Interpolation interp, Boundary b) {
  if (interp == Interpolation::Cubic)
    sample_tricubic(vol, x, y, z, out, b);
  else
    sample_trilinear(vol, x, y, z, out, b);
}

Volume resize_trilinear(const Volume& vol, int nx, int ny, int nz, Boundary b) {
  if (vol.empty()) throw InvalidInput("resize_trilinear: the input volume is empty");
  if (nx < 1 || ny < 1 || nz < 1) {
    throw InvalidInput("resize_trilinear: the new size must be at least 1 voxel on each axis");
  }
  const double rx = double(vol.nx()) / nx, ry = double(vol.ny()) / ny, rz = double(vol.nz()) / nz;
  // GridTransform is uniform, so only one axis can set the new voxel size;
  // x is used and voxel 0's centre stays where it was.
  GridTransform xf = vol.transform();
  xf.voxel_size *= rx;
  Volume out(nx, ny, nz, vol.channels(), 0.0f, xf);

  StageProgress none(nullptr, "resize", 0.0, 1.0, std::size_t(nz) * ny);
  const std::size_t rows = std::size_t(nz) * ny;
  const std::size_t grain = std::max<std::size_t>(1, 4096 / std::size_t(nx));
  parallel_chunks(rows, grain, none, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      const int z = int(r / ny), y = int(r % ny);
      for (int x = 0; x < nx; ++x) {
        sample_trilinear(vol, x * rx, y * ry, z * rz, &out.at(x, y, z, 0), b);
      }
    }
  });
  return out;
}

}  // namespace exsynth
