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

}  // namespace

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
