// A dense separable blur and an exact rank histogram match. OpenVDB's
// filters (tools::Filter::gaussian) work on sparse grids with a background
// value and have no toroidal boundary, which tileable solids need, so the
// blur is written here: 7 taps at sigma = 1, one pass per axis over lines
// of a dense Volume.
#include "solid/structure_detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include <tbb/parallel_sort.h>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"

namespace exsynth::solid {
namespace {

std::vector<float> gaussian_kernel(double sigma) {
  const int radius = std::max(1, int(std::ceil(3.0 * sigma)));
  std::vector<float> k(2 * radius + 1);
  double sum = 0;
  for (int i = -radius; i <= radius; ++i) sum += std::exp(-0.5 * i * i / (sigma * sigma));
  for (int i = -radius; i <= radius; ++i) k[i + radius] = float(std::exp(-0.5 * i * i / (sigma * sigma)) / sum);
  return k;
}

int boundary_index(int i, int n, Boundary b) {
  if (b == Boundary::Wrap) return ((i % n) + n) % n;
  return std::clamp(i, 0, n - 1);
}

// One axis: lines of n voxels `step` voxels apart; line l starts at the
// voxel with the other two coordinates of l.
void blur_axis(Volume& v, int axis, const std::vector<float>& kernel, Boundary b, int channels,
               StageProgress& progress) {
  const int dims[3] = {v.nx(), v.ny(), v.nz()};
  const int n = dims[axis];
  if (n <= 1) return;
  const std::size_t step = axis == 0 ? 1 : axis == 1 ? std::size_t(v.nx()) : std::size_t(v.nx()) * v.ny();
  const std::size_t lines = v.voxel_count() / std::size_t(n);
  const int radius = int(kernel.size() / 2), stride = v.channels();
  parallel_chunks(lines, 256, progress, [&](std::size_t begin, std::size_t end) {
    std::vector<float> line(std::size_t(n) * channels);
    for (std::size_t l = begin; l < end; ++l) {
      // the line's first voxel: l enumerates the other two axes, lower first
      std::size_t start;
      if (axis == 0) start = l * std::size_t(n);
      else if (axis == 1) start = (l / v.nx()) * std::size_t(v.nx()) * v.ny() + l % v.nx();
      else start = l;
      float* base = v.data() + start * stride;
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < channels; ++c) line[std::size_t(i) * channels + c] = base[i * step * stride + c];
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < channels; ++c) {
          float acc = 0;
          for (int t = -radius; t <= radius; ++t)
            acc += kernel[t + radius] * line[std::size_t(boundary_index(i + t, n, b)) * channels + c];
          base[i * step * stride + c] = acc;
        }
    }
  });
}

}  // namespace

std::size_t blur_units(const Volume& v) {
  const int dims[3] = {v.nx(), v.ny(), v.nz()};
  std::size_t units = 0;
  for (int a = 0; a < 3; ++a)
    if (dims[a] > 1) units += v.voxel_count() / std::size_t(dims[a]);
  return units;
}

void gaussian_blur(Volume& v, double sigma, Boundary boundary, int channels, StageProgress& progress) {
  if (!(sigma > 0)) throw InvalidInput("the blur's sigma must be > 0, got " + std::to_string(sigma));
  const std::vector<float> kernel = gaussian_kernel(sigma);
  for (int axis = 0; axis < 3; ++axis) blur_axis(v, axis, kernel, boundary, channels, progress);
}

void match_histograms(Volume& v, int channels, const std::vector<const Image*>& images, StageProgress& progress) {
  const std::size_t voxels = v.voxel_count();
  if (voxels == 0) return;
  const int stride = v.channels();
  for (int c = 0; c < channels; ++c) {
    progress.check();
    std::vector<float> target;
    for (const Image* img : images)
      for (std::size_t p = 0; p < img->pixel_count(); ++p) target.push_back(img->data()[p * img->channels() + c]);
    if (target.empty()) throw InvalidInput("histogram matching needs an exemplar with pixels");
    tbb::parallel_sort(target.begin(), target.end());
    // (value, voxel): a total order, so the parallel sort's result is unique
    std::vector<std::pair<float, std::uint32_t>> order(voxels);
    for (std::size_t i = 0; i < voxels; ++i) order[i] = {v.data()[i * stride + c], std::uint32_t(i)};
    tbb::parallel_sort(order.begin(), order.end());
    const double m = double(target.size()), n = double(voxels);
    for (std::size_t r = 0; r < voxels; ++r) {
      const std::size_t q = std::min(target.size() - 1, std::size_t((double(r) + 0.5) * m / n));
      v.data()[std::size_t(order[r].second) * stride + c] = target[q];
    }
    progress.advance();
  }
}

std::size_t split_units(const Volume& v, int channels) { return 2 * blur_units(v) + std::size_t(channels); }

void split_structure_detail(Volume& values, Volume&& mean, double sigma, Boundary boundary, int channels,
                            const std::vector<const Image*>& images, StageProgress& progress) {
  Volume detail = values;
  gaussian_blur(mean, sigma, boundary, channels, progress);
  gaussian_blur(detail, sigma, boundary, channels, progress);
  const int stride = values.channels();
  for (std::size_t i = 0; i < values.voxel_count(); ++i)
    for (int c = 0; c < channels; ++c) {
      const std::size_t k = i * stride + c;
      values.data()[k] = mean.data()[k] + values.data()[k] - detail.data()[k];
    }
  match_histograms(values, channels, images, progress);
}

}  // namespace exsynth::solid
