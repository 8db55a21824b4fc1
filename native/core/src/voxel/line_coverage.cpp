#include "voxel/line_coverage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace exsynth::voxel {

void accumulate_coverage(const std::vector<Crossing>& xs, int n, float weight, float* cov) {
  for (std::size_t i = 0; i < xs.size(); i += 2) {
    const double a = xs[i].t;
    const double b = i + 1 < xs.size() ? double(xs[i + 1].t) : std::numeric_limits<double>::infinity();
    const long k0 = std::max<long>(0, long(std::floor(a + 0.5)));
    const long k1 = std::min<long>(n - 1, std::isinf(b) ? n - 1 : long(std::floor(b + 0.5)));
    for (long k = k0; k <= k1; ++k) {
      const double overlap = std::min(b, k + 0.5) - std::max(a, k - 0.5);
      if (overlap > 0) cov[k] += weight * float(overlap);
    }
  }
}

void centre_parity(const std::vector<Crossing>& xs, int n, std::uint8_t* inside) {
  std::size_t next = 0;  // crossings strictly below the current centre
  for (int k = 0; k < n; ++k) {
    while (next < xs.size() && xs[next].t < float(k)) ++next;
    inside[k] = std::uint8_t(next & 1u);
  }
}

}  // namespace exsynth::voxel
