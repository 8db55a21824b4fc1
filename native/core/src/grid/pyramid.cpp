#include "exsynth/pyramid.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"

namespace exsynth {
namespace {

constexpr std::array<double, 5> kBinomial = {1.0 / 16, 4.0 / 16, 6.0 / 16, 4.0 / 16, 1.0 / 16};

int half_size(int n) { return (n + 1) / 2; }

int boundary_index(int i, int n, Boundary b) {
  if (b == Boundary::Wrap) {
    i %= n;
    return i < 0 ? i + n : i;
  }
  return std::clamp(i, 0, n - 1);
}

// Progress sub-range of one blur pass inside a whole job.
struct Span {
  ExecContext* ctx;
  double lo, hi;
};

// Blurs and decimates the middle axis of a dense array laid out as
// [outer][n][inner] (inner = the contiguous floats of one sample along the
// axis), giving [outer][ceil(n/2)][inner]. Working on whole contiguous lines
// makes the same code cache-friendly for every axis.
std::vector<float> reduce_axis(const std::vector<float>& in, std::size_t outer, int n,
                               std::size_t inner, Boundary b, const Span& span) {
  const int m = half_size(n);
  std::vector<float> out(outer * std::size_t(m) * inner);
  StageProgress progress(span.ctx, "pyramid", span.lo, span.hi, outer * std::size_t(m));
  const std::size_t grain = std::max<std::size_t>(1, 4096 / inner);
  parallel_chunks(outer * std::size_t(m), grain, progress, [&](std::size_t begin, std::size_t end) {
    std::vector<double> acc(inner);
    for (std::size_t line = begin; line < end; ++line) {
      const std::size_t o = line / std::size_t(m);
      const int j = int(line % std::size_t(m));
      std::fill(acc.begin(), acc.end(), 0.0);
      for (int k = 0; k < 5; ++k) {
        const int src = boundary_index(2 * j + k - 2, n, b);
        const float* s = in.data() + (o * std::size_t(n) + std::size_t(src)) * inner;
        const double w = kBinomial[k];
        for (std::size_t i = 0; i < inner; ++i) acc[i] += w * s[i];
      }
      float* d = out.data() + line * inner;
      for (std::size_t i = 0; i < inner; ++i) d[i] = float(acc[i]);
    }
  });
  return out;
}

Image downsample_impl(const Image& img, Boundary b, ExecContext* ctx, double lo, double hi) {
  if (img.empty()) throw InvalidInput("cannot downsample an empty image");
  const int w = img.width(), h = img.height(), c = img.channels();
  const int w2 = half_size(w), h2 = half_size(h);
  const double mid = lo + (hi - lo) * 0.5;
  std::vector<float> a = reduce_axis(img.values(), std::size_t(h), w, std::size_t(c), b, {ctx, lo, mid});
  std::vector<float> r = reduce_axis(a, 1, h, std::size_t(w2) * c, b, {ctx, mid, hi});
  Image out(w2, h2, c);
  out.values() = std::move(r);
  return out;
}

Volume downsample_impl(const Volume& vol, Boundary b, ExecContext* ctx, double lo, double hi) {
  if (vol.empty()) throw InvalidInput("cannot downsample an empty volume");
  const int nx = vol.nx(), ny = vol.ny(), nz = vol.nz(), c = vol.channels();
  const int nx2 = half_size(nx), ny2 = half_size(ny), nz2 = half_size(nz);
  // The x pass touches the most data; give each pass a share of the range
  // proportional to the floats it reads.
  const double wx = 1.0, wy = 0.5, wz = 0.25, sum = wx + wy + wz;
  const double t1 = lo + (hi - lo) * wx / sum, t2 = lo + (hi - lo) * (wx + wy) / sum;
  std::vector<float> a =
      reduce_axis(vol.values(), std::size_t(nz) * ny, nx, std::size_t(c), b, {ctx, lo, t1});
  std::vector<float> bb = reduce_axis(a, std::size_t(nz), ny, std::size_t(nx2) * c, b, {ctx, t1, t2});
  a.clear();
  a.shrink_to_fit();
  std::vector<float> r = reduce_axis(bb, 1, nz, std::size_t(nx2) * ny2 * c, b, {ctx, t2, hi});

  // Voxel 0's centre stays put; the spacing of the kept samples doubles.
  GridTransform xf = vol.transform();
  xf.voxel_size *= 2.0;
  Volume out(nx2, ny2, nz2, c, 0.0f, xf);
  out.values() = std::move(r);
  return out;
}

void check_levels(int levels) {
  if (levels < 1 || levels > kMaxPyramidLevels) {
    throw InvalidInput("pyramid 'levels' must be between 1 and " + std::to_string(kMaxPyramidLevels) + " (got " +
                       std::to_string(levels) + ")");
  }
}

// Progress ranges of the levels, weighted by the size of each level's input.
std::vector<double> level_bounds(std::vector<double> work) {
  std::vector<double> bounds{0.0};
  double total = 0.0;
  for (double w : work) total += w;
  double acc = 0.0;
  for (double w : work) {
    acc += w;
    bounds.push_back(total > 0 ? acc / total : 1.0);
  }
  return bounds;
}

}  // namespace

Image downsample(const Image& img, Boundary b) { return downsample_impl(img, b, nullptr, 0, 1); }

Volume downsample(const Volume& vol, Boundary b) { return downsample_impl(vol, b, nullptr, 0, 1); }

std::vector<Image> gaussian_pyramid(const Image& img, const PyramidOptions& opt, ExecContext* ctx) {
  check_levels(opt.levels);
  if (img.empty()) throw InvalidInput("cannot build a pyramid of an empty image");
  std::vector<double> work;
  for (int l = 1, w = img.width(), h = img.height(); l < opt.levels; ++l) {
    work.push_back(double(w) * h);
    w = half_size(w);
    h = half_size(h);
  }
  const std::vector<double> bounds = level_bounds(work);
  std::vector<Image> levels;
  levels.reserve(std::size_t(opt.levels));
  levels.push_back(img);
  for (int l = 1; l < opt.levels; ++l) {
    levels.push_back(downsample_impl(levels.back(), opt.boundary, ctx, bounds[l - 1], bounds[l]));
  }
  return levels;
}

std::vector<Volume> gaussian_pyramid(const Volume& vol, const PyramidOptions& opt, ExecContext* ctx) {
  return gaussian_pyramid(vol, opt, ctx, 0.0, 1.0);
}

std::vector<Volume> gaussian_pyramid(const Volume& vol, const PyramidOptions& opt, ExecContext* ctx, double lo,
                                     double hi) {
  check_levels(opt.levels);
  if (vol.empty()) throw InvalidInput("cannot build a pyramid of an empty volume");
  std::vector<double> work;
  for (int l = 1, x = vol.nx(), y = vol.ny(), z = vol.nz(); l < opt.levels; ++l) {
    work.push_back(double(x) * y * z);
    x = half_size(x);
    y = half_size(y);
    z = half_size(z);
  }
  const std::vector<double> bounds = level_bounds(work);
  std::vector<Volume> levels;
  levels.reserve(std::size_t(opt.levels));
  // Level 0 is a copy (a 384^3 one takes ~0.1 s): checked on both sides, so
  // the time before it (the caller's) and the copy count as separate gaps.
  if (ctx) ctx->check();
  levels.push_back(vol);
  if (ctx) ctx->check();
  for (int l = 1; l < opt.levels; ++l) {
    levels.push_back(downsample_impl(levels.back(), opt.boundary, ctx, lo + (hi - lo) * bounds[l - 1],
                                     lo + (hi - lo) * bounds[l]));
  }
  return levels;
}

}  // namespace exsynth
