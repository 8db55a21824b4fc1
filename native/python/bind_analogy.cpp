// exsynth._native.synthesize_analogy, analogy_padding
#include <pybind11/pybind11.h>

#include "arguments.hpp"
#include "arrays.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/errors.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_analogy(py::module_& m) {
  m.def(
      "analogy_padding",
      [](const IntArg& fine_size, const IntArg& coarse_size, const py::kwargs& extra) {
        reject_unknown(extra, "fine_size, coarse_size");
        using Lim = AnalogyLimits;
        return analogy_padding(int_arg(fine_size, "fine_size", Lim::min_fine_size, Lim::max_fine_size),
                               int_arg(coarse_size, "coarse_size", Lim::min_coarse_size, Lim::max_coarse_size));
      },
      py::arg("fine_size") = AnalogyOptions{}.fine_size, py::arg("coarse_size") = AnalogyOptions{}.coarse_size,
      "Empty voxels a grid needs around a surface for the analogy's neighbourhoods (fine half-width plus the "
      "coarse one at half resolution; 4 by default): voxelize A, A' and B with at least this padding.");
  m.def(
      "synthesize_analogy",
      [](const ArrayArg& a_arg, const ArrayArg& a_prime_arg, const ArrayArg& b_arg, const OptionalArrayArg& field_a,
         const OptionalArrayArg& field_b, const RealArg& voxel_size, const IntArg& levels,
         const IntArg& fine_size, const IntArg& coarse_size, const IntArg& sweeps,
         const RealArg& pca_variance, const IntArg& max_pca_dims, const RealArg& ann_eps,
         const RealArg& coherence, const RealArg& coherence_slack, const RealArg& cull_distance,
         const BoolArg& remove_debris, const OptionalArrayArg& a_region, const IntArg& memory_budget,
         const IntArg& seed, const ContextArg& ctx_arg, const py::kwargs& extra) {
        reject_unknown(extra, "field_a, field_b, voxel_size, levels, fine_size, coarse_size, sweeps, pca_variance, "
                              "max_pca_dims, ann_eps, coherence, coherence_slack, cull_distance, remove_debris, a_region, "
                              "memory_budget, seed, ctx");
        const char* expected = "a (Z, Y, X) float32 volume";
        const py::array a = array_arg(a_arg, "a", expected), a_prime = array_arg(a_prime_arg, "a_prime", expected),
                        b = array_arg(b_arg, "b", expected);
        for (const auto& [arr, name] : {std::pair<const py::array&, const char*>{a, "a"}, {a_prime, "a_prime"}, {b, "b"}})
          check_shape(arr, name, {-1, -1, -1}, expected);
        if (field_a.is_none() != field_b.is_none())
          throw InvalidInput("give both field_a and field_b (a field-aligned analogy) or neither (isotropic)");
        const GridTransform t = to_transform(py::make_tuple(0.0, 0.0, 0.0), voxel_size);
        const Volume va = to_volume(a, "a", t), vap = to_volume(a_prime, "a_prime", t), vb = to_volume(b, "b", t);
        Volume fa, fb;
        if (!field_a.is_none()) {
          const py::array arr_a = array_arg(field_a, "field_a", "a (Z, Y, X, 3) float32 direction per voxel of A");
          const py::array arr_b = array_arg(field_b, "field_b", "a (Z, Y, X, 3) float32 direction per voxel of B");
          check_shape(arr_a, "field_a", {-1, -1, -1, 3}, "a (Z, Y, X, 3) float32 direction per voxel of A");
          check_shape(arr_b, "field_b", {-1, -1, -1, 3}, "a (Z, Y, X, 3) float32 direction per voxel of B");
          fa = to_volume(arr_a, "field_a", t);
          fb = to_volume(arr_b, "field_b", t);
        }
        using Lim = AnalogyLimits;
        AnalogyOptions opt;
        opt.levels = int_arg(levels, "levels", 1, Lim::max_levels);
        opt.fine_size = int_arg(fine_size, "fine_size", Lim::min_fine_size, Lim::max_fine_size, "odd");
        opt.coarse_size = int_arg(coarse_size, "coarse_size", Lim::min_coarse_size, Lim::max_coarse_size, "odd");
        opt.sweeps = int_arg(sweeps, "sweeps", 1, Lim::max_sweeps);
        opt.pca_variance = real_arg(pca_variance, "pca_variance", 0.0, 1.0, Ends::OpenLow);
        opt.max_pca_dims = int_arg(max_pca_dims, "max_pca_dims", 1, Lim::max_pca_dims);
        opt.ann_eps = real_arg(ann_eps, "ann_eps", 0.0, kInf);
        opt.coherence = real_arg(coherence, "coherence", 0.0, kInf);
        opt.coherence_slack = real_arg(coherence_slack, "coherence_slack", 0.0, kInf);
        opt.cull_distance = real_arg(cull_distance, "cull_distance", -kInf, kInf, Ends::Closed,
                                     "world units; < 0 = automatic, 0 = off");
        opt.remove_debris = bool_arg(remove_debris, "remove_debris");
        if (!a_region.is_none()) {
          const py::array arr = array_arg(a_region, "a_region", "a (Z, Y, X) float32 mask on A's grid");
          check_shape(arr, "a_region", {-1, -1, -1}, "a (Z, Y, X) float32 mask on A's grid (> 0.5 = learn here)");
          opt.a_region = to_volume(arr, "a_region", t);
        }
        opt.memory_budget = memory_budget_arg(memory_budget);
        opt.seed = seed_arg(seed);
        ExecContext* ctx = context_arg(ctx_arg);
        AnalogyResult r;
        {
          py::gil_scoped_release release;
          r = fa.empty() ? synthesize_analogy(va, vap, vb, opt, ctx) : synthesize_analogy(va, vap, fa, vb, fb, opt, ctx);
        }
        py::dict out;
        out["searched"] = r.searched;
        out["culled"] = r.culled;
        out["coherent"] = r.coherent;
        out["debris"] = r.debris;
        out["ann_skipped"] = r.ann_skipped;
        out["b_prime"] = from_volume(std::move(r.b_prime));
        return out;
      },
      py::arg("a"), py::arg("a_prime"), py::arg("b"), py::kw_only(), py::arg("field_a") = py::none(),
      py::arg("field_b") = py::none(), py::arg("voxel_size") = 1.0, py::arg("levels") = AnalogyOptions{}.levels,
      py::arg("fine_size") = AnalogyOptions{}.fine_size, py::arg("coarse_size") = AnalogyOptions{}.coarse_size,
      py::arg("sweeps") = AnalogyOptions{}.sweeps, py::arg("pca_variance") = AnalogyOptions{}.pca_variance,
      py::arg("max_pca_dims") = AnalogyOptions{}.max_pca_dims, py::arg("ann_eps") = AnalogyOptions{}.ann_eps,
      py::arg("coherence") = AnalogyOptions{}.coherence, py::arg("coherence_slack") = AnalogyOptions{}.coherence_slack,
      py::arg("cull_distance") = AnalogyOptions{}.cull_distance, py::arg("remove_debris") = AnalogyOptions{}.remove_debris,
      py::arg("a_region") = py::none(), py::arg("memory_budget") = 0, py::arg("seed") = 0, py::arg("ctx") = py::none(),
      R"doc(Volume analogy B' : B :: A' : A (Bhat et al. 2004). a, a_prime: (Z, Y, X) float32 on one
grid; b: (Z, Y, X) float32 on a grid of the same voxel_size (world units; used for automatic
culling of signed distances: cull_distance < 0 = the fine half-width, 0 = off).
field_a / field_b: (Z, Y, X, 3) directions on A's / B's grid for the field-aligned analogy
(frames T, B = T x N, N and sweep order); both None = isotropic (global frame, scanline order).
coherence: Hertzmann's kappa (0 = nearest neighbour only); remove_debris: drop parts of B' that
float free of B (signed distances only). a_region: optional (Z, Y, X) mask on A's grid, > 0.5 where
A' shows the change to learn (e.g. near faces selected on a model; None = wherever A' differs). Returns {'b_prime', 'searched', 'coherent', 'culled',
'debris'}.)doc");
}

}  // namespace exsynth::py_bind
