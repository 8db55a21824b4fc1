// Built-in exemplar pairs: analytic signed distances sampled on a grid.
#include "exsynth/pairs.hpp"
#include "exsynth/format.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"

namespace exsynth {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfExtent = 1.0;  // the grid spans [-1, 1]^3
constexpr double kRoom = 0.9;        // shapes stay inside |coordinate| <= 0.9, away from the grid's faces

// ---- validation -------------------------------------------------------------

void require(bool ok, const std::string& message) {
  if (!ok) throw InvalidInput(message);
}

std::string num(double v) { return format_number(v); }

void require_positive(double v, const char* name) {
  require(std::isfinite(v) && v > 0, std::string(name) + " must be a finite number > 0, got " + num(v));
}

}  // namespace

void validate_pair_options(PairPreset preset, const PairOptions& o) {
  require(o.resolution >= 8 && o.resolution <= 512,
          "resolution must be in 8..512 (voxels per grid edge), got " + std::to_string(o.resolution));
  require_positive(o.thickness, "thickness");
  require_positive(o.spacing, "spacing");
  require_positive(o.feature_radius, "feature_radius");
  require_positive(o.feature_height, "feature_height");
  require_positive(o.cylinder_radius, "cylinder_radius");
  require_positive(o.sphere_radius, "sphere_radius");
  require_positive(o.dilation, "dilation");
  require(std::isfinite(o.jitter) && o.jitter >= 0 && o.jitter <= 0.25,
          "jitter must be in 0..0.25 (a fraction of spacing), got " + num(o.jitter));
  require(o.feature_radius < 0.5 * o.spacing,
          "feature_radius (" + num(o.feature_radius) + ") must be less than half the spacing (" + num(o.spacing) +
              "); lower feature_radius or raise spacing");
  switch (preset) {
    case PairPreset::Spikes:
    case PairPreset::Pits:
    case PairPreset::Holes:
      require(0.5 * o.thickness <= kRoom,
              "thickness (" + num(o.thickness) + ") must be at most " + num(2 * kRoom) +
                  " to fit the grid, which spans -1..1; lower thickness");
      break;
    default:
      break;
  }
  if (preset == PairPreset::Spikes)
    require(0.5 * o.thickness + o.feature_height <= kRoom,
            "feature_height (" + num(o.feature_height) + ") plus half the thickness (" + num(0.5 * o.thickness) +
                ") must be at most " + num(kRoom) + " so the spikes fit the grid; lower feature_height or thickness");
  if (preset == PairPreset::Pits)
    require(o.feature_radius < o.thickness,
            "feature_radius (" + num(o.feature_radius) + ") must be less than the thickness (" + num(o.thickness) +
                ") or the pits pierce the slab; lower feature_radius or raise thickness (or use the holes preset)");
  if (preset == PairPreset::Grooves) {
    require(o.cylinder_radius <= kRoom,
            "cylinder_radius (" + num(o.cylinder_radius) + ") must be at most " + num(kRoom) +
                " to fit the grid, which spans -1..1; lower cylinder_radius");
    require(o.feature_radius < 0.5 * o.cylinder_radius,
            "feature_radius (" + num(o.feature_radius) + ") must be less than half the cylinder_radius (" +
                num(o.cylinder_radius) + "); lower feature_radius or raise cylinder_radius");
  }
  if (preset == PairPreset::Dilate)
    require(o.sphere_radius + o.dilation <= kRoom,
            "sphere_radius + dilation (" + num(o.sphere_radius + o.dilation) + ") must be at most " + num(kRoom) +
                " so the dilated sphere fits the grid; lower sphere_radius or dilation");
}

