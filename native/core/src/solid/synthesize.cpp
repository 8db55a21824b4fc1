// The coarse-to-fine driver shared by solids (three views) and images (one
// view on a one-voxel-thick volume), and their validation.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <array>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/pyramid.hpp"
#include "image/coordinate_synthesis.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/sample.hpp"
#include "exsynth/solid.hpp"
#include "solid/coordinate_synthesis.hpp"
#include "solid/exemplar_index.hpp"
#include "solid/exemplar_rotations.hpp"
#include "solid/feature_channel.hpp"
#include "solid/level_solver.hpp"
#include "solid/structure_detail.hpp"

namespace exsynth {
namespace {

const char* kViewName[3] = {"x", "y", "z"};

void check_options(const TextureOptimizationOptions& o) {
  auto range = [](const char* name, double v, double lo, double hi, const char* hint) {
    if (!(v >= lo && v <= hi))
      throw InvalidInput(std::string(name) + " must be between " + std::to_string(lo).substr(0, 6) + " and " +
                         std::to_string(hi).substr(0, 8) + ", got " + std::to_string(v) + hint);
  };
  range("levels", o.levels, 1, kMaxLevels, "");
  range("neighborhood", o.neighborhood, 3, 32, " (the paper uses 8)");
  range("iterations", o.iterations, 1, kMaxIterations, "");
  range("finest_iterations", o.finest_iterations, -1, 100, " (0 = iterations, -1 = by size)");
  if (!(o.r > 0 && o.r <= 2)) throw InvalidInput("r must be in (0, 2], got " + std::to_string(o.r) + " (the paper uses 0.8)");
  if (!(o.pca_variance > 0 && o.pca_variance <= 1))
    throw InvalidInput("pca_variance must be in (0, 1], got " + std::to_string(o.pca_variance));
  range("max_pca_dims", o.max_pca_dims, 1, 4096, "");
  range("coherence_k", o.coherence_k, 0, 64, "");
  range("random_candidates", o.random_candidates, 0, 64, "");
  range("ann_eps", o.ann_eps, 0, 1e6, "");
  range("histogram_bins", o.histogram_bins, 2, 256, "");
  range("histogram_strength", o.histogram_strength, 0, 16, " (1 = the gentle weighting, 3 = default)");
  range("feature_weight", o.feature_weight, 0, 100, " (0 = off)");
  range("feature_threshold", o.feature_threshold, 0, kMaxFeatureThreshold, " (0 = darker than the window's mean at all)");
  range("feature_scale", o.feature_scale, 0, kMaxFeatureScale, " pixels (0 = the neighbourhood's edge)");
  range("histogram_values", o.histogram_values, 0, 100, " (0 = off)");
  range("histogram_value_rounds", o.histogram_value_rounds, 1, 64, "");
  range("histogram_value_window", o.histogram_value_window, 0, 1, " (0 = each texel's own price)");
  range("structure_sigma", o.structure_sigma, 0, kMaxStructureSigma, " voxels (0 = off)");
  if (o.max_exemplar_size != 0) range("max_exemplar_size", o.max_exemplar_size, o.neighborhood, 1 << 16, " pixels (0 = full resolution)");
}

/// Output edges follow one rule, min_texture_size .. max (see solid.hpp).
void check_edge(const std::string& what, int value, int max, const TextureOptimizationOptions& o, const char* unit) {
  check_options(o);
  const int lo = min_texture_size(o.levels, o.neighborhood);
  if (value >= lo && value <= max) return;
  std::string msg = what + " must be between " + std::to_string(lo) + " and " + std::to_string(max) + " " + unit +
                    " with " + std::to_string(o.levels) + " level" + (o.levels == 1 ? "" : "s") + " and " +
                    std::to_string(o.neighborhood) + "x" + std::to_string(o.neighborhood) + " neighbourhoods, got " +
                    std::to_string(value);
  if (value < lo)
    msg += "; use a larger size" + std::string(o.levels > 1 ? " or fewer levels (1 level allows from " +
                                                                  std::to_string(o.neighborhood) + ")"
                                                            : " or a smaller neighbourhood");
  throw InvalidInput(msg);
}

struct Dims {
  int d[3];
  std::size_t voxels() const { return std::size_t(d[0]) * d[1] * d[2]; }
};

// The finest level's rounds (finest_iterations: > 0 as given, 0 = iterations,
// -1 = by the level's size).
int finest_rounds(const TextureOptimizationOptions& opt, const Dims& finest) {
  if (opt.finest_iterations > 0) return opt.finest_iterations;
  const int edge = std::max({finest.d[0], finest.d[1], finest.d[2]});
  if (opt.finest_iterations < 0 && edge >= kAutoFinestFrom) return std::min(kAutoFinestIterations, opt.iterations);
  return opt.iterations;
}

/// Level sizes, coarsest first; each level halves (rounding up) like the pyramids.
std::vector<Dims> level_dims(Dims finest, int levels) {
  std::vector<Dims> out(levels);
  out[levels - 1] = finest;
  for (int l = levels - 2; l >= 0; --l)
    for (int a = 0; a < 3; ++a) out[l].d[a] = (out[l + 1].d[a] + 1) / 2;
  return out;
}

void check_exemplar(const Image& img, const std::string& what) {
  if (img.width() < 1 || img.height() < 1 || img.channels() < 1)
    throw InvalidInput(what + " is empty; give an image with at least one pixel and one channel");
  for (std::size_t i = 0; i < img.values().size(); ++i)
    if (!std::isfinite(img.values()[i])) {
      const std::size_t p = i / img.channels();
      throw InvalidInput(what + " has a non-finite value (NaN or Inf) at pixel (" + std::to_string(p % img.width()) +
                         ", " + std::to_string(p / img.width()) + "); fix or clamp the image first");
    }
}

/// Power of two e such that the exemplars' and the constraint targets'
/// largest magnitude times 2^-e lies in [1, 2); 0 when it is already in
/// [1/16, 16] (ordinary colours: untouched). Non-finite values are skipped
/// (they are refused elsewhere).
int value_exponent(const std::vector<const Image*>& images, const Volume* constraint, int channels) {
  float max_abs = 0.0f;
  for (const Image* img : images)
    for (float v : img->values())
      if (std::isfinite(v)) max_abs = std::max(max_abs, std::abs(v));
  if (constraint && !constraint->empty() && constraint->channels() == channels + 1)
    for (std::size_t i = 0; i < constraint->values().size(); ++i)
      if (i % (channels + 1) != std::size_t(channels) && std::isfinite(constraint->values()[i]))
        max_abs = std::max(max_abs, std::abs(constraint->values()[i]));
  if (max_abs == 0.0f || (max_abs >= 1.0f / 16 && max_abs <= 16.0f)) return 0;
  return std::ilogb(max_abs);
}

struct Job {
  Dims finest;
  std::array<const Image*, 3> views{};  // nullptr = inactive view
  const Volume* constraint = nullptr;
  std::string name;                      // "solid" or "image", for stages and messages
};

// The job's exemplars as the optimiser reads them: each distinct exemplar
// once (views may share one), at its working resolution, value-scaled, with
// the feature channel appended. `images` points into the owned vectors, which
// are reserved up front and never reallocate; so the struct stays put.
struct PreparedExemplars {
  std::vector<const Image*> images;
  std::vector<std::string> names;           // per image: "the exemplar for view z", for messages
  std::vector<std::array<int, 2>> given;    // per image: its size as given (before max_exemplar_size)
  std::array<int, 3> image_of{-1, -1, -1};  // per view: index into images, -1 = inactive
  int user_channels = 0, channels = 0;      // channels counts the feature channel
  int exponent = 0;                         // values were scaled by 2^-exponent
  const Volume* constraint = nullptr;       // the job's, scaled like the exemplars
  std::vector<Image> working, scaled, featured, rotated;
  std::vector<bool> turned;                 // per image: used in its quarter turns (rotate_exemplar)
  Volume scaled_constraint;

