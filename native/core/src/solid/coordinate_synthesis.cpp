// Coarse-to-fine driver of solid synthesis by exemplar coordinates: per
// level, the exemplars' appearance-space analysis (ExemplarIndex with 5x5
// windows), the crossbar candidate table and a CoordinateSolver; the colours
// are read from the working exemplars once, at the end.
#include "solid/coordinate_synthesis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/rng.hpp"
#include "solid/coordinate_solver.hpp"
#include "solid/crossbar_candidates.hpp"
#include "solid/exemplar_index.hpp"

namespace exsynth {

namespace {

const std::vector<std::string> kMethodNames{"optimization", "coordinates"};

}  // namespace

const std::vector<std::string>& solid_method_names() { return kMethodNames; }
const char* solid_method_name(SolidMethod m) { return kMethodNames[std::size_t(m)].c_str(); }
const char* default_solid_method_name() { return solid_method_name(SolidOptions{}.method); }
SolidMethod solid_method_from_name(const std::string& name) {
  for (std::size_t i = 0; i < kMethodNames.size(); ++i)
    if (kMethodNames[i] == name) return SolidMethod(i);
  throw InvalidInput("method must be 'optimization' or 'coordinates', got '" + name + "'");
}

namespace solid {
namespace {

// Crossbar lines of 7 texels; 2 triples kept per texel, from the 3 x 3 best
// line matches in the two other views.
constexpr int kCrossbarHalf = 3;
constexpr int kTriplesPerTexel = 1;
constexpr int kLineMatches = 3;

void check_exemplar(const Image& img, int view, int channels) {
  const std::string what = std::string("the exemplar for view ") + "xyz"[view];
  if (img.width() < 1 || img.height() < 1 || img.channels() < 1)
    throw InvalidInput(what + " is empty; give an image with at least one pixel and one channel");
  if (channels >= 0 && img.channels() != channels)
    throw InvalidInput("the exemplars have different channel counts (" + std::to_string(channels) + " and " +
                       std::to_string(img.channels()) + "); give every view the same channels");
  for (std::size_t i = 0; i < img.values().size(); ++i)
    if (!std::isfinite(img.values()[i]))
      throw InvalidInput(what + " has a non-finite value (NaN or Inf) at pixel (" +
                         std::to_string(i / img.channels() % img.width()) + ", " +
                         std::to_string(i / img.channels() / img.width()) + "); fix or clamp the image first");
}

// finest_iterations = -1: this many correction passes at the finest level
// once it is kAutoFinestFrom voxels across. 1 instead of 2 at 64^3
// (crackedground / stone33, seed 7): CPU 9.9 / 11.4 -> 7.8 / 7.8 s,
// sharpness 0.86 / 0.74 -> 0.87 / 0.77, hist_emd 2.94 / 10.8 -> 2.89 / 9.9.
constexpr int kAutoFinestPasses = 1;

// Correction passes: `iterations` at the coarsest level, then one per finer
// level before the finest. Every pass drifts toward the exemplar's flatter
// texels: 64^3 stone33 contrast with 6 / 3 passes at the two coarse levels
// 0.82, with 3 / 1 0.84 (squared costs: 12 / 6 0.64, 6 / 3 0.70, 3 / 1 0.78);
// docs/solid.md, sixth pass.
constexpr int kUpsampledPasses = 1;

int rounds(const SolidOptions& opt, int level, int levels, int edge) {
  if (level == 0) return opt.iterations;
  if (level < levels - 1) return std::min(kUpsampledPasses, opt.iterations);
  if (opt.finest_iterations == 0) return opt.iterations;
  if (opt.finest_iterations > 0) return opt.finest_iterations;
  return edge >= kAutoFinestFrom ? std::min(kAutoFinestPasses, opt.iterations) : opt.iterations;
}

}  // namespace

TextureResult synthesize_coordinates(const std::array<const Image*, 3>& view_images, const Volume& constraint,
                                     const SolidOptions& opt, ExecContext* ctx) {
  if (!constraint.empty())
    throw InvalidInput("method 'coordinates' does not take a constraint volume yet; use method='optimization'");
  if (opt.coordinate_coherence_k < 0 || opt.coordinate_coherence_k > 16)
    throw InvalidInput("coordinate_coherence_k must be between 0 and 16, got " + std::to_string(opt.coordinate_coherence_k));
  const int L = opt.levels;
  StageProgress prepare(ctx, "solid: preparing the exemplars", 0.0, 0.0, 1);

  // Distinct exemplars at the working resolution (views may share one).
  std::vector<const Image*> sources;
  std::array<int, 3> image_of{-1, -1, -1};
  int channels = -1;
  for (int i = 0; i < 3; ++i) {
    if (!view_images[i]) continue;
    auto it = std::find(sources.begin(), sources.end(), view_images[i]);
    if (it == sources.end()) {
      check_exemplar(*view_images[i], i, channels);
      channels = view_images[i]->channels();
      sources.push_back(view_images[i]);
      it = sources.end() - 1;
    }
    image_of[i] = int(it - sources.begin());
  }
  std::vector<Image> working;
  for (const Image* img : sources) {
    Image w = *img;
    while (opt.max_exemplar_size > 0 && std::max(w.width(), w.height()) > opt.max_exemplar_size)
      w = downsample(w, Boundary::Clamp);
    working.push_back(std::move(w));
  }

  // The analysis sees the values scaled by a power of two into [1, 2) when
  // they lie outside [1/16, 16] (squared float distances would overflow or
  // underflow); the colours are read from the unscaled exemplars.
  float max_abs = 0.0f;
  for (const Image& w : working)
    for (float v : w.values()) max_abs = std::max(max_abs, std::abs(v));
  const int exponent = max_abs == 0.0f || (max_abs >= 1.0f / 16 && max_abs <= 16.0f) ? 0 : std::ilogb(max_abs);
  PyramidOptions popt;
  popt.levels = L;
  std::vector<std::vector<Image>> pyramids;
  for (const Image& w : working) {
    Image scaled = w;
    for (float& v : scaled.values()) v = std::ldexp(v, -exponent);
    pyramids.push_back(gaussian_pyramid(scaled, popt));
    const Image& coarsest = pyramids.back().back();
    if (coarsest.width() < kCoordinateWindow + 1 || coarsest.height() < kCoordinateWindow + 1)
      throw InvalidInput("an exemplar of " + std::to_string(w.width()) + "x" + std::to_string(w.height()) +
                         " pixels is " + std::to_string(coarsest.width()) + "x" + std::to_string(coarsest.height()) +
                         " at the coarsest of " + std::to_string(L) + " levels, too small for method 'coordinates' (" +
                         std::to_string(kCoordinateWindow + 1) + " pixels at least); use a larger exemplar or fewer levels");
  }

  {  // Peak memory: two levels' coordinates, the colours, the exemplar analysis.
    const double voxels = double(opt.size) * opt.size * opt.size;
    double bytes = voxels * (12.0 * 1.25 + 4.0 * channels);
    for (const Image& w : working)
      bytes += double(w.pixel_count()) *
               (double(kCoordinateWindow) * kCoordinateWindow * channels + kCoordinateFeatureDims + opt.coordinate_coherence_k +
                2.0 * (2 * kCrossbarHalf + 1) * channels + 3.0 * 4 * kTriplesPerTexel) * 4.0 * 1.5;
    check_memory_budget(bytes, opt.memory_budget, "synthesizing a " + std::to_string(opt.size) + "^3 solid",
                        "lower the size, the exemplar's size or max_exemplar_size, or raise the memory budget");
  }

  std::vector<float> lo(std::size_t(channels), std::numeric_limits<float>::max());
  std::vector<float> hi(std::size_t(channels), std::numeric_limits<float>::lowest());
  for (const auto& pyr : pyramids)
    for (std::size_t p = 0; p < pyr[0].pixel_count(); ++p)
      for (int c = 0; c < channels; ++c) {
        lo[c] = std::min(lo[c], pyr[0].data()[p * channels + c]);
        hi[c] = std::max(hi[c], pyr[0].data()[p * channels + c]);
      }

  // Levels coarsest first; each halves (rounding up); progress by voxels.
  std::vector<int> edge(static_cast<std::size_t>(L));
  edge[L - 1] = opt.size;
  for (int l = L - 2; l >= 0; --l) edge[l] = (edge[l + 1] + 1) / 2;
  double total = 0, done = 0;
  for (int e : edge) total += double(e) * e * e;

  TextureResult result;
  std::unique_ptr<CoordinateSolver> previous;
  std::vector<std::unique_ptr<ExemplarIndex>> prev_index;
  std::unique_ptr<CrossbarCandidates> prev_table;
  const int feature_dims = std::min(opt.max_pca_dims, kCoordinateFeatureDims);
  for (int l = 0; l < L; ++l) {
    const double voxels = double(edge[l]) * edge[l] * edge[l];
    const double p0 = done / total, p1 = (done + voxels) / total;
    done += voxels;
    const double a0 = p0, a1 = p0 + 0.15 * (p1 - p0), a2 = p0 + 0.3 * (p1 - p0);
    const std::string stage = "solid: level " + std::to_string(l + 1) + "/" + std::to_string(L);
    const int pyr = L - 1 - l;

    std::vector<std::unique_ptr<ExemplarIndex>> index;
    for (std::size_t e = 0; e < pyramids.size(); ++e)
      index.push_back(std::make_unique<ExemplarIndex>(
          pyramids[e][pyr], kCoordinateWindow, opt.pca_variance, feature_dims, opt.coordinate_coherence_k,
          opt.histogram_bins, lo, hi, ctx, stage + " exemplar analysis", a0 + (a1 - a0) * double(e) / pyramids.size(),
          a0 + (a1 - a0) * double(e + 1) / pyramids.size()));
    std::array<const ExemplarIndex*, 3> views{};
    for (int i = 0; i < 3; ++i) views[i] = image_of[i] >= 0 ? index[image_of[i]].get() : nullptr;
    auto table = std::make_unique<CrossbarCandidates>(views, kCrossbarHalf, kTriplesPerTexel, kLineMatches, ctx,
                                                      stage + " crossbar candidates", a1, a2);

    const int passes = rounds(opt, l, L, edge[l]);
    auto solver = std::make_unique<CoordinateSolver>(std::array<int, 3>{edge[l], edge[l], edge[l]}, views, *table,
                                                     opt.coordinate_coherence_k, opt.tileable, hash_index(opt.seed, std::uint64_t(l), 0xC0DE));
    StageProgress progress(ctx, l == 0 ? stage + " initialise" : stage + " upsample", a2, p1,
                           std::size_t(passes + 1) * solver->units() + (l == L - 1 ? solver->units() : 0));
    if (l == 0) solver->initialize(progress);
    else solver->upsample(*previous, progress);
    for (int it = 0; it < passes; ++it) {
      if (ctx) ctx->set_stage(stage + " correction " + std::to_string(it + 1) + "/" + std::to_string(passes));
      solver->correct(progress);
      result.energy.push_back(solver->energy() * std::ldexp(1.0, 2 * exponent));
      result.energy_level.push_back(l);
    }
    if (l == L - 1) {
      if (ctx) ctx->set_stage("solid: colours");
      std::array<const Image*, 3> images{};
      for (int i = 0; i < 3; ++i) images[i] = image_of[i] >= 0 ? &working[std::size_t(image_of[i])] : nullptr;
      result.texture = solver->colours(images, progress);
    }
    previous = std::move(solver);
    prev_table = std::move(table);  // the solver refers to these
    prev_index = std::move(index);
  }
  if (ctx) ctx->set_progress(1.0);
  return result;
}

}  // namespace solid
}  // namespace exsynth
