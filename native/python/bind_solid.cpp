// exsynth._native.synthesize_solid / synthesize_image
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/format.hpp"
#include "exsynth/solid.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

SolidSearch to_search(const std::string& s) {
  if (s == "kcoherence") return SolidSearch::KCoherence;
  if (s == "kdtree") return SolidSearch::KdTree;
  if (s == "exact") return SolidSearch::Exact;
  throw InvalidInput("search must be 'kcoherence', 'kdtree' or 'exact', got '" + s + "'");
}

// rotate_exemplar: 'off', 'on', 'auto', or a bool (on / off).
RotateExemplar rotate_arg(const py::handle& v, const std::string& k) {
  if (py::isinstance<py::bool_>(v)) return bool_arg(v, k) ? RotateExemplar::On : RotateExemplar::Off;
  return rotate_exemplar_from_name(string_arg(v, k, "'off', 'on' or 'auto' (or True / False)"));
}

// The optimiser's options, which both entry points share.
constexpr const char* kCommonNames =
    "levels, neighborhood, iterations, finest_iterations, r, pca_variance, max_pca_dims, search, coherence_k, "
    "random_candidates, ann_eps, histogram_matching, histogram_bins, histogram_strength, mean_shift, "
    "coherent_upsampling, exemplar_values, histogram_values, histogram_value_rounds, histogram_value_window, structure_sigma, feature_weight, feature_threshold, feature_scale, rotate_exemplar, tileable, max_exemplar_size, memory_budget, seed";

// The options both entry points share, in one place; `names`: every option
// the entry point takes, for the message about an unknown one.
void set_common(TextureOptimizationOptions& o, const py::kwargs& kw, const std::string& names) {
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    // Ranges as solid/synthesize.cpp's check_options (which checks them again).
    if (k == "levels") o.levels = int_arg(v, k, 1, kMaxLevels);
    else if (k == "neighborhood") o.neighborhood = int_arg(v, k, 3, 32);
    else if (k == "iterations") o.iterations = int_arg(v, k, 1, kMaxIterations);
    else if (k == "finest_iterations") o.finest_iterations = int_arg(v, k, -1, 100);
    else if (k == "r") o.r = real_arg(v, k, 0.0, 2.0, Ends::OpenLow);
    else if (k == "pca_variance") o.pca_variance = real_arg(v, k, 0.0, 1.0, Ends::OpenLow);
    else if (k == "max_pca_dims") o.max_pca_dims = int_arg(v, k, 1, 4096);
    else if (k == "search") o.search = to_search(string_arg(v, k, "'kcoherence', 'kdtree' or 'exact'"));
    else if (k == "coherence_k") o.coherence_k = int_arg(v, k, 0, 64);
    else if (k == "random_candidates") o.random_candidates = int_arg(v, k, 0, 64);
    else if (k == "ann_eps") o.ann_eps = real_arg(v, k, 0.0, 1e6);
    else if (k == "histogram_matching") o.histogram_matching = bool_arg(v, k);
    else if (k == "histogram_bins") o.histogram_bins = int_arg(v, k, 2, 256);
    else if (k == "histogram_strength") o.histogram_strength = real_arg(v, k, 0.0, 16.0);
    else if (k == "mean_shift") o.mean_shift = bool_arg(v, k);
    else if (k == "coherent_upsampling") o.coherent_upsampling = bool_arg(v, k);
    else if (k == "exemplar_values") o.exemplar_values = bool_arg(v, k);
    else if (k == "histogram_values") o.histogram_values = real_arg(v, k, 0.0, 100.0, Ends::Closed, "0 = off");
    else if (k == "histogram_value_rounds") o.histogram_value_rounds = int_arg(v, k, 1, 64);
    else if (k == "histogram_value_window") o.histogram_value_window = real_arg(v, k, 0.0, 1.0);
    else if (k == "structure_sigma")
      o.structure_sigma = real_arg(v, k, 0.0, kMaxStructureSigma, Ends::Closed, "voxels; 0 = off");
    else if (k == "feature_weight") o.feature_weight = real_arg(v, k, 0.0, 100.0, Ends::Closed, "0 = off");
    else if (k == "feature_threshold")
      o.feature_threshold = real_arg(v, k, 0.0, kMaxFeatureThreshold, Ends::Closed, "0 = darker than the window's mean at all");
    else if (k == "feature_scale")
      o.feature_scale = int_arg(v, k, 0, kMaxFeatureScale, "exemplar pixels; 0 = the neighbourhood's edge");
    else if (k == "rotate_exemplar") o.rotate_exemplar = rotate_arg(v, k);
    else if (k == "tileable") o.tileable = bool_arg(v, k);
    else if (k == "max_exemplar_size") o.max_exemplar_size = int_arg(v, k, 0, 1 << 16);
    else if (k == "memory_budget") o.memory_budget = memory_budget_arg(v, k);
    else if (k == "seed") o.seed = seed_arg(v, k);
    else
      throw InvalidInput("unknown option '" + k + "'; options: " + names);
  }
}

