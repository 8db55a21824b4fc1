#pragma once
// Solver for the diffusion's sparse systems: conjugate gradients
// preconditioned by a smoothed-aggregation algebraic multigrid V-cycle.
//
// Why not a sparse Cholesky: its fill on a surface mesh grows as
// V log V and its cost as V^1.5; Eigen's simplicial LDLT took 0.55 s on a
// 104k-vertex mesh and 6 s on a 164k-vertex icosphere (AMD ordering), and it
// cannot be cancelled. Multigrid costs O(V) per iteration and needs ~10-20
// iterations whatever the size, because the aggregates reproduce constants
// exactly, which is the near-null space of a Laplacian with few fixed
// vertices (the slowest part of Turk's repeated averaging). Systems up to
// `direct_size` unknowns are factorised directly (also the coarsest level).
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "exsynth/exec_context.hpp"

namespace exsynth::field {

using SparseSym = Eigen::SparseMatrix<double>;  ///< symmetric: column i is row i
using Block = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct SpdSolveOptions {
  int direct_size = 4000;    ///< at most this many unknowns: LDLT (also the coarsest level)
  double tolerance = 1e-7;   ///< relative residual ||b - A x|| / ||b|| per column (enough for float output)
  int max_iterations = 200;
};

struct SpdSolveStats {
  int levels = 1;      ///< 1 = direct solve
  int iterations = 0;  ///< PCG iterations (0 for direct)
  double residual = 0; ///< worst relative residual over the columns
};

/// Smoothed-aggregation hierarchy; apply() is one symmetric V-cycle
/// (forward Gauss-Seidel down, backward up, LDLT at the bottom).
class Multigrid {
 public:
  Multigrid(const SparseSym& a, int direct_size);
  void apply(const Block& r, Block& z) const { cycle(0, r, z); }
  int levels() const { return int(levels_.size()) + 1; }

 private:
  struct Level {
    SparseSym a;      ///< this level's operator
    SparseSym p, pt;  ///< prolongation to this level from the next coarser one, and its transpose
    Eigen::VectorXd inv_diag;
  };
  void cycle(std::size_t l, const Block& b, Block& x) const;
  std::vector<Level> levels_;
  Eigen::SimplicialLDLT<SparseSym> coarse_;
};

/// Solves A X = B for an SPD M-matrix A (a Laplacian with fixed vertices
/// eliminated). Checks cancel once per iteration and advances `progress`
/// (made with kProgressUnits units) as the residual falls. Falls back to the
/// direct factorisation if the iteration does not reach the tolerance.
constexpr std::size_t kProgressUnits = 1000;
Block solve_spd(const SparseSym& a, const Block& b, const SpdSolveOptions& opt, StageProgress* progress = nullptr,
                SpdSolveStats* stats = nullptr);

}  // namespace exsynth::field
