#include "voxel/distance_transform.hpp"

#include <limits>

#include "exsynth/parallel.hpp"

namespace exsynth::voxel {

void distance_transform_1d(const float* f, const std::int32_t* lab, int n, float* d, std::int32_t* out_lab,
                           int* v, double* g, double* z) {
  // Lower envelope of the parabolas (q - p)^2 + f[p] over the seeds p.
  // g[k] = f[v[k]] + v[k]^2 is kept per envelope vertex so the intersection
  // needs one subtraction and one division. Doubles: values reach 3 * n^2.
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFarAway) continue;
    const double fq = double(f[q]) + double(q) * q;
    if (k < 0) {
      k = 0;
      v[0] = q;
      g[0] = fq;
      z[0] = -std::numeric_limits<double>::infinity();
      z[1] = std::numeric_limits<double>::infinity();
      continue;
    }
    double s;
    for (;;) {
      s = (fq - g[k]) / (2.0 * (q - v[k]));
      if (s <= z[k]) {
        --k;  // z[0] = -inf keeps k >= 0
      } else {
        break;
      }
    }
    ++k;
    v[k] = q;
    g[k] = fq;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) {
      d[q] = kFarAway;
      out_lab[q] = -1;
    }
    return;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const int p = v[k];
    d[q] = float(double(q - p) * (q - p) + f[p]);
    out_lab[q] = lab[p];
  }
}

namespace {

// One pass along an axis with stride `stride` over lines of length n; the
// lines are enumerated by (a, b) with base offset a * sa + b * sb.
void pass(int n, std::size_t stride, int na, std::size_t sa, int nb, std::size_t sb, std::vector<float>& dist2,
          std::vector<std::int32_t>& label, StageProgress& progress) {
  parallel_chunks(std::size_t(na) * nb, 64, progress, [&](std::size_t begin, std::size_t end) {
    std::vector<float> f(n), d(n);
    std::vector<std::int32_t> lab(n), out_lab(n);
    std::vector<int> v(n);
    std::vector<double> g(n), z(n + 1);
    for (std::size_t line = begin; line < end; ++line) {
      const std::size_t base = (line % na) * sa + (line / na) * sb;
      for (int i = 0; i < n; ++i) {
        f[i] = dist2[base + i * stride];
        lab[i] = label[base + i * stride];
      }
      distance_transform_1d(f.data(), lab.data(), n, d.data(), out_lab.data(), v.data(), g.data(), z.data());
      for (int i = 0; i < n; ++i) {
        dist2[base + i * stride] = d[i];
        label[base + i * stride] = out_lab[i];
      }
    }
  });
}

}  // namespace

void distance_transform(int nx, int ny, int nz, std::vector<float>& dist2, std::vector<std::int32_t>& label,
                        StageProgress& progress) {
  const std::size_t sx = 1, sy = std::size_t(nx), sz = std::size_t(nx) * ny;
  pass(nx, sx, ny, sy, nz, sz, dist2, label, progress);  // rows along x
  pass(ny, sy, nx, sx, nz, sz, dist2, label, progress);  // columns along y
  pass(nz, sz, nx, sx, ny, sy, dist2, label, progress);  // pillars along z
}

}  // namespace exsynth::voxel
