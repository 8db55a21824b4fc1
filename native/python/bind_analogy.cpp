// exsynth._native.synthesize_analogy
#include <pybind11/pybind11.h>

#include "arrays.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/errors.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {

void bind_analogy(py::module_& m) {
  m.def(
      "synthesize_analogy",
      [](const py::array& a, const py::array& a_prime, const py::array& b, const py::object& field_a,
         const py::object& field_b, double voxel_size, int levels, int fine_size, int coarse_size, int sweeps,
         double pca_variance, int max_pca_dims, double ann_eps, double coherence, double coherence_slack, double cull_distance, bool remove_debris, const py::object& a_region,
         std::size_t memory_budget, std::uint64_t seed, ExecContext* ctx) {
        for (const auto& [arr, name] : {std::pair<const py::array&, const char*>{a, "a"}, {a_prime, "a_prime"}, {b, "b"}})
          check_shape(arr, name, {-1, -1, -1}, "a (Z, Y, X) float32 volume");
        if (field_a.is_none() != field_b.is_none())
          throw InvalidInput("give both field_a and field_b (a field-aligned analogy) or neither (isotropic)");
        const GridTransform t = to_transform(py::make_tuple(0.0, 0.0, 0.0), voxel_size);
        const Volume va = to_volume(a, "a", t), vap = to_volume(a_prime, "a_prime", t), vb = to_volume(b, "b", t);
        Volume fa, fb;
        if (!field_a.is_none()) {
          const py::array arr_a = py::array::ensure(field_a), arr_b = py::array::ensure(field_b);
          if (!arr_a || !arr_b) throw InvalidInput("field_a and field_b must be arrays of shape (Z, Y, X, 3)");
          check_shape(arr_a, "field_a", {-1, -1, -1, 3}, "a (Z, Y, X, 3) float32 direction per voxel of A");
          check_shape(arr_b, "field_b", {-1, -1, -1, 3}, "a (Z, Y, X, 3) float32 direction per voxel of B");
          fa = to_volume(arr_a, "field_a", t);
          fb = to_volume(arr_b, "field_b", t);
        }
        AnalogyOptions opt;
        opt.levels = levels;
        opt.fine_size = fine_size;
        opt.coarse_size = coarse_size;
        opt.sweeps = sweeps;
        opt.pca_variance = pca_variance;
        opt.max_pca_dims = max_pca_dims;
        opt.ann_eps = ann_eps;
        opt.coherence = coherence;
        opt.coherence_slack = coherence_slack;
        opt.cull_distance = cull_distance;
        opt.remove_debris = remove_debris;
        if (!a_region.is_none()) {
          const py::array arr = py::array::ensure(a_region);
          if (!arr) throw InvalidInput("a_region must be a (Z, Y, X) array on A's grid");
          check_shape(arr, "a_region", {-1, -1, -1}, "a (Z, Y, X) float32 mask on A's grid (> 0.5 = learn here)");
          opt.a_region = to_volume(arr, "a_region", t);
        }
        opt.memory_budget = memory_budget ? memory_budget : kDefaultMemoryBudget;
        opt.seed = seed;
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
      py::arg("field_b") = py::none(), py::arg("voxel_size") = 1.0, py::arg("levels") = 2, py::arg("fine_size") = 5, py::arg("coarse_size") = 3, py::arg("sweeps") = 2,
      py::arg("pca_variance") = 0.95, py::arg("max_pca_dims") = 24, py::arg("ann_eps") = 0.5, py::arg("coherence") = 1.0,
      py::arg("coherence_slack") = 0.05,
      py::arg("cull_distance") = -1.0, py::arg("remove_debris") = true,
      py::arg("a_region") = py::none(), py::arg("memory_budget") = std::size_t(0), py::arg("seed") = std::uint64_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
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
