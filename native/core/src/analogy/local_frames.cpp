#include "analogy/local_frames.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "exsynth/parallel.hpp"
#include "exsynth/sample.hpp"
#include "field/tangent.hpp"
#include "grid/gradient.hpp"

namespace exsynth::analogy {
namespace {

// Eigen's diagonal (Jacobi) preconditioner, applied once per CG iteration:
// the one place inside Eigen's solver loop where a cancel can be checked
// without changing a single operation of the solve.
class CancellablePreconditioner : public Eigen::DiagonalPreconditioner<double> {
 public:
  void watch(StageProgress* progress) { progress_ = progress; }
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    if (progress_) {
      progress_->check();
      progress_->advance(1);
    }
    return Eigen::DiagonalPreconditioner<double>::solve(b);
  }

 private:
  StageProgress* progress_ = nullptr;
};

}  // namespace

std::vector<Frame> frames_at(const Volume& sdf, const Volume& field, int scale,
                             const std::vector<std::uint32_t>& voxels, std::size_t* bad_count,
                             StageProgress& progress) {
  std::vector<Frame> frames(voxels.size(), Frame::Identity());
  if (field.empty()) {  // the global frame: nothing to compute
    progress.check();
    progress.advance(voxels.size());
    if (bad_count) *bad_count = 0;
    return frames;
  }
  const int nx = sdf.nx(), ny = sdf.ny();
  std::vector<unsigned char> bad(voxels.size(), 0);
  parallel_chunks(voxels.size(), 4096, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t v = voxels[i];
      const int x = int(v % std::uint32_t(nx)), y = int((v / std::uint32_t(nx)) % std::uint32_t(ny)),
                z = int(v / (std::uint32_t(nx) * std::uint32_t(ny)));
      const Eigen::Vector3f n = grid::unit_normal(sdf, x, y, z);
      float t[3];
      sample_trilinear(field, double(x) * scale, double(y) * scale, double(z) * scale, t);
      Eigen::Vector3f tv(t[0], t[1], t[2]);
      if (!tv.allFinite() || tv.norm() < 1e-6f) {
        bad[i] = 1;
        tv = Eigen::Vector3f::UnitX();
      }
      const Eigen::Vector3f tt =
          field::unit_tangent_or(tv.cast<double>(), n.cast<double>(), 1e-4, Eigen::Vector3d::UnitX()).cast<float>();
      frames[i].col(0) = tt;
      frames[i].col(1) = tt.cross(n);
      frames[i].col(2) = n;
    }
  });
  if (bad_count) *bad_count = std::size_t(std::count(bad.begin(), bad.end(), 1));
  return frames;
}

std::vector<float> sweep_distance(int nx, int ny, int nz, const std::vector<std::uint32_t>& voxels,
                                  const std::vector<Frame>& frames, const std::vector<float>& guess,
                                  int iterations, StageProgress& progress) {
  const std::size_t n = voxels.size();
  std::vector<float> phi(n, 0.0f);
  if (n == 0) return phi;
  auto row_of = [&](std::uint32_t v) -> std::ptrdiff_t {
    const auto it = std::lower_bound(voxels.begin(), voxels.end(), v);
    return it != voxels.end() && *it == v ? it - voxels.begin() : -1;
  };
  // Least squares over the edges (i, j) to the +x, +y, +z neighbours:
  // phi_j - phi_i = mean T along the edge. Normal equations: a graph
  // Laplacian (degree on the diagonal, -1 per neighbour); a tiny diagonal
  // fixes each component's free constant. Rows are written in column order
  // straight into the compressed matrix: Eigen's setFromTriplets on 7n
  // triplets took ~0.2 s at 10^6 voxels with no cancel check inside.
  const std::uint32_t step[3] = {1u, std::uint32_t(nx), std::uint32_t(nx) * std::uint32_t(ny)};
  const int dims[3] = {nx, ny, nz};
  Eigen::SparseMatrix<double, Eigen::RowMajor> lap{Eigen::Index(n), Eigen::Index(n)};
  lap.reserve(Eigen::VectorXi::Constant(Eigen::Index(n), 7));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(n));
  for (std::size_t i = 0; i < n; ++i) {
    progress.check_every(i);
    const std::uint32_t v = voxels[i];
    const int c[3] = {int(v % std::uint32_t(nx)), int((v / std::uint32_t(nx)) % std::uint32_t(ny)),
                      int(v / (std::uint32_t(nx) * std::uint32_t(ny)))};
    std::array<std::ptrdiff_t, 6> nb;  // rows of the -z -y -x +x +y +z neighbours, -1 = none
    for (int a = 0; a < 3; ++a) {
      nb[std::size_t(2 - a)] = c[a] > 0 ? row_of(v - step[a]) : -1;
      nb[std::size_t(3 + a)] = c[a] + 1 < dims[a] ? row_of(v + step[a]) : -1;
    }
    int degree = 0;
    for (const std::ptrdiff_t j : nb) degree += j >= 0;
    for (int k = 0; k < 3; ++k)
      if (nb[std::size_t(k)] >= 0) lap.insert(Eigen::Index(i), Eigen::Index(nb[std::size_t(k)])) = -1.0;
    lap.insert(Eigen::Index(i), Eigen::Index(i)) = 1e-6 + degree;
    for (int k = 3; k < 6; ++k)
      if (nb[std::size_t(k)] >= 0) lap.insert(Eigen::Index(i), Eigen::Index(nb[std::size_t(k)])) = -1.0;
    for (int a = 0; a < 3; ++a) {
      const std::ptrdiff_t j = nb[std::size_t(3 + a)];
      if (j < 0) continue;
      const double d = 0.5 * double(frames[i](a, 0) + frames[std::size_t(j)](a, 0));
      rhs[Eigen::Index(i)] -= d;
      rhs[Eigen::Index(j)] += d;
    }
  }
  lap.makeCompressed();
  progress.check();
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double, Eigen::RowMajor>, Eigen::Lower | Eigen::Upper, CancellablePreconditioner> cg;
  cg.setMaxIterations(iterations);
  cg.setTolerance(1e-5);
  cg.compute(lap);
  cg.preconditioner().watch(&progress);
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(Eigen::Index(n));
  if (guess.size() == n)
    for (std::size_t i = 0; i < n; ++i) x0[Eigen::Index(i)] = guess[i];
  const Eigen::VectorXd x = cg.solveWithGuess(rhs, x0);
  for (std::size_t i = 0; i < n; ++i) phi[i] = float(x[Eigen::Index(i)]);
  return phi;
}

}  // namespace exsynth::analogy
