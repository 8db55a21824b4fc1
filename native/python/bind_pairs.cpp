// exsynth._native.make_exemplar_pair
#include <pybind11/pybind11.h>

#include <string>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/pairs.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

constexpr const char* kOptionNames =
    "thickness, spacing, feature_radius, feature_height, jitter, cylinder_radius, groove_direction, "
    "sphere_radius, dilation, memory_budget";

constexpr const char* kPresetNames = "'spikes', 'pits', 'holes', 'grooves' or 'dilate'";

PairPreset to_preset(const std::string& s) {
  for (PairPreset p : kPairPresets)
    if (s == pair_preset_name(p)) return p;
  throw InvalidInput("preset must be 'spikes', 'pits', 'holes', 'grooves' or 'dilate', got '" + s + "'");
}

void apply_options(PairOptions& o, const py::kwargs& kw) {
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    // Lengths are world units on the [-1, 1] grid; the core checks how they fit together.
    auto length = [&](double& field) { field = real_arg(v, k, 0.0, kInf, Ends::OpenLow, "world units"); };
    if (k == "thickness") length(o.thickness);
    else if (k == "spacing") length(o.spacing);
    else if (k == "feature_radius") length(o.feature_radius);
    else if (k == "feature_height") length(o.feature_height);
    else if (k == "jitter") o.jitter = real_arg(v, k, 0.0, 0.25, Ends::Closed, "a fraction of spacing");
    else if (k == "cylinder_radius") length(o.cylinder_radius);
    else if (k == "sphere_radius") length(o.sphere_radius);
    else if (k == "dilation") length(o.dilation);
    else if (k == "groove_direction") {
      const std::string d = string_arg(v, k, "'around' or 'along'");
      if (d == "around") o.groove_direction = GrooveDirection::Around;
      else if (d == "along") o.groove_direction = GrooveDirection::Along;
      else throw InvalidInput("groove_direction must be 'around' or 'along', got '" + d + "'");
    } else if (k == "memory_budget") {
      o.memory_budget = memory_budget_arg(v, k);
    } else {
      throw InvalidInput("unknown option '" + k + "'; options: " + kOptionNames);
    }
  }
}

}  // namespace

void bind_pairs(py::module_& m) {
  {
    py::list names;
    for (PairPreset p : kPairPresets) names.append(pair_preset_name(p));
    m.attr("PAIR_PRESETS") = py::tuple(names);
  }
  m.attr("PAIR_MIN_RESOLUTION") = kMinPairResolution;
  m.attr("PAIR_MAX_RESOLUTION") = kMaxPairResolution;
  m.attr("PAIR_DETAIL_RESOLUTION") = kPairDetailResolution;
  m.attr("MAX_PATTERN_RESOLUTION") = kMaxPatternResolution;
  {  // The shape options' defaults (world units on the pair's [-1, 1] cube), as make_exemplar_pair takes them.
    const PairOptions d;
    py::dict defaults;
    defaults["thickness"] = d.thickness;
    defaults["spacing"] = d.spacing;
    defaults["feature_radius"] = d.feature_radius;
    defaults["feature_height"] = d.feature_height;
    defaults["jitter"] = d.jitter;
    defaults["cylinder_radius"] = d.cylinder_radius;
    defaults["sphere_radius"] = d.sphere_radius;
    defaults["dilation"] = d.dilation;
    m.attr("PAIR_DEFAULTS") = defaults;
  }
  m.def(
      "resolution_for_pattern",
      [](const IntArg& resolution, const RealArg& pattern_scale, const py::kwargs& extra) {
        reject_unknown(extra, "resolution, pattern_scale");
        return resolution_for_pattern(
            int_arg(resolution, "resolution", 1, kMaxPairResolution * 64, "voxels along B's longest side"),
            real_arg(pattern_scale, "pattern_scale", 0.0, kInf, Ends::OpenLow, "a fraction of B's longest side"));
      },
      py::arg("resolution"), py::arg("pattern_scale"),
      "B's resolution for a built-in pair covering pattern_scale of B's longest side: resolution, raised\n"
      "until the pair has PAIR_DETAIL_RESOLUTION voxels across (its features keep their shape), but not\n"
      "past max(resolution, MAX_PATTERN_RESOLUTION).");
  m.def(
      "check_exemplar_pair",
      [](const StrArg& preset, const IntArg& resolution, const py::kwargs& kw) {
        PairOptions opt;
        opt.resolution = int_arg(resolution, "resolution", kMinPairResolution, kMaxPairResolution, "voxels per grid edge");
        apply_options(opt, kw);
        const PairPreset p = to_preset(string_arg(preset, "preset", kPresetNames));
        validate_pair_options(p, opt);
      },
      py::arg("preset") = "spikes", py::kw_only(), py::arg("resolution") = 64,
      R"doc(Raise InvalidInputError if make_exemplar_pair would refuse these options (same
arguments, nothing built): lets a caller refuse a job before it starts.)doc");

  m.def(
      "make_exemplar_pair",
      [](const StrArg& preset, const IntArg& resolution, const IntArg& seed, const ContextArg& ctx_arg,
         const py::kwargs& kw) {
        PairOptions opt;
        opt.resolution = int_arg(resolution, "resolution", kMinPairResolution, kMaxPairResolution, "voxels per grid edge");
        opt.seed = seed_arg(seed);
        ExecContext* ctx = context_arg(ctx_arg);
        apply_options(opt, kw);
        const PairPreset p = to_preset(string_arg(preset, "preset", kPresetNames));
        ExemplarPair pair;
        {
          py::gil_scoped_release release;
          pair = make_exemplar_pair(p, opt, ctx);
        }
        const GridTransform t = pair.a.transform();
        py::dict out;
        out["origin"] = take_vector(std::vector<double>(t.origin.begin(), t.origin.end()), {3});
        out["voxel_size"] = t.voxel_size;
        out["a"] = from_volume(std::move(pair.a));
        out["a_prime"] = from_volume(std::move(pair.a_prime));
        out["field"] = from_volume(std::move(pair.field_a));
        return out;
      },
      py::arg("preset") = "spikes", py::kw_only(), py::arg("resolution") = 64, py::arg("seed") = 0, py::arg("ctx") = py::none(),
      R"doc(A built-in exemplar pair A -> A' (Bhat et al. 2004, Figures 2 and 7) as signed distances.

preset: 'spikes' | 'pits' | 'holes' (a horizontal slab -> with cones on top / spherical dents /
holes through it), 'grooves' (a cylinder around z -> with grooves around or along it), 'dilate'
(a sphere -> a larger sphere). The grid is resolution^3 voxels (8..512) spanning [-1, 1]^3.
Shape options (keywords, world units): thickness=0.4, spacing=0.5, feature_radius=0.12,
feature_height=0.3 (spikes), jitter=0.0 (0..0.25 of spacing, seeded by seed),
cylinder_radius=0.6, groove_direction='around'|'along', sphere_radius=0.5, dilation=0.15,
memory_budget=0 (default).
Returns a dict: a, a_prime (Z, Y, X) float32 signed distances, positive outside; field
(Z, Y, X, 3) float32 unit direction per voxel (slabs and dilate: +x; grooves: along them);
origin (3,) float64, the centre of voxel [0, 0, 0]; voxel_size. Releases the GIL; reports to
ctx; raises InvalidInputError, OverBudgetError, CancelledError.)doc");
}

}  // namespace exsynth::py_bind
