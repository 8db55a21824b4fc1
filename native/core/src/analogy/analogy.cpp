// Public entry points of the volume analogy: every bad input named with its
// fix and the memory budget checked before any work, then the solver.
#include "exsynth/analogy.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "analogy/features.hpp"
#include "analogy/solver.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {
namespace {

using namespace analogy;

void check_volume(const Volume& v, const char* name) {
  if (v.empty()) throw InvalidInput(std::string(name) + " is empty; give a volume with at least one voxel");
  if (v.channels() != 1)
    throw InvalidInput(std::string(name) + " must have 1 channel (a signed distance or density), got " +
                       std::to_string(v.channels()));
  for (float x : v.values())
    if (!std::isfinite(x)) throw InvalidInput(std::string(name) + " has a non-finite value; fix the volume first");
}

std::string size_of(const Volume& v) {
  return std::to_string(v.nx()) + "x" + std::to_string(v.ny()) + "x" + std::to_string(v.nz());
}

// A field must match its volume's grid and be a usable direction wherever
// the pattern will be synthesized: near the surface.
void check_field(const Volume& field, const Volume& sdf, const char* name, const char* volume_name) {
  if (field.channels() != 3 || field.nx() != sdf.nx() || field.ny() != sdf.ny() || field.nz() != sdf.nz())
    throw InvalidInput(std::string(name) + " must have 3 channels on " + volume_name + "'s grid (" + size_of(sdf) +
                       "), got " + size_of(field) + " with " + std::to_string(field.channels()) + " channels");
  const float near = float(2.0 * sdf.transform().voxel_size);
  std::size_t bad = 0, surface = 0;
  for (std::size_t i = 0; i < sdf.voxel_count(); ++i) {
    if (std::abs(sdf.data()[i]) > near) continue;
    ++surface;
    const float* t = field.data() + 3 * i;
    if (!std::isfinite(t[0]) || !std::isfinite(t[1]) || !std::isfinite(t[2]) ||
        t[0] * t[0] + t[1] * t[1] + t[2] * t[2] < 1e-12f)
      ++bad;
  }
  if (bad)
    throw InvalidInput(std::string(name) + " is zero or not finite at " + std::to_string(bad) + " of the " +
                       std::to_string(surface) + " voxels near " + volume_name +
                       "'s surface; give a direction at every surface point (or use a field preset)");
}

// Every bad input named with its fix, before any work.
void validate(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b, const Volume* field_b,
              const AnalogyOptions& opt) {
  check_volume(a, "A");
  check_volume(a_prime, "A'");
  check_volume(b, "B");
  if (a.nx() != a_prime.nx() || a.ny() != a_prime.ny() || a.nz() != a_prime.nz())
    throw InvalidInput("A and A' must have the same size, got " + size_of(a) + " and " + size_of(a_prime) +
                       "; voxelize both on the same grid");
  using Lim = AnalogyLimits;
  auto range = [](const char* name, int v, int lo, int hi, bool odd) {
    if (v < lo || v > hi || (odd && v % 2 == 0))
      throw InvalidInput(std::string(name) + " must be " + (odd ? "odd, " : "") + "between " + std::to_string(lo) +
                         " and " + std::to_string(hi) + ", got " + std::to_string(v));
  };
  range("levels", opt.levels, 1, Lim::max_levels, false);
  range("fine_size", opt.fine_size, Lim::min_fine_size, Lim::max_fine_size, true);
  range("coarse_size", opt.coarse_size, Lim::min_coarse_size, Lim::max_coarse_size, true);
  range("sweeps", opt.sweeps, 1, Lim::max_sweeps, false);
  range("max_pca_dims", opt.max_pca_dims, 1, Lim::max_pca_dims, false);
  if (!(opt.pca_variance > 0 && opt.pca_variance <= 1))
    throw InvalidInput("pca_variance must be in (0, 1], got " + std::to_string(opt.pca_variance));
  if (!(opt.ann_eps >= 0) || !std::isfinite(opt.ann_eps))
    throw InvalidInput("ann_eps must be a finite number >= 0, got " + std::to_string(opt.ann_eps));
  if (!(opt.coherence >= 0) || !(opt.coherence_slack >= 0) || !std::isfinite(opt.coherence) ||
      !std::isfinite(opt.coherence_slack))
    throw InvalidInput("coherence and coherence_slack must be finite numbers >= 0");
  if (!std::isfinite(opt.cull_distance)) throw InvalidInput("cull_distance must be finite (< 0 = automatic, 0 = off)");
  if (b.voxel_count() >= std::size_t(std::numeric_limits<std::uint32_t>::max()) ||
      a.voxel_count() >= std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw InvalidInput("A or B has too many voxels (limit 2^31); use a lower resolution");
  if (!opt.a_region.empty() && (opt.a_region.channels() != 1 || opt.a_region.nx() != a.nx() ||
                                 opt.a_region.ny() != a.ny() || opt.a_region.nz() != a.nz()))
    throw InvalidInput("a_region must have 1 channel on A's grid (" + size_of(a) + "), got " + size_of(opt.a_region) +
                       " with " + std::to_string(opt.a_region.channels()) + " channels");
  if (field_a) {
    check_field(*field_a, a, "field_a", "A");
    check_field(*field_b, b, "field_b", "B");
  }
}

AnalogyResult run(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b,
                  const Volume* field_b, const AnalogyOptions& opt, ExecContext* ctx) {
  validate(a, a_prime, field_a, b, field_b, opt);
  const Neighbourhoods hood = make_neighbourhoods(opt.fine_size, opt.coarse_size, field_a == nullptr);
  // Peak: A's database (features, coefficients, frames), the pyramids, and
  // per-B-voxel bookkeeping (B', sources, static projections of the band).
  check_memory_budget(double(a.voxel_count()) * (hood.dims(opt.levels > 1) + 2.0 * opt.max_pca_dims + 9) * 4.0 * 1.2 +
                          double(a.voxel_count() * 2 + b.voxel_count() * 4) * 4.0 * 8.0 / 7.0 +
                          double(b.voxel_count()) * 4.0 * 3.0,
                      opt.memory_budget, "the analogy of a " + size_of(a) + " exemplar onto a " + size_of(b) + " volume",
                      "use a lower resolution or raise the memory budget");
  return AnalogySolver(a, a_prime, field_a, b, field_b, opt, ctx).run();
}

}  // namespace

int analogy_padding(int fine_size, int coarse_size) { return fine_size / 2 + 2 * (coarse_size / 2); }

AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& b, const AnalogyOptions& opt,
                                 ExecContext* ctx) {
  return run(a, a_prime, nullptr, b, nullptr, opt, ctx);
}

AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& field_a, const Volume& b,
                                 const Volume& field_b, const AnalogyOptions& opt, ExecContext* ctx) {
  return run(a, a_prime, &field_a, b, &field_b, opt, ctx);
}

}  // namespace exsynth