namespace {

// ---- primitives (exact signed distances) -------------------------------------

// Distance from (u, v) to the segment (a, b) in the plane.
double segment_distance(double u, double v, double au, double av, double bu, double bv) {
  const double eu = bu - au, ev = bv - av, wu = u - au, wv = v - av;
  const double t = std::clamp((wu * eu + wv * ev) / (eu * eu + ev * ev), 0.0, 1.0);
  return std::hypot(wu - t * eu, wv - t * ev);
}

// Solid cone around a vertical axis: base disk of radius `base` at height 0
// (relative), apex at height `apex`; q = distance from the axis, z = height.
// A solid of revolution's distance is its profile's distance in (q, z).
double cone_sdf(double q, double z, double base, double apex) {
  const double d = std::min(segment_distance(q, z, base, 0, 0, apex), segment_distance(q, z, 0, 0, base, 0));
  const bool inside = z >= 0 && z <= apex && q <= base * (apex - z) / apex;
  return inside ? -d : d;
}

// ---- the shapes ---------------------------------------------------------------

struct Shapes {
  PairPreset preset;
  PairOptions o;

  // Centre of the slab feature in lattice cell (i, j), jittered by (seed, cell).
  std::array<double, 2> feature_centre(long i, long j) const {
    std::array<double, 2> c{(double(i) + 0.5) * o.spacing, (double(j) + 0.5) * o.spacing};
    if (o.jitter > 0) {
      const std::uint64_t key = (std::uint64_t(i + (1l << 30)) << 32) ^ std::uint64_t(j + (1l << 30));
      IndexRng rng(o.seed, key);
      c[0] += o.jitter * o.spacing * (2 * rng.uniform() - 1);
      c[1] += o.jitter * o.spacing * (2 * rng.uniform() - 1);
    }
    return c;
  }

  // Slab features: a feature reaches at most (jitter + 1/2) spacing < 1
  // spacing from its cell's centre, so the 3 x 3 cells around a point hold
  // every feature that can touch it.
  template <class Fn>
  double min_over_features(double x, double y, Fn&& fn) const {
    const long ci = long(std::floor(x / o.spacing)), cj = long(std::floor(y / o.spacing));
    double best = INFINITY;
    for (long j = cj - 1; j <= cj + 1; ++j)
      for (long i = ci - 1; i <= ci + 1; ++i) {
        const auto c = feature_centre(i, j);
        best = std::min(best, fn(std::hypot(x - c[0], y - c[1])));
      }
    return best;
  }

  // A and A' at one point, and the field there.
  void eval(double x, double y, double z, float& a, float& ap, float t[3]) const {
    const double half = 0.5 * o.thickness, r = o.feature_radius;
    t[0] = 1, t[1] = 0, t[2] = 0;
    switch (preset) {
      case PairPreset::Spikes: {
        const double slab = std::abs(z) - half;
        // The cone continues down to the slab's centre (inside the slab) so
        // its base leaves no internal surface near the top.
        const double apex = half + o.feature_height, base = r * apex / o.feature_height;
        const double cones = min_over_features(x, y, [&](double q) { return cone_sdf(q, z, base, apex); });
        a = float(slab), ap = float(std::min(slab, cones));
        break;
      }
      case PairPreset::Pits: {
        const double slab = std::abs(z) - half, dz = z - half;
        const double spheres = min_over_features(x, y, [&](double q) { return std::hypot(q, dz) - r; });
        a = float(slab), ap = float(std::max(slab, -spheres));
        break;
      }
      case PairPreset::Holes: {
        const double slab = std::abs(z) - half;
        const double cylinders = min_over_features(x, y, [&](double q) { return q - r; });
        a = float(slab), ap = float(std::max(slab, -cylinders));
        break;
      }
      case PairPreset::Grooves: {
        const double q = std::hypot(x, y), R = o.cylinder_radius;
        const double cyl = q - R;
        double groove;
        if (o.groove_direction == GrooveDirection::Around) {
          // Rings (tori of tube radius r on the surface) at z = (k + 1/2) spacing.
          const double zk = (std::floor(z / o.spacing) + 0.5) * o.spacing;
          groove = std::hypot(q - R, z - zk) - r;
          if (q > 1e-12) t[0] = float(-y / q), t[1] = float(x / q);
        } else {
          // n straight tubes on the surface at angles (k + 1/2) 2 pi / n.
          const int n = groove_count();
          const double step = 2 * kPi / n;
          const double angle = (std::floor(std::atan2(y, x) / step) + 0.5) * step;
          groove = std::hypot(x - R * std::cos(angle), y - R * std::sin(angle)) - r;
          t[0] = 0, t[2] = 1;
        }
        a = float(cyl), ap = float(std::max(cyl, -groove));
        break;
      }
      case PairPreset::Dilate: {
        const double d = std::sqrt(x * x + y * y + z * z);
        a = float(d - o.sphere_radius), ap = float(d - (o.sphere_radius + o.dilation));
        break;
      }
    }
  }