  PreparedExemplars() = default;
  PreparedExemplars(const PreparedExemplars&) = delete;
  PreparedExemplars& operator=(const PreparedExemplars&) = delete;
};

void distinct_exemplars(const Job& job, PreparedExemplars& p) {
  int channels = -1;
  for (int i = 0; i < 3; ++i) {
    if (!job.views[i]) continue;
    auto it = std::find(p.images.begin(), p.images.end(), job.views[i]);
    if (it == p.images.end()) {
      const std::string what = job.name == "image" ? "the exemplar" : std::string("the exemplar for view ") + kViewName[i];
      check_exemplar(*job.views[i], what);
      if (channels >= 0 && job.views[i]->channels() != channels)
        throw InvalidInput("the exemplars have different channel counts (" + std::to_string(channels) + " and " +
                           std::to_string(job.views[i]->channels()) + "); give every view the same channels");
      channels = job.views[i]->channels();
      p.images.push_back(job.views[i]);
      p.names.push_back(what);
      p.given.push_back({job.views[i]->width(), job.views[i]->height()});
      it = p.images.end() - 1;
    }
    p.image_of[i] = int(it - p.images.begin());
  }
  if (p.images.empty()) throw InvalidInput("no exemplar: give at least one exemplar image and one active view");
  p.user_channels = p.channels = channels;
}

void prepare_exemplars(const Job& job, const TextureOptimizationOptions& opt, PreparedExemplars& p) {
  // Working resolution: large exemplars are analysed at a reduced size.
  p.working.reserve(p.images.size());
  for (const Image*& img : p.images)
    if (opt.max_exemplar_size > 0 && std::max(img->width(), img->height()) > opt.max_exemplar_size) {
      Image w = downsample(*img, Boundary::Clamp);
      while (std::max(w.width(), w.height()) > opt.max_exemplar_size) w = downsample(w, Boundary::Clamp);
      p.working.push_back(std::move(w));
      img = &p.working.back();
    }

  // Value scale: distances are squared in float, so values near 1e18 and
  // above overflow (and below 1e-18 underflow). Exemplars (and constraint
  // targets) outside [1/16, 16] in magnitude are scaled by a power of two,
  // which is exact and leaves the optimisation unchanged, and the result is
  // scaled back: any finite input works.
  p.exponent = value_exponent(p.images, job.constraint, p.channels);
  const float scale = std::ldexp(1.0f, -p.exponent);
  const bool constrained = job.constraint && !job.constraint->empty();
  p.constraint = job.constraint;
  if (p.exponent != 0) {
    p.scaled.reserve(p.images.size());
    for (const Image*& img : p.images) {
      p.scaled.push_back(*img);
      for (float& v : p.scaled.back().values()) v *= scale;
      img = &p.scaled.back();
    }
    if (constrained) {
      p.scaled_constraint = *job.constraint;
      const std::size_t cc = std::size_t(p.scaled_constraint.channels());
      for (std::size_t i = 0; i < p.scaled_constraint.values().size(); ++i)
        if (i % cc != cc - 1) p.scaled_constraint.values()[i] *= scale;  // the last channel is a weight
      p.constraint = &p.scaled_constraint;
    }
  }
  // Which exemplars take their quarter turns: decided on the exemplar's own
  // channels, before the feature channel joins them.
  p.turned.assign(p.images.size(), opt.rotate_exemplar == RotateExemplar::On);
  if (opt.rotate_exemplar == RotateExemplar::Auto)
    for (std::size_t e = 0; e < p.images.size(); ++e)
      p.turned[e] = exemplar_feature_stretch(*p.images[e]) < kRoundFeatureStretch;
  // The feature-distance channel, appended after the exemplar's channels: the
  // constraint's targets (the exemplar's channels) leave it free.
  if (opt.feature_weight > 0) {
    const int scale = opt.feature_scale > 0 ? opt.feature_scale : opt.neighborhood;
    p.featured.reserve(p.images.size());
    for (const Image* img : p.images)
      p.featured.push_back(solid::with_feature_channel(*img, float(opt.feature_weight), scale, opt.feature_threshold));
    for (std::size_t e = 0; e < p.images.size(); ++e) p.images[e] = &p.featured[e];
    ++p.channels;
  }
  // Last, so the feature channel is the one of the whole exemplar, turned
  // with it (its square window and Euclidean distances turn exactly).
  p.rotated.reserve(p.images.size());
  for (std::size_t e = 0; e < p.images.size(); ++e)
    if (p.turned[e]) {
      p.rotated.push_back(solid::quarter_turn_mosaic(*p.images[e]));
      p.images[e] = &p.rotated.back();
    }
}

void check_constraint(const Job& job, int channels) {
  if (!job.constraint || job.constraint->empty()) return;
  const Volume& c = *job.constraint;
  if (c.nx() != job.finest.d[0] || c.ny() != job.finest.d[1] || c.nz() != job.finest.d[2] || c.channels() != channels + 1)
    throw InvalidInput("the constraint volume must be " + std::to_string(job.finest.d[0]) + "x" + std::to_string(job.finest.d[1]) +
                       "x" + std::to_string(job.finest.d[2]) + " voxels with " + std::to_string(channels + 1) +
                       " channels (the exemplar's " + std::to_string(channels) + " target values, then a weight), got " +
                       std::to_string(c.nx()) + "x" + std::to_string(c.ny()) + "x" + std::to_string(c.nz()) + " with " +
                       std::to_string(c.channels()));
  for (float v : c.values())
    if (!std::isfinite(v)) throw InvalidInput("the constraint volume has a non-finite value; fix it first");
}

// Peak memory: the finest texture twice (upsampling), the sparse matches,
// weights and energies (double-buffered), the exemplar-values sources, the
// constraint pyramid and the exemplar analysis (neighbourhoods, coefficients,
// k-NN lists per thread). Each part's advice names its own cause.
void check_texture_memory(const Job& job, const TextureOptimizationOptions& opt, const PreparedExemplars& p) {
  const int n = opt.neighborhood, channels = p.channels;
  const double voxels = double(job.finest.voxels());
  // (+ 8 bytes per sparse voxel and view: the optimisation's window table, level_solver.hpp)
  double texture_bytes = voxels * channels * 4.0 * 2.0 + voxels * 3.0 / 4.0 * (16.0 + 8.0);
  if (opt.exemplar_values) texture_bytes += voxels * 4.0;  // TextureResult::source
  if (opt.exemplar_values && opt.histogram_values > 0)  // the plain choices (write_values), the rounds' proposals
    texture_bytes += voxels * 4.0 + solid::LevelSolver::sample_proposal_bytes(voxels, n);
  if (opt.exemplar_values && opt.structure_sigma > 0)  // the mean; each channel's value order (matched in parallel)
    texture_bytes += voxels * channels * (4.0 + 4.0);
  if (p.constraint && !p.constraint->empty()) texture_bytes += voxels * (p.user_channels + 1) * 4.0 * 8.0 / 7.0;
  double exemplar_bytes = 0;
  const Image* largest = p.images[0];
  for (const Image* img : p.images) {
    const double count = double(img->width() - n + 1) * (img->height() - n + 1);
    exemplar_bytes += count * (double(n) * n * channels + opt.max_pca_dims + 8 + opt.coherence_k) * 4.0 * 1.5;
    if (img->pixel_count() > largest->pixel_count()) largest = img;
  }
  const std::string size = job.name == "image" ? std::to_string(job.finest.d[0]) + "x" + std::to_string(job.finest.d[1])
                                               : std::to_string(job.finest.d[0]) + "^3";
  const bool mosaic = std::any_of(p.rotated.begin(), p.rotated.end(), [&](const Image& r) { return &r == largest; });
  const std::string exemplar = std::to_string(largest->width()) + "x" + std::to_string(largest->height()) + " " +
                               std::to_string(p.user_channels) + "-channel exemplar" +  // as the caller gave it
                               (mosaic ? " mosaic (its four quarter turns, rotate_exemplar)" : "");
  if (exemplar_bytes >= texture_bytes)
    check_memory_budget(texture_bytes + exemplar_bytes, opt.memory_budget,
                        "analysing the " + exemplar + " (" + std::to_string(n) + "x" + std::to_string(n) +
                            " neighbourhoods) for a " + size + " " + job.name,
                        std::string("the exemplar is too big: give a smaller exemplar or a lower max_exemplar_size "
                                    "(working resolution), fewer channels or a smaller neighbourhood") +
                            (mosaic ? ", set rotate_exemplar to off" : "") + ", or raise the memory budget");
  else
    check_memory_budget(texture_bytes + exemplar_bytes, opt.memory_budget, "synthesizing a " + size + " " + job.name,
                        "lower the size or raise the memory budget");
}

// Value ranges for the histogram bins: the exemplars' (finest level).
void value_ranges(const std::vector<const Image*>& images, int channels, std::vector<float>& lo, std::vector<float>& hi) {
  lo.assign(channels, std::numeric_limits<float>::max());
  hi.assign(channels, std::numeric_limits<float>::lowest());
  for (const Image* img : images)
    for (std::size_t p = 0; p < img->pixel_count(); ++p)
      for (int c = 0; c < channels; ++c) {
        lo[c] = std::min(lo[c], img->data()[p * channels + c]);
        hi[c] = std::max(hi[c], img->data()[p * channels + c]);
      }
}

// The coarsest level's start: random exemplar texels of the first active
// view (Kopf et al. initialise from the exemplar).
Volume random_texels(const Dims& d, const std::array<const solid::ExemplarIndex*, 3>& views, int channels,
                     std::uint64_t seed) {
  int first_view = 0;
  while (!views[first_view]) ++first_view;  // validated: one view is active
  const Image& ex = views[first_view]->image();
  Volume tex(d.d[0], d.d[1], d.d[2], channels);
  for (std::size_t v = 0; v < tex.voxel_count(); ++v) {
    IndexRng rng(seed, v, 0x1417);
    const std::size_t pix = rng.below(ex.pixel_count());
    std::copy(ex.data() + pix * channels, ex.data() + (pix + 1) * channels, tex.data() + v * channels);
  }
  return tex;
}

// One level's rounds of search and optimisation (and the exemplar-values
// pass at the finest level), energies appended to `result`.
// `mean`, when given at the finest level with exemplar values, receives the
// texture after the last optimisation (the weighted mean), before the
// exemplar values replace it (structure_sigma).
void optimize_level(solid::LevelSolver& solver, const Job& job, const TextureOptimizationOptions& opt, const Dims& d,
                    int l, double energy_scale, double p0, double p1, ExecContext* ctx, TextureResult& result,
                    Volume* mean = nullptr) {
  const int L = opt.levels;
  const std::string stage = job.name + ": level " + std::to_string(l + 1) + "/" + std::to_string(L);
  const bool coarsest = l == 0, finest = l == L - 1;
  // finest_iterations applies from two levels on (a single level is also
  // the coarsest, which needs its 2x to converge).
  const int iterations = coarsest ? 2 * opt.iterations : finest ? finest_rounds(opt, d) : opt.iterations;
  const bool exemplar_values = finest && opt.exemplar_values;
  const bool keep_mean = exemplar_values && mean;
  // With exemplar values the finest level's last optimisation would be
  // overwritten voxel for voxel: the pass reads only the matches and
  // weights of the last search, and a voxel it leaves (no covering window)
  // is one the optimisation leaves too. So it is skipped (same output;
  // measured 2.1 s of 28.6 s CPU at 128^3) unless its mean is kept.
  const int optimisations = exemplar_values && !keep_mean ? iterations - 1 : iterations;
  StageProgress progress(ctx, stage, p0 + 0.1 * (p1 - p0), p1,
                         std::size_t(iterations) * solver.search_units() +
                             std::size_t(optimisations) * solver.optimize_units() +
                             (!coarsest && opt.coherent_upsampling ? solver.optimize_units() : 0) +
                             (exemplar_values ? solver.discrete_units() : 0));
  // Coherent upsampling: the finer level's texture is first rebuilt from the
  // inherited matches, i.e. from the finer exemplar's own texels, instead of
  // being searched from the trilinearly upsampled (blurred) coarse texture:
  // a blurred query's nearest windows are the exemplar's smoothest ones, so
  // the blur would persist. Measured (docs/solid.md): 2D sharpness 0.71 ->
  // 0.88 (crackedground), 0.36 -> 0.84 (stone33) at no search cost.
  if (!coarsest && opt.coherent_upsampling) solver.optimize(iterations, progress);
  for (int it = 0; it < iterations; ++it) {
    // The coarsest level has no coherent matches to start from and is
    // small: search it exhaustively (in PCA space) until matches settle.
    if (ctx) ctx->set_stage(stage + " search");
    const double energy = solver.search(it, coarsest && it < 2, progress);
    if (!std::isfinite(energy))
      throw Error("the " + job.name + "'s energy became " + std::to_string(energy) +
                  " (not finite) at level " + std::to_string(l + 1) + "; this is a bug, please report it with the exemplar");
    result.energy.push_back(energy * energy_scale);
    result.energy_level.push_back(l);
    if (it >= optimisations) break;
    if (ctx) ctx->set_stage(stage + " optimise");
    solver.optimize(it, progress);
  }
  // Exemplar values (docs/solid.md, "Where the detail went"): the weighted
  // mean of disagreeing windows is what blurs; the output takes the texels
  // of the best-matching windows instead.
  if (exemplar_values) {
    if (keep_mean) *mean = solver.texture();
    if (ctx) ctx->set_stage(stage + " exemplar values");
    solver.discrete(progress, &result.source);
  }
}

TextureResult optimize_texture(const Job& job, const TextureOptimizationOptions& opt, bool wrap, ExecContext* ctx) {
  check_options(opt);
  const int L = opt.levels, n = opt.neighborhood;
  PreparedExemplars ex;
  distinct_exemplars(job, ex);
  StageProgress prepare(ctx, job.name + ": preparing the exemplars", 0.0, 0.0, 1);
  prepare_exemplars(job, opt, ex);
  const int channels = ex.channels;
  const std::vector<Dims> dims = level_dims(job.finest, L);

  PyramidOptions popt;
  popt.levels = L;
  std::vector<std::vector<Image>> pyramids;
  for (std::size_t e = 0; e < ex.images.size(); ++e) {
    const Image* img = ex.images[e];
    pyramids.push_back(gaussian_pyramid(*img, popt));
    // A turned exemplar's windows must fit in one turn: a quarter of the mosaic.
    const int q = ex.turned[e] ? 2 : 1;
    const Image& coarsest = pyramids.back().back();
    const auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
    const bool reduced = q == 1 && (ex.given[e][0] != img->width() || ex.given[e][1] != img->height());
    if (coarsest.width() / q < n || coarsest.height() / q < n)
      throw InvalidInput(ex.names[e] + " (" + size(ex.given[e][0], ex.given[e][1]) + " pixels" +
                         (reduced ? ", analysed at " + size(img->width(), img->height()) + " within max_exemplar_size" : "") +
                         (q > 1 ? "; its central square " + size(img->width() / q, img->height() / q) +
                                      ", turned for rotate_exemplar" : std::string()) + ")" +
                         " is " + std::to_string(coarsest.width() / q) + "x" + std::to_string(coarsest.height() / q) +
                         " at the coarsest of " + std::to_string(L) + " levels, smaller than the " + std::to_string(n) + "x" +
                         std::to_string(n) + " neighbourhood; use a larger exemplar, fewer levels or a smaller neighbourhood");
  }
  check_constraint(job, ex.user_channels);
  check_texture_memory(job, opt, ex);
  std::vector<float> lo, hi;
  value_ranges(ex.images, ex.user_channels, lo, hi);  // histograms of the exemplar's channels only

  std::vector<Volume> constraint_levels;
  if (ex.constraint && !ex.constraint->empty()) {
    PyramidOptions cp;
    cp.levels = L;
    cp.boundary = wrap ? Boundary::Wrap : Boundary::Clamp;
    constraint_levels = gaussian_pyramid(*ex.constraint, cp);
  }

  // Progress: each level's share is proportional to its voxel count.
  double total_work = 0;
  for (const Dims& d : dims) total_work += double(d.voxels());
  double done = 0;

  // Energies are mean |s - e|^r: back in the caller's units.
  const double energy_scale = std::pow(2.0, double(ex.exponent) * opt.r);
  TextureResult result;
  Volume tex;
  std::unique_ptr<solid::LevelSolver> previous;
  std::vector<std::unique_ptr<solid::ExemplarIndex>> prev_index;
  const Volume empty;
  const bool split = opt.exemplar_values && opt.structure_sigma > 0;
  Volume mean;  // the finest level's weighted mean (structure_sigma)
  for (int l = 0; l < L; ++l) {
    const double p0 = done / total_work, p1 = (done + double(dims[l].voxels())) / total_work;
    done += double(dims[l].voxels());
    const std::string stage = job.name + ": level " + std::to_string(l + 1) + "/" + std::to_string(L);
    const int pyr = L - 1 - l;  // pyramid index of this level

    std::vector<std::unique_ptr<solid::ExemplarIndex>> index;
    const double a0 = p0, a1 = p0 + 0.1 * (p1 - p0);
    const std::size_t count = ex.images.size();
    for (std::size_t e = 0; e < count; ++e)
      index.push_back(std::make_unique<solid::ExemplarIndex>(
          pyramids[e][pyr], n, opt.pca_variance, opt.max_pca_dims,
          opt.search == SolidSearch::KCoherence ? opt.coherence_k : 0, opt.histogram_bins, lo, hi, ctx,
          stage + " exemplar analysis", a0 + (a1 - a0) * double(e) / double(count),
          a0 + (a1 - a0) * double(e + 1) / double(count)));
    std::array<const solid::ExemplarIndex*, 3> views{};
    for (int i = 0; i < 3; ++i) views[i] = ex.image_of[i] >= 0 ? index[ex.image_of[i]].get() : nullptr;

    const Dims& d = dims[l];
    tex = l == 0 ? random_texels(d, views, channels, opt.seed)
                 : resize_trilinear(tex, d.d[0], d.d[1], d.d[2], wrap ? Boundary::Wrap : Boundary::Clamp);
    const Volume& constraint = constraint_levels.empty() ? empty : constraint_levels[pyr];
    auto solver = std::make_unique<solid::LevelSolver>(tex, views, constraint, opt, wrap,
                                                       hash_index(opt.seed, std::uint64_t(l), 0x5EED), lo, hi);
    if (l > 0) solver->inherit_matches(*previous);
    optimize_level(*solver, job, opt, d, l, energy_scale, p0, p1, ctx, result, split ? &mean : nullptr);
    previous = std::move(solver);
    prev_index = std::move(index);  // the solver's views point into these
  }
  if (split) {
    // (the finest level's progress ends at 1; the split is short: ~0.6 s of ~9 s at 128^3)
    StageProgress progress(ctx, job.name + ": structure and detail", 1.0, 1.0,
                           solid::split_units(tex, ex.user_channels));
    solid::split_structure_detail(tex, std::move(mean), opt.structure_sigma, wrap ? Boundary::Wrap : Boundary::Clamp,
                                  ex.user_channels, ex.images, progress);
    previous->constrain_texture();  // a requested target still wins by its weight
  }
  if (ctx) ctx->set_progress(1.0);
  if (channels != ex.user_channels) {  // drop the feature-distance channel
    const int user_channels = ex.user_channels;
    Volume out(tex.nx(), tex.ny(), tex.nz(), user_channels, 0.0f, tex.transform());
    for (std::size_t v = 0; v < tex.voxel_count(); ++v)
      std::copy(tex.data() + v * channels, tex.data() + v * channels + user_channels, out.data() + v * user_channels);
    tex = std::move(out);
  }
  if (ex.exponent != 0)
    for (float& v : tex.values()) v = std::ldexp(v, ex.exponent);
  result.texture = std::move(tex);
  for (int i = 0; i < 3; ++i) result.rotated_exemplar[i] = ex.image_of[i] >= 0 && ex.turned[std::size_t(ex.image_of[i])];
  return result;
}

}  // namespace

int min_texture_size(int levels, int neighborhood) {
  return (neighborhood - 1) * (1 << (std::max(levels, 1) - 1)) + 1;
}

TextureResult synthesize_solid(const SolidExemplars& ex, const SolidOptions& opt, ExecContext* ctx) {
  check_edge("size", opt.size, kMaxSolidSize, opt, "voxels");
  Job job;
  job.finest = {{opt.size, opt.size, opt.size}};
  job.name = "solid";
  const Image* first = nullptr;
  for (const Image& img : ex.views)
    if (!img.empty() && !first) first = &img;
  if (!first) throw InvalidInput("no exemplar: give at least one exemplar image");
  int active = 0;
  for (int i = 0; i < 3; ++i) {
    if (!ex.active[i]) continue;
    job.views[i] = ex.views[i].empty() ? first : &ex.views[i];
    ++active;
  }
  if (active < 2) throw InvalidInput("a solid needs at least two active views (x, y, z); got " + std::to_string(active));
  if (opt.method == SolidMethod::Coordinates) return solid::synthesize_coordinates(job.views, ex.constraint, opt, ctx);
  job.constraint = &ex.constraint;
  return optimize_texture(job, opt, opt.tileable, ctx);
}

Image synthesize_image(const Image& exemplar, const ImageSynthesisOptions& opt, ExecContext* ctx,
                       std::vector<double>* energy) {
  if (opt.method == ImageMethod::Coordinates) return image::synthesize_coordinates(exemplar, opt, ctx, energy);
  check_edge("width", opt.width, kMaxImageSize, opt, "pixels");
  check_edge("height", opt.height, kMaxImageSize, opt, "pixels");
  Job job;
  job.finest = {{opt.width, opt.height, 1}};
  job.name = "image";
  job.views[2] = &exemplar;  // the z-slice of a one-voxel-thick volume is the image
  TextureResult r = optimize_texture(job, opt, opt.tileable, ctx);
  if (energy) *energy = r.energy;
  Image out(opt.width, opt.height, exemplar.channels());
  std::copy(r.texture.values().begin(), r.texture.values().end(), out.data());
  return out;
}

}  // namespace exsynth
