#include "field/multigrid.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "exsynth/errors.hpp"

namespace exsynth::field {
namespace {

// Connections weaker than this (relative to the geometric mean of the two
// diagonals) do not pull vertices into one aggregate: a standard choice for
// smoothed aggregation; it also keeps the clamped near-zero cotangent
// weights of obtuse triangles from shaping the aggregates.
constexpr double kStrength = 0.08;

// y = M^T x, one output row per column of M: rows are independent, so the
// result does not depend on how TBB splits them. For a symmetric A this is
// A x; with M = P it restricts, with M = P^T it prolongs.
void gather(const SparseSym& m, const Block& x, Block& y) {
  y.resize(m.cols(), 3);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, m.cols(), 2048), [&](const auto& r) {
    for (Eigen::Index i = r.begin(); i < r.end(); ++i) {
      Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
      for (SparseSym::InnerIterator it(m, i); it; ++it) s += it.value() * x.row(it.row());
      y.row(i) = s;
    }
  });
}

void gauss_seidel(const SparseSym& a, const Eigen::VectorXd& inv_diag, const Block& b, Block& x, bool forward) {
  const Eigen::Index n = a.cols();
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index i = forward ? k : n - 1 - k;
    Eigen::RowVector3d s = b.row(i);
    for (SparseSym::InnerIterator it(a, i); it; ++it)
      if (it.row() != i) s -= it.value() * x.row(it.row());
    x.row(i) = s * inv_diag[i];
  }
}

// Greedy aggregation in vertex order (deterministic): roots whose strong
// neighbours are all free take them; the rest join their strongest
// aggregated neighbour; leftovers start aggregates of their own.
std::vector<int> aggregate(const SparseSym& a, const Eigen::VectorXd& diag, int& count) {
  const Eigen::Index n = a.cols();
  auto strong = [&](Eigen::Index i, const SparseSym::InnerIterator& it) {
    return it.row() != i && std::abs(it.value()) >= kStrength * std::sqrt(diag[i] * diag[it.row()]);
  };
  std::vector<int> agg(std::size_t(n), -1);
  count = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    bool free = true, any = false;
    for (SparseSym::InnerIterator it(a, i); it; ++it) {
      if (!strong(i, it)) continue;
      any = true;
      free = free && agg[it.row()] < 0;
    }
    if (!free || !any) continue;
    agg[i] = count;
    for (SparseSym::InnerIterator it(a, i); it; ++it)
      if (strong(i, it)) agg[it.row()] = count;
    ++count;
  }
  const std::vector<int> roots = agg;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    double best = 0;
    for (SparseSym::InnerIterator it(a, i); it; ++it)
      if (strong(i, it) && roots[it.row()] >= 0 && std::abs(it.value()) > best) {
        best = std::abs(it.value());
        agg[i] = roots[it.row()];
      }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    agg[i] = count;
    for (SparseSym::InnerIterator it(a, i); it; ++it)
      if (strong(i, it) && agg[it.row()] < 0) agg[it.row()] = count;
    ++count;
  }
  return agg;
}

void factorize(Eigen::SimplicialLDLT<SparseSym>& ldlt, const SparseSym& a) {
  ldlt.compute(a);
  if (ldlt.info() != Eigen::Success)
    throw Error("direction field: the averaging system could not be factorised (report this mesh as a bug)");
}

}  // namespace

Multigrid::Multigrid(const SparseSym& a0, int direct_size) {
  SparseSym a = a0;
  while (a.cols() > direct_size) {
    const Eigen::VectorXd diag = a.diagonal();
    int count = 0;
    const std::vector<int> agg = aggregate(a, diag, count);
    if (count > 0.8 * double(a.cols())) break;  // barely coarsens: solve this level directly
    // Smoothed prolongator P = (I - w D^-1 A) P0, with P0 the piecewise-
    // constant aggregate indicator and w = (4/3) / (Gershgorin bound of
    // lambda_max(D^-1 A)), written out row by row (row i: +1 at agg[i], and
    // -w a_ij / a_ii at agg[j] for each j in row i).
    double bound = 0;
    for (Eigen::Index i = 0; i < a.cols(); ++i) {
      double row = 0;
      for (SparseSym::InnerIterator it(a, i); it; ++it) row += std::abs(it.value());
      bound = std::max(bound, row / diag[i]);
    }
    const double omega = (4.0 / 3.0) / bound;
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(std::size_t(a.nonZeros() + a.cols()));
    for (Eigen::Index i = 0; i < a.cols(); ++i) {
      entries.emplace_back(int(i), agg[i], 1.0);
      for (SparseSym::InnerIterator it(a, i); it; ++it)
        entries.emplace_back(int(i), agg[it.row()], -omega * it.value() / diag[i]);
    }
    Level lv;
    lv.inv_diag = diag.cwiseInverse();
    lv.p.resize(a.cols(), count);
    lv.p.setFromTriplets(entries.begin(), entries.end());
    lv.pt = lv.p.transpose();
    SparseSym coarse = lv.pt * SparseSym(a * lv.p);
    lv.a = std::move(a);
    levels_.push_back(std::move(lv));
    a = std::move(coarse);
  }
  factorize(coarse_, a);
}

