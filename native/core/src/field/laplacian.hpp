#pragma once
// The averaging operator of the diffusion: edge weights, connected
// components, and the harmonic interpolation that Turk's repeated
// neighbour averaging converges to (solved by multigrid.hpp).
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/field.hpp"
#include "field/multigrid.hpp"

namespace exsynth::field {

/// Cotangent weights are clamped to this range (see FieldWeights).
constexpr double kMinCotWeight = 1e-6;
constexpr double kMaxCotWeight = 100.0;

struct Edge {
  int i, j;  ///< i < j
  double w;  ///< > 0
};

/// Every edge of every face once, sorted by (i, j). Faces with a repeated
/// index or no area still contribute their edges (at the minimum weight), so
/// the operator connects exactly what component_labels() connects.
std::vector<Edge> edge_weights(const TriangleMesh& mesh, FieldWeights kind);

/// Per vertex, the smallest vertex index of its connected component
/// (connected through `edges`; an unused vertex is its own component).
std::vector<int> component_labels(std::size_t vertex_count, const std::vector<Edge>& edges);

/// Values at the fixed vertices stay; every free vertex in a component with
/// a fixed vertex becomes the weighted average of its neighbours (the
/// Laplacian rows of the free vertices, solved by solve_spd for x, y and z
/// at once). Rows of vertices whose component has no fixed vertex are zero
/// and `solved` is false for them. Progress: stages in [0.05, 0.95].
struct HarmonicResult {
  Eigen::MatrixX3d values;
  std::vector<char> solved;  ///< fixed or interpolated
  SpdSolveStats stats;
};
HarmonicResult harmonic_interpolate(std::size_t vertex_count, const std::vector<Edge>& edges,
                                    const std::vector<char>& fixed, const Eigen::MatrixX3d& fixed_values,
                                    ExecContext* ctx = nullptr, const SpdSolveOptions& solver = {});

}  // namespace exsynth::field