/// The last channel of a constraint is a weight in [0, 1] (1 = take the
/// target); the core only checks finiteness, so a weight of 2 would
/// silently overshoot the target.
void check_constraint_weights(const Volume& c) {
  const int channels = c.channels();
  if (channels < 2) return;  // the core reports the channel count
  const std::vector<float>& v = c.values();
  for (std::size_t i = std::size_t(channels - 1); i < v.size(); i += std::size_t(channels))
    if (!(v[i] >= 0.0f && v[i] <= 1.0f))
      throw InvalidInput("'constraint' weights (its last channel) must be in [0, 1] (1 = take the target, 0 = ignore "
                         "it), got " + std::to_string(v[i]) + " at voxel " + std::to_string(i / std::size_t(channels)));
}

/// synthesize_solid's own options (method, coordinate_coherence_k); the
/// rest go to set_common.
py::kwargs set_solid_options(SolidOptions& o, const py::kwargs& kw) {
  py::kwargs rest;
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    if (k == "method") o.method = solid_method_from_name(string_arg(item.second, k, "'optimization' or 'coordinates'"));
    else if (k == "coordinate_coherence_k") o.coordinate_coherence_k = int_arg(item.second, k, 0, 16);
    else rest[item.first] = item.second;
  }
  return rest;
}

