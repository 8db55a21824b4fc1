// exsynth._native.synthesize_solid / synthesize_image
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/solid.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

/// (H, W) or (H, W, C) uint8 / uint16 / float32 / float64 -> Image in [0, 1]
/// for integer types (8- and 16-bit exemplars), unchanged for floats.
Image to_image(const py::handle& arg, const std::string& name) {
  const py::array a = array_arg(arg, name, "an (H, W) or (H, W, C) image array");
  if (a.ndim() != 2 && a.ndim() != 3)
    throw InvalidInput("'" + name + "' must be an (H, W) or (H, W, C) image array, got a " + describe(a));
  const int h = int(a.shape(0)), w = int(a.shape(1)), c = a.ndim() == 3 ? int(a.shape(2)) : 1;
  if (h < 1 || w < 1 || c < 1) throw InvalidInput("'" + name + "' is empty (" + describe(a) + ")");
  Image img(w, h, c);
  float* out = img.data();
  const std::size_t count = img.values().size();
  auto copy = [&](auto tag, float scale) {
    using T = decltype(tag);
    auto arr = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
    const T* src = arr.data();
    for (std::size_t i = 0; i < count; ++i) out[i] = float(src[i]) * scale;
  };
  const auto dt = a.dtype();
  if (dt.is(py::dtype::of<std::uint8_t>())) copy(std::uint8_t{}, 1.0f / 255.0f);
  else if (dt.is(py::dtype::of<std::uint16_t>())) copy(std::uint16_t{}, 1.0f / 65535.0f);
  else if (dt.is(py::dtype::of<float>())) copy(float{}, 1.0f);
  else if (dt.is(py::dtype::of<double>())) copy(double{}, 1.0f);
  else
    throw InvalidInput("'" + name + "' must have dtype uint8, uint16, float32 or float64, got " + describe(a));
  return img;
}

SolidSearch to_search(const std::string& s) {
  if (s == "kcoherence") return SolidSearch::KCoherence;
  if (s == "kdtree") return SolidSearch::KdTree;
  if (s == "exact") return SolidSearch::Exact;
  throw InvalidInput("search must be 'kcoherence', 'kdtree' or 'exact', got '" + s + "'");
}

// The options both entry points share, in one place.
void set_common(TextureOptimizationOptions& o, const py::kwargs& kw) {
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    // Ranges as solid/synthesize.cpp's check_options (which checks them again).
    if (k == "levels") o.levels = int_arg(v, k, 1, 8);
    else if (k == "neighborhood") o.neighborhood = int_arg(v, k, 3, 32);
    else if (k == "iterations") o.iterations = int_arg(v, k, 1, 100);
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
    else if (k == "feature_weight") o.feature_weight = real_arg(v, k, 0.0, 100.0, Ends::Closed, "0 = off");
    else if (k == "tileable") o.tileable = bool_arg(v, k);
    else if (k == "max_exemplar_size") o.max_exemplar_size = int_arg(v, k, 0, 1 << 16);
    else if (k == "memory_budget") o.memory_budget = memory_budget_arg(v, k);
    else if (k == "seed") o.seed = seed_arg(v, k);
    else
      throw InvalidInput("unknown option '" + k +
                         "'; options: levels, neighborhood, iterations, finest_iterations, r, pca_variance, max_pca_dims, search, "
                         "coherence_k, random_candidates, ann_eps, histogram_matching, histogram_bins, histogram_strength, mean_shift, coherent_upsampling, "
                         "exemplar_values, "
                         "feature_weight, tileable, max_exemplar_size, memory_budget, seed");
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

py::list to_list(const std::vector<double>& v) {
  py::list l;
  for (double x : v) l.append(x);
  return l;
}

}  // namespace

