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
      [](const py::array& a, const py::array& a_prime, const py::array& b, double voxel_size, int levels,
         int fine_size, int coarse_size, int sweeps, double pca_variance, int max_pca_dims, double ann_eps,
         double cull_distance, std::size_t memory_budget, std::uint64_t seed, ExecContext* ctx) {
        for (const auto& [arr, name] : {std::pair<const py::array&, const char*>{a, "a"}, {a_prime, "a_prime"}, {b, "b"}})
          check_shape(arr, name, {-1, -1, -1}, "a (Z, Y, X) float32 volume");
        const GridTransform t = to_transform(py::make_tuple(0.0, 0.0, 0.0), voxel_size);
        const Volume va = to_volume(a, "a", t), vap = to_volume(a_prime, "a_prime", t), vb = to_volume(b, "b", t);
        AnalogyOptions opt;
        opt.levels = levels;
        opt.fine_size = fine_size;
        opt.coarse_size = coarse_size;
        opt.sweeps = sweeps;
        opt.pca_variance = pca_variance;
        opt.max_pca_dims = max_pca_dims;
        opt.ann_eps = ann_eps;
        opt.cull_distance = cull_distance;
        opt.memory_budget = memory_budget ? memory_budget : kDefaultMemoryBudget;
        opt.seed = seed;
        AnalogyResult r;
        {
          py::gil_scoped_release release;
          r = synthesize_analogy(va, vap, vb, opt, ctx);
        }
        py::dict out;
        out["searched"] = r.searched;
        out["culled"] = r.culled;
        out["b_prime"] = from_volume(std::move(r.b_prime));
        return out;
      },
      py::arg("a"), py::arg("a_prime"), py::arg("b"), py::kw_only(), py::arg("voxel_size") = 1.0,
      py::arg("levels") = 2, py::arg("fine_size") = 5, py::arg("coarse_size") = 3, py::arg("sweeps") = 2,
      py::arg("pca_variance") = 0.95, py::arg("max_pca_dims") = 24, py::arg("ann_eps") = 0.5,
      py::arg("cull_distance") = -1.0, py::arg("memory_budget") = std::size_t(0), py::arg("seed") = std::uint64_t(0),
      py::arg("ctx") = static_cast<ExecContext*>(nullptr),
      R"doc(Volume analogy B' : B :: A' : A (Bhat et al. 2004, isotropic variant: global frame,
scanline order). a, a_prime: (Z, Y, X) float32 on one grid; b: (Z, Y, X) float32 on a grid of
the same voxel_size (world units; used for automatic culling of signed distances:
cull_distance < 0 = the fine half-width, 0 = off). Returns {'b_prime', 'searched', 'culled'}.)doc");
}

}  // namespace exsynth::py_bind