/// synthesize_image's own options (method and the coordinate method's);
/// the rest go to set_common.
py::kwargs set_image_options(ImageSynthesisOptions& o, const py::kwargs& kw) {
  py::kwargs rest;
  CoordinateSynthesisOptions& c = o.coordinates;
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    // Ranges as image/coordinate_synthesis.cpp's check (which checks them again).
    if (k == "method") o.method = image_method_from_name(string_arg(v, k, "'coordinates' or 'optimization'"));
    else if (k == "jitter") c.jitter = real_arg(v, k, 0.0, 4.0, Ends::Closed, "times the level spacing");
    else if (k == "jitter_from") c.jitter_from = int_arg(v, k, 1, 1024, "pixels (a power of two)");
    else if (k == "corrections") c.corrections = int_arg(v, k, 0, 16);
    else if (k == "candidates_k") c.coherence_k = int_arg(v, k, 1, 16);
    else if (k == "coherence") c.coherence = real_arg(v, k, 0.0, 100.0);
    else if (k == "wide_below") c.wide_below = int_arg(v, k, 0, 1024, "pixels (0 = 3 x 3 neighbourhoods everywhere)");
    else if (k == "appearance_window") c.appearance_window = int_arg(v, k, 1, 15, "pixels (odd)");
    else if (k == "appearance_dims") c.appearance_dims = int_arg(v, k, 1, 64);
    else if (k == "coarsest_spacing") c.coarsest_spacing = int_arg(v, k, 0, 1024, "pixels (a power of two, 0 = auto)");
    else if (k == "exhaustive") c.exhaustive = bool_arg(v, k);
    else if (k == "refine_passes") c.refine_passes = int_arg(v, k, 0, 16, "(0 = no patch refinement)");
    else if (k == "refine_patch") c.refine_patch = int_arg(v, k, 2, 32, "pixels");
    else if (k == "refine_stride") c.refine_stride = int_arg(v, k, 1, 32, "pixels (at most refine_patch)");
    else if (k == "refine_random") c.refine_random = int_arg(v, k, 0, 16, "probes per radius");
    else if (k == "refine_medoid") c.refine_medoid = bool_arg(v, k);
    else if (k == "cut_passes") c.cut_passes = int_arg(v, k, 0, 16, "(0 = no seam cuts)");
    else if (k == "cut_window") c.cut_window = int_arg(v, k, 4, 256, "pixels");
    else if (k == "cut_labels") c.cut_labels = int_arg(v, k, 1, 256, "sources per window");
    else if (k == "cut_reach") c.cut_reach = int_arg(v, k, 0, 256, "pixels (0 = the whole window)");
    else if (k == "cut_radius") c.cut_radius = int_arg(v, k, 0, 4, "pixels");
    else if (k == "cut_matches") c.cut_matches = bool_arg(v, k);
    else if (k == "cut_leave") c.cut_leave = real_arg(v, k, 0.0, 1e6, Ends::Closed, "colour distance per pixel");
    else rest[item.first] = item.second;
  }
  return rest;
}

py::list to_list(const std::vector<double>& v) {
  py::list l;
  for (double x : v) l.append(x);
  return l;
}

}  // namespace

// synthesize_image's docstring, with the coordinate method's defaults read
// from the core (written out, they went stale when a default moved).
const std::string& image_doc() {
  static const std::string doc = [] {
    const CoordinateSynthesisOptions d;
    auto flag = [](bool b) { return b ? "True" : "False"; };
    return "2D texture synthesis: exemplar -> (height, width, C) float32 image (tileable=True to tile).\n"
           "method='" + std::string(default_image_method_name()) + "' is the default. method='coordinates': Lefebvre & Hoppe 2005 "
           "in appearance space: jitter=" + format_number(d.jitter) + ", jitter_from=" + std::to_string(d.jitter_from) +
           ", corrections=" + std::to_string(d.corrections) + ", candidates_k=" + std::to_string(d.coherence_k) +
           ",\ncoherence=" + format_number(d.coherence) + ", wide_below=" + std::to_string(d.wide_below) +
           ", appearance_window=" + std::to_string(d.appearance_window) + ", appearance_dims=" + std::to_string(d.appearance_dims) +
           ", coarsest_spacing=" + std::to_string(d.coarsest_spacing) + " (auto), exhaustive=" + flag(d.exhaustive) +
           ",\nrefine_passes=" + std::to_string(d.refine_passes) + " (the patch refinement: 0 = off), refine_patch=" +
           std::to_string(d.refine_patch) + ", refine_stride=" + std::to_string(d.refine_stride) + ", refine_random=" +
           std::to_string(d.refine_random) + ", refine_medoid=" + flag(d.refine_medoid) +
           ",\ncut_passes=" + std::to_string(d.cut_passes) + " (the seam cuts: 0 = off), cut_window=" +
           std::to_string(d.cut_window) + ", cut_labels=" + std::to_string(d.cut_labels) + ", cut_leave=" +
           format_number(d.cut_leave) + ", cut_reach=" + std::to_string(d.cut_reach) + ", cut_radius=" +
           std::to_string(d.cut_radius) + ", cut_matches=" + flag(d.cut_matches) +
           "; also tileable, max_exemplar_size, seed.\nmethod='optimization': the optimiser of synthesize_solid, "
           "same options (feature_weight=" + format_number(ImageSynthesisOptions{}.feature_weight) +
           ", histogram_values=" + format_number(ImageSynthesisOptions{}.histogram_values) + " here). Returns {'image': ..., 'energy': [...]}.";
  }();
  return doc;
}

