#include "field/laplacian.hpp"

#include <algorithm>
#include <numeric>

#include <Eigen/Sparse>

#include "exsynth/errors.hpp"

namespace exsynth::field {

std::vector<Edge> edge_weights(const TriangleMesh& mesh, FieldWeights kind) {
  const int n = int(mesh.vertices.size());
  // Half-cotangents of each face's corners onto the opposite edge, summed per
  // edge by the sparse matrix (upper triangle). Serial: deterministic sums.
  std::vector<Eigen::Triplet<double>> half_cots;
  half_cots.reserve(mesh.faces.size() * 3);
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const int p = f[k], q = f[(k + 1) % 3], r = f[(k + 2) % 3];
      if (q == r) continue;
      const Eigen::Vector3d u = (mesh.vertices[q] - mesh.vertices[p]).cast<double>();
      const Eigen::Vector3d v = (mesh.vertices[r] - mesh.vertices[p]).cast<double>();
      const double cross = u.cross(v).norm();
      // A face without area has no angle to speak of: it only connects.
      const double cot = cross > 1e-12 * u.norm() * v.norm() ? u.dot(v) / cross : 0.0;
      half_cots.emplace_back(std::min(q, r), std::max(q, r), 0.5 * cot);
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> w(n, n);
  w.setFromTriplets(half_cots.begin(), half_cots.end());
  half_cots = {};

  std::vector<Edge> edges;
  edges.reserve(std::size_t(w.nonZeros()));
  for (int i = 0; i < n; ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(w, i); it; ++it) {
      const double weight = kind == FieldWeights::Uniform ? 1.0 : std::clamp(it.value(), kMinCotWeight, kMaxCotWeight);
      edges.push_back({i, int(it.col()), weight});
    }
  }
  return edges;
}

std::vector<int> component_labels(std::size_t vertex_count, const std::vector<Edge>& edges) {
  // Union-find that always hangs the larger root under the smaller, so every
  // root is its component's smallest vertex.
  std::vector<int> parent(vertex_count);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const Edge& e : edges) {
    const int a = find(e.i), b = find(e.j);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  for (std::size_t v = 0; v < vertex_count; ++v) parent[v] = find(int(v));
  return parent;
}

HarmonicResult harmonic_interpolate(std::size_t vertex_count, const std::vector<Edge>& edges,
                                    const std::vector<char>& fixed, const Eigen::MatrixX3d& fixed_values,
                                    ExecContext* ctx, const SpdSolveOptions& solver) {
  StageProgress assemble(ctx, "direction field: assemble", 0.05, 0.1, 1);
  const std::vector<int> label = component_labels(vertex_count, edges);
  std::vector<char> anchored(vertex_count, 0);  // indexed by component label
  for (std::size_t v = 0; v < vertex_count; ++v)
    if (fixed[v]) anchored[label[v]] = 1;

  HarmonicResult out;
  out.values = Eigen::MatrixX3d::Zero(Eigen::Index(vertex_count), 3);
  out.solved.assign(vertex_count, 0);
  std::vector<int> row(vertex_count, -1);
  int unknowns = 0;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    if (fixed[v]) {
      out.values.row(Eigen::Index(v)) = fixed_values.row(Eigen::Index(v));
      out.solved[v] = 1;
    } else if (anchored[label[v]]) {
      row[v] = unknowns++;
      out.solved[v] = 1;
    }
  }
  if (unknowns == 0) return out;

  // Rows of the Laplacian at the free vertices; fixed neighbours move to the
  // right-hand side. Every free vertex reaches a fixed one through positive
  // weights, so the matrix is a symmetric positive definite M-matrix. Rows
  // follow vertex order, so i < j gives row[i] < row[j].
  Eigen::VectorXd diag = Eigen::VectorXd::Zero(unknowns);
  Block rhs = Block::Zero(unknowns, 3);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * edges.size() + std::size_t(unknowns));
  for (const Edge& e : edges) {
    const int ri = row[e.i], rj = row[e.j];
    if (ri < 0 && rj < 0) continue;
    if (ri >= 0) diag[ri] += e.w;
    if (rj >= 0) diag[rj] += e.w;
    if (ri >= 0 && rj >= 0) {
      entries.emplace_back(rj, ri, -e.w);
      entries.emplace_back(ri, rj, -e.w);
    } else if (ri >= 0) {
      rhs.row(ri) += e.w * fixed_values.row(e.j);
    } else {
      rhs.row(rj) += e.w * fixed_values.row(e.i);
    }
  }
  for (int r = 0; r < unknowns; ++r) entries.emplace_back(r, r, diag[r]);
  SparseSym a(unknowns, unknowns);
  a.setFromTriplets(entries.begin(), entries.end());
  entries = {};

  StageProgress solve(ctx, "direction field: solve", 0.1, 0.95, kProgressUnits);
  const Block x = solve_spd(a, rhs, solver, &solve, &out.stats);
  for (std::size_t v = 0; v < vertex_count; ++v)
    if (row[v] >= 0) out.values.row(Eigen::Index(v)) = x.row(row[v]);
  return out;
}

}  // namespace exsynth::field