  // Along grooves: as many as fit around the circumference at `spacing`.
  int groove_count() const {
    return std::max(3, int(std::lround(2 * kPi * o.cylinder_radius / o.spacing)));
  }
};

}  // namespace

int resolution_for_pattern(int resolution, double pattern_scale) {
  if (resolution < 1) throw InvalidInput("resolution must be at least 1 voxel, got " + std::to_string(resolution));
  if (!(pattern_scale > 0) || !std::isfinite(pattern_scale))
    throw InvalidInput("pattern_scale must be a positive fraction of B's longest side, got " +
                       std::to_string(pattern_scale));
  if (std::lround(pattern_scale * resolution) >= kPairDetailResolution) return resolution;
  // The least r with round(pattern_scale * r) >= kPairDetailResolution,
  // from the estimate, stepped to the exact rounding.
  const int top = std::max(resolution, kMaxPatternResolution);
  const double need = std::ceil((kPairDetailResolution - 0.5) / pattern_scale);
  int r = int(std::clamp(need, double(resolution), double(top)));
  while (r < top && std::lround(pattern_scale * r) < kPairDetailResolution) ++r;
  while (r > resolution && std::lround(pattern_scale * (r - 1)) >= kPairDetailResolution) --r;
  return r;
}

const char* pair_preset_name(PairPreset preset) {
  switch (preset) {
    case PairPreset::Spikes: return "spikes";
    case PairPreset::Pits: return "pits";
    case PairPreset::Holes: return "holes";
    case PairPreset::Grooves: return "grooves";
    case PairPreset::Dilate: return "dilate";
  }
  return "?";
}

ExemplarPair make_exemplar_pair(PairPreset preset, const PairOptions& opt, ExecContext* ctx) {
  validate_pair_options(preset, opt);
  const int n = opt.resolution;
  const double voxels = double(n) * n * n;
  check_memory_budget(voxels * 5 * sizeof(float), opt.memory_budget,
                      std::string("the ") + pair_preset_name(preset) + " exemplar pair at resolution " + std::to_string(n),
                      "lower resolution or raise memory_budget");

  const double h = 2 * kHalfExtent / n;
  GridTransform xform;
  xform.voxel_size = h;
  xform.origin = {-kHalfExtent + 0.5 * h, -kHalfExtent + 0.5 * h, -kHalfExtent + 0.5 * h};

  StageProgress progress(ctx, std::string("exemplar pair (") + pair_preset_name(preset) + ")", 0.0, 1.0, std::size_t(n));
  ExemplarPair pair;
  pair.a = Volume(n, n, n, 1, 0.0f, xform);
  pair.a_prime = Volume(n, n, n, 1, 0.0f, xform);
  pair.field_a = Volume(n, n, n, 3, 0.0f, xform);

  const Shapes shapes{preset, opt};
  parallel_chunks(std::size_t(n), 1, progress, [&](std::size_t z0, std::size_t z1) {
    for (int z = int(z0); z < int(z1); ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const auto p = xform.index_to_world(x, y, z);
          float* t = &pair.field_a.at(x, y, z, 0);
          shapes.eval(p[0], p[1], p[2], pair.a.at(x, y, z), pair.a_prime.at(x, y, z), t);
        }
  });
  progress.check();
  return pair;
}

}  // namespace exsynth