void bind_solid(py::module_& m) {
  m.def(
      "min_texture_size",
      [](const IntArg& levels, const IntArg& neighborhood, const py::kwargs& extra) {
        reject_unknown(extra, "levels, neighborhood");
        // Ranges as set_common's (solid/synthesize.cpp's check_options).
        return min_texture_size(int_arg(levels, "levels", 1, kMaxLevels), int_arg(neighborhood, "neighborhood", 3, 32));
      },
      py::arg("levels") = TextureOptimizationOptions{}.levels,
      py::arg("neighborhood") = TextureOptimizationOptions{}.neighborhood,
        "Smallest solid size / image width and height accepted with these levels and neighbourhood: the "
        "coarsest level must hold one neighbourhood ((neighborhood - 1) * 2^(levels - 1) + 1; 29 by default).");
  // The engine's defaults, for the add-on's properties and the CLI's options.
  m.attr("DEFAULT_LEVELS") = TextureOptimizationOptions{}.levels;
  m.attr("DEFAULT_ITERATIONS") = TextureOptimizationOptions{}.iterations;
  m.attr("MAX_LEVELS") = kMaxLevels;
  m.attr("MAX_ITERATIONS") = kMaxIterations;
  m.attr("SOLID_DEFAULT_SIZE") = SolidOptions{}.size;
  m.attr("SOLID_DEFAULT_FEATURE_WEIGHT") = SolidOptions{}.feature_weight;
  m.attr("SOLID_DEFAULT_HISTOGRAM_VALUES") = SolidOptions{}.histogram_values;
  m.attr("SOLID_DEFAULT_FEATURE_THRESHOLD") = SolidOptions{}.feature_threshold;
  m.attr("SOLID_DEFAULT_STRUCTURE_SIGMA") = SolidOptions{}.structure_sigma;
  m.attr("SOLID_MAX_STRUCTURE_SIGMA") = kMaxStructureSigma;
  m.attr("SOLID_MAX_FEATURE_THRESHOLD") = kMaxFeatureThreshold;
  m.attr("SOLID_DEFAULT_FEATURE_SCALE") = SolidOptions{}.feature_scale;
  m.attr("SOLID_MAX_FEATURE_SCALE") = kMaxFeatureScale;
  m.attr("SOLID_DEFAULT_ROTATE_EXEMPLAR") = rotate_exemplar_name(SolidOptions{}.rotate_exemplar);
  m.attr("ROTATE_EXEMPLAR_CHOICES") = py::tuple(py::cast(rotate_exemplar_names()));
  m.attr("ROUND_FEATURE_STRETCH") = kRoundFeatureStretch;
  m.def(
      "exemplar_feature_stretch",
      [](const ArrayArg& exemplar, const py::kwargs& extra) {
        reject_unknown(extra, "none besides the exemplar");
        const Image img = to_image(exemplar, "exemplar");
        py::gil_scoped_release release;
        return exemplar_feature_stretch(img);
      },
      py::arg("exemplar"),
      "The exemplar's feature stretch (1 = round features), which rotate_exemplar='auto' compares with "
      "ROUND_FEATURE_STRETCH: the exemplar is used in its quarter turns below it.");
  m.attr("SOLID_MAX_SIZE") = kMaxSolidSize;
  m.attr("IMAGE_MAX_SIZE") = kMaxImageSize;
  m.attr("DEFAULT_MAX_EXEMPLAR_SIZE") = kDefaultMaxExemplarSize;
  m.attr("SOLID_METHODS") = py::tuple(py::cast(solid_method_names()));
  m.attr("SOLID_DEFAULT_METHOD") = default_solid_method_name();
  m.attr("IMAGE_METHODS") = py::tuple(py::cast(image_method_names()));
  m.attr("IMAGE_DEFAULT_METHOD") = default_image_method_name();
  m.def(
      "synthesize_solid",
      [](const ArrayArg& exemplar, const OptionalArrayArg& exemplar_y, const OptionalArrayArg& exemplar_z,
         const StrArg& views_arg, const IntArg& size, const OptionalArrayArg& constraint, const ContextArg& ctx_arg,
         const py::kwargs& kw) {
        const std::string views = string_arg(views_arg, "views", "the active slices, e.g. 'xyz' or 'xy'");
        ExecContext* ctx = context_arg(ctx_arg);
        SolidExemplars ex;
        ex.views[0] = to_image(exemplar, "exemplar");
        if (!exemplar_y.is_none()) ex.views[1] = to_image(exemplar_y, "exemplar_y");
        if (!exemplar_z.is_none()) ex.views[2] = to_image(exemplar_z, "exemplar_z");
        for (int i = 0; i < 3; ++i) ex.active[i] = views.find("xyz"[i]) != std::string::npos;
        for (char c : views)
          if (c != 'x' && c != 'y' && c != 'z')
            throw InvalidInput("views must name the active slices with x, y and z (e.g. 'xyz' or 'xy'), got '" + views + "'");
        if (!constraint.is_none()) {
          ex.constraint = to_volume(constraint, "constraint", GridTransform{});
          check_constraint_weights(ex.constraint);
        }
        SolidOptions opt;
        opt.size = int_arg(size, "size", 1, 2048, "voxels per edge");
        set_common(opt, set_solid_options(opt, kw), std::string("method, coordinate_coherence_k, ") + kCommonNames);
        TextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_solid(ex, opt, ctx);
        }
        py::dict out;
        out["energy"] = to_list(r.energy);
        out["energy_level"] = py::cast(r.energy_level);
        out["rotated_exemplar"] = py::make_tuple(r.rotated_exemplar[0], r.rotated_exemplar[1], r.rotated_exemplar[2]);
        Volume& t = r.texture;
        const py::ssize_t c = t.channels();
        out["solid"] = take_vector(std::move(t.values()), {t.nz(), t.ny(), t.nx(), c});
        return out;
      },
      py::arg("exemplar"), py::kw_only(), py::arg("exemplar_y") = py::none(), py::arg("exemplar_z") = py::none(),
      py::arg("views") = "xyz", py::arg("size") = SolidOptions{}.size, py::arg("constraint") = py::none(),
      py::arg("ctx") = py::none(),
      R"doc(Solid texture from 2D exemplars (Kopf et al. 2007).

exemplar: (H, W) or (H, W, C) uint8/uint16 (scaled to [0, 1]) or float; used for every view
without its own. exemplar_y / exemplar_z: the y- and z-slice exemplars (same channels).
views: active slices, 'xyz' or two of them. constraint: (size, size, size, C + 1) float32:
target values then a weight in [0, 1]. Options (keywords): levels=3, neighborhood=8,
iterations=3, finest_iterations=-1 (rounds at the finest level; 0 = iterations; -1 = 2 from 64 voxels across), r=0.8, pca_variance=0.95, max_pca_dims=32,
search='kcoherence'|'kdtree'|'exact', coherence_k=4, random_candidates=2, ann_eps=2.0, histogram_matching=True, histogram_bins=16, histogram_strength=3
((1 + excess)^-strength re-weighting; 1 = gentle),
mean_shift=False, coherent_upsampling=True, exemplar_values=True, histogram_values=SOLID_DEFAULT_HISTOGRAM_VALUES (> 0: the
exemplar values match the exemplars' histogram, this being the step of the per-bin prices; 0 = off), histogram_value_rounds=32
(its pricing rounds), histogram_value_window=0 (0..1: the share of a proposal's price taken from its whole
window's texels, for coherent choices), structure_sigma=SOLID_DEFAULT_STRUCTURE_SIGMA (> 0, with exemplar_values: low
frequencies below a Gaussian of this many voxels from the optimiser's weighted mean, the rest from the exemplar values,
then each channel's histogram matched to the exemplars'; 0 = off; up to SOLID_MAX_STRUCTURE_SIGMA), feature_weight=SOLID_DEFAULT_FEATURE_WEIGHT (the feature-distance channel's weight; 0 = off),
feature_threshold=SOLID_DEFAULT_FEATURE_THRESHOLD (features: pixels darker than their window's mean by more than this x the
exemplar's luminance std), feature_scale=SOLID_DEFAULT_FEATURE_SCALE (the channel's distance saturates this many exemplar
pixels from a feature's edge; 0 = neighborhood; up to SOLID_MAX_FEATURE_SCALE), rotate_exemplar=SOLID_DEFAULT_ROTATE_EXEMPLAR ('on': also the exemplar's 90/180/270-degree
turns, for textures with no preferred direction: cracks, cells; 'auto': when exemplar_feature_stretch(exemplar) <
ROUND_FEATURE_STRETCH; 'off'; True / False = 'on' / 'off'), tileable=True,
max_exemplar_size=256 (working resolution: larger exemplars are halved until they fit; 0 = never),
method=SOLID_DEFAULT_METHOD ('optimization': Kopf et al. 2007; 'coordinates': exemplar coordinates after
Dong et al. 2008, which uses levels, iterations, finest_iterations, coordinate_coherence_k=0 (0..16), pca_variance, max_pca_dims,
max_exemplar_size, tileable, memory_budget and seed (feature_weight, feature_threshold, feature_scale, rotate_exemplar and histogram_values
do not apply), and takes no constraint),
memory_budget=0 (default), seed=0. size: min_texture_size(levels, neighborhood) .. SOLID_MAX_SIZE.
Returns {'solid': (Z, Y, X, C) float32, 'energy': [...], 'energy_level': [...], 'rotated_exemplar': (x, y, z)
(per view, whether its exemplar was used in its quarter turns)}.)doc");

  m.def(
      "synthesize_image",
      [](const ArrayArg& exemplar, const IntArg& width, const IntArg& height, const ContextArg& ctx_arg,
         const py::kwargs& kw) {
        ExecContext* ctx = context_arg(ctx_arg);
        const Image ex = to_image(exemplar, "exemplar");
        ImageSynthesisOptions opt;
        opt.width = int_arg(width, "width", 1, 16384, "pixels");
        opt.height = int_arg(height, "height", 1, 16384, "pixels");
        set_common(opt, set_image_options(opt, kw),
                   "method, jitter, jitter_from, corrections, candidates_k, coherence, wide_below, "
                   "appearance_window, appearance_dims, coarsest_spacing, exhaustive, refine_{passes, patch, stride, random, medoid}, "
                   "cut_{passes, window, labels, leave, reach, radius, matches}, tileable, max_exemplar_size, memory_budget, "
                   "seed; method='optimization' also takes synthesize_solid's");
        Image img;
        std::vector<double> energy;
        {
          py::gil_scoped_release release;
          img = synthesize_image(ex, opt, ctx, &energy);
        }
        py::dict out;
        out["energy"] = to_list(energy);
        const py::ssize_t h = img.height(), w = img.width(), c = img.channels();
        out["image"] = take_vector(std::move(img.values()), {h, w, c});
        return out;
      },
      py::arg("exemplar"), py::kw_only(), py::arg("width") = ImageSynthesisOptions{}.width,
      py::arg("height") = ImageSynthesisOptions{}.height,
      py::arg("ctx") = py::none(),
      image_doc().c_str());
}

}  // namespace exsynth::py_bind