void bind_solid(py::module_& m) {
  m.def(
      "min_texture_size",
      [](const IntArg& levels, const IntArg& neighborhood, const py::kwargs& extra) {
        reject_unknown(extra, "levels, neighborhood");
        // Ranges as set_common's (solid/synthesize.cpp's check_options).
        return min_texture_size(int_arg(levels, "levels", 1, 8), int_arg(neighborhood, "neighborhood", 3, 32));
      },
      py::arg("levels") = 3, py::arg("neighborhood") = 8,
        "Smallest solid size / image width and height accepted with these levels and neighbourhood: the "
        "coarsest level must hold one neighbourhood ((neighborhood - 1) * 2^(levels - 1) + 1; 29 by default).");
  m.attr("SOLID_MAX_SIZE") = kMaxSolidSize;
  m.attr("IMAGE_MAX_SIZE") = kMaxImageSize;
  m.attr("DEFAULT_MAX_EXEMPLAR_SIZE") = kDefaultMaxExemplarSize;
  m.attr("SOLID_METHODS") = py::tuple(py::cast(solid_method_names()));
  m.attr("SOLID_DEFAULT_METHOD") = default_solid_method_name();
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
        py::kwargs common;  // method is the solid's own; the rest is shared with synthesize_image
        for (auto item : kw) {
          if (std::string(py::str(item.first)) == "method")
            opt.method = solid_method_from_name(string_arg(item.second, "method", "'optimization' or 'coordinates'"));
          else if (std::string(py::str(item.first)) == "coordinate_coherence_k")
            opt.coordinate_coherence_k = int_arg(item.second, "coordinate_coherence_k", 0, 16);
          else
            common[item.first] = item.second;
        }
        set_common(opt, common);
        TextureResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_solid(ex, opt, ctx);
        }
        py::dict out;
        out["energy"] = to_list(r.energy);
        out["energy_level"] = py::cast(r.energy_level);
        Volume& t = r.texture;
        const py::ssize_t c = t.channels();
        out["solid"] = take_vector(std::move(t.values()), {t.nz(), t.ny(), t.nx(), c});
        return out;
      },
      py::arg("exemplar"), py::kw_only(), py::arg("exemplar_y") = py::none(), py::arg("exemplar_z") = py::none(),
      py::arg("views") = "xyz", py::arg("size") = 64, py::arg("constraint") = py::none(),
      py::arg("ctx") = py::none(),
      R"doc(Solid texture from 2D exemplars (Kopf et al. 2007).

exemplar: (H, W) or (H, W, C) uint8/uint16 (scaled to [0, 1]) or float; used for every view
without its own. exemplar_y / exemplar_z: the y- and z-slice exemplars (same channels).
views: active slices, 'xyz' or two of them. constraint: (size, size, size, C + 1) float32:
target values then a weight in [0, 1]. Options (keywords): levels=3, neighborhood=8,
iterations=3, finest_iterations=-1 (rounds at the finest level; 0 = iterations; -1 = 2 from 64 voxels across), r=0.8, pca_variance=0.95, max_pca_dims=32,
search='kcoherence'|'kdtree'|'exact', coherence_k=4, random_candidates=2, ann_eps=2.0, histogram_matching=True, histogram_bins=16, histogram_strength=3
((1 + excess)^-strength re-weighting; 1 = gentle),
mean_shift=False, coherent_upsampling=True, exemplar_values=True, feature_weight=0 (> 0: feature-distance channel), tileable=True,
max_exemplar_size=256 (working resolution: larger exemplars are halved until they fit; 0 = never),
method=SOLID_DEFAULT_METHOD ('optimization': Kopf et al. 2007; 'coordinates': exemplar coordinates after
Dong et al. 2008, which uses levels, iterations, finest_iterations, coordinate_coherence_k=1 (0..16), pca_variance, max_pca_dims,
max_exemplar_size, tileable, memory_budget and seed, and takes no constraint),
memory_budget=0 (default), seed=0. size: min_texture_size(levels, neighborhood) .. SOLID_MAX_SIZE.
Returns {'solid': (Z, Y, X, C) float32, 'energy': [...], 'energy_level': [...]}.)doc");

  m.def(
      "synthesize_image",
      [](const ArrayArg& exemplar, const IntArg& width, const IntArg& height, const ContextArg& ctx_arg,
         const py::kwargs& kw) {
        ExecContext* ctx = context_arg(ctx_arg);
        const Image ex = to_image(exemplar, "exemplar");
        ImageSynthesisOptions opt;
        opt.width = int_arg(width, "width", 1, 16384, "pixels");
        opt.height = int_arg(height, "height", 1, 16384, "pixels");
        set_common(opt, kw);
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
      py::arg("exemplar"), py::kw_only(), py::arg("width") = 128, py::arg("height") = 128,
      py::arg("ctx") = py::none(),
      "2D texture optimisation: exemplar -> (height, width, C) float32 image (tileable=True to tile).\n"
      "Same options as synthesize_solid. Returns {'image': ..., 'energy': [...]}.");
}

}  // namespace exsynth::py_bind
