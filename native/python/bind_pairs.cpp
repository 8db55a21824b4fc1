// exsynth._native.make_exemplar_pair
#include <pybind11/pybind11.h>

#include <string>

#include "arrays.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/pairs.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

constexpr const char* kOptionNames =
    "thickness, spacing, feature_radius, feature_height, jitter, cylinder_radius, groove_direction, "
    "sphere_radius, dilation, memory_budget";

PairPreset to_preset(const std::string& s) {
  if (s == "spikes") return PairPreset::Spikes;
  if (s == "pits") return PairPreset::Pits;
  if (s == "holes") return PairPreset::Holes;
  if (s == "grooves") return PairPreset::Grooves;
  if (s == "dilate") return PairPreset::Dilate;
  throw InvalidInput("preset must be 'spikes', 'pits', 'holes', 'grooves' or 'dilate', got '" + s + "'");
}

template <class T>
T option(const py::handle& v, const std::string& name, const char* expected) {
  try {
    return v.cast<T>();
  } catch (const py::cast_error&) {
    throw InvalidInput("option '" + name + "' must be " + expected + ", got " +
                       std::string(py::str(py::type::of(v).attr("__name__"))));
  }
}

void apply_options(PairOptions& o, const py::kwargs& kw) {
  for (auto item : kw) {
    const std::string k = py::str(item.first);
    const py::handle v = item.second;
    if (k == "thickness") o.thickness = option<double>(v, k, "a number");
    else if (k == "spacing") o.spacing = option<double>(v, k, "a number");
    else if (k == "feature_radius") o.feature_radius = option<double>(v, k, "a number");
    else if (k == "feature_height") o.feature_height = option<double>(v, k, "a number");
    else if (k == "jitter") o.jitter = option<double>(v, k, "a number");
    else if (k == "cylinder_radius") o.cylinder_radius = option<double>(v, k, "a number");
    else if (k == "sphere_radius") o.sphere_radius = option<double>(v, k, "a number");
    else if (k == "dilation") o.dilation = option<double>(v, k, "a number");
    else if (k == "groove_direction") {
      const std::string d = option<std::string>(v, k, "'around' or 'along'");
      if (d == "around") o.groove_direction = GrooveDirection::Around;
      else if (d == "along") o.groove_direction = GrooveDirection::Along;
      else throw InvalidInput("groove_direction must be 'around' or 'along', got '" + d + "'");
    } else if (k == "memory_budget") {
      const std::size_t b = option<std::size_t>(v, k, "a non-negative integer (bytes; 0 = default)");
      o.memory_budget = b ? b : kDefaultMemoryBudget;
    } else {
      throw InvalidInput("unknown option '" + k + "'; options: " + kOptionNames);
    }
  }
}

}  // namespace

void bind_pairs(py::module_& m) {
  m.def(
      "check_exemplar_pair",
      [](const std::string& preset, int resolution, const py::kwargs& kw) {
        PairOptions opt;
        opt.resolution = resolution;
        apply_options(opt, kw);
        validate_pair_options(to_preset(preset), opt);
      },
      py::arg("preset") = "spikes", py::kw_only(), py::arg("resolution") = 64,
      R"doc(Raise InvalidInputError if make_exemplar_pair would refuse these options (same
arguments, nothing built): lets a caller refuse a job before it starts.)doc");

  m.def(
      "make_exemplar_pair",
      [](const std::string& preset, int resolution, std::uint64_t seed, ExecContext* ctx, const py::kwargs& kw) {
        PairOptions opt;
        opt.resolution = resolution;
        opt.seed = seed;
        apply_options(opt, kw);
        const PairPreset p = to_preset(preset);
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
      py::arg("preset") = "spikes", py::kw_only(), py::arg("resolution") = 64, py::arg("seed") = std::uint64_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
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