void Multigrid::cycle(std::size_t l, const Block& b, Block& x) const {
  if (l == levels_.size()) {
    x = coarse_.solve(b);
    return;
  }
  const Level& lv = levels_[l];
  x = Block::Zero(b.rows(), 3);
  gauss_seidel(lv.a, lv.inv_diag, b, x, true);
  Block ax, rc, xc, correction;
  gather(lv.a, x, ax);
  gather(lv.p, b - ax, rc);
  cycle(l + 1, rc, xc);
  gather(lv.pt, xc, correction);
  x += correction;
  gauss_seidel(lv.a, lv.inv_diag, b, x, false);  // backward: the cycle stays symmetric, as CG needs
}

Block solve_spd(const SparseSym& a, const Block& b, const SpdSolveOptions& opt, StageProgress* progress,
                SpdSolveStats* stats) {
  SpdSolveStats local;
  SpdSolveStats& st = stats ? *stats : local;
  auto direct = [&] {
    Eigen::SimplicialLDLT<SparseSym> ldlt;
    factorize(ldlt, a);
    return Block(ldlt.solve(b));
  };
  if (a.cols() <= opt.direct_size) {
    st = {};
    return direct();
  }
  const Multigrid mg(a, opt.direct_size);
  st.levels = mg.levels();

  // Preconditioned CG on the three columns at once (one sweep over A serves
  // all three), each with its own step lengths; a converged column stops moving.
  Block x = Block::Zero(b.rows(), 3), r = b, z, p, q;
  const Eigen::RowVector3d bnorm = b.colwise().norm();
  auto done = [&](int k) { return r.col(k).norm() <= opt.tolerance * bnorm[k]; };
  auto worst_residual = [&] {
    double worst = 0;
    for (int k = 0; k < 3; ++k)
      if (bnorm[k] > 0) worst = std::max(worst, r.col(k).norm() / bnorm[k]);
    return worst;
  };
  mg.apply(r, z);
  p = z;
  Eigen::RowVector3d rz = (r.cwiseProduct(z)).colwise().sum();
  // Progress: how far the worst column's residual has come down to the
  // tolerance, on a log scale, in units of 1/1000 of the stage.
  std::size_t reported = 0;
  auto report = [&] {
    const double worst = worst_residual();
    const double f = worst > 0 ? std::clamp(std::log(worst) / std::log(opt.tolerance), 0.0, 1.0) : 1.0;
    const auto units = std::size_t(f * kProgressUnits);
    if (units <= reported) return;
    progress->advance(units - reported);
    reported = units;
  };
  for (st.iterations = 0; st.iterations < opt.max_iterations; ++st.iterations) {
    if (done(0) && done(1) && done(2)) break;
    if (progress) {
      progress->check();
      report();
    }
    gather(a, p, q);
    const Eigen::RowVector3d pq = (p.cwiseProduct(q)).colwise().sum();
    for (int k = 0; k < 3; ++k) {
      if (done(k) || pq[k] <= 0) continue;
      const double alpha = rz[k] / pq[k];
      x.col(k) += alpha * p.col(k);
      r.col(k) -= alpha * q.col(k);
    }
    mg.apply(r, z);
    const Eigen::RowVector3d rz_new = (r.cwiseProduct(z)).colwise().sum();
    for (int k = 0; k < 3; ++k) {
      const double beta = rz[k] > 0 ? rz_new[k] / rz[k] : 0.0;
      p.col(k) = z.col(k) + beta * p.col(k);
    }
    rz = rz_new;
  }
  st.residual = worst_residual();
  // Never seen on meshes, but a system the hierarchy cannot handle must not
  // give a wrong field: pay for the exact factorisation instead.
  if (st.residual > opt.tolerance) {
    st.levels = 1;
    return direct();
  }
  return x;
}

}  // namespace exsynth::field
