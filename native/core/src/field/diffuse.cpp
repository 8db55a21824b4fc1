// diffuse_direction_field: painted vectors -> a unit tangent field.
//
// Choice: harmonic interpolation of the 3D components (the fixed point of
// Turk 2001's repeated neighbour averaging) with the painted vertices fixed,
// then projection and normalisation at every vertex. Averaging in 3D rather
// than with a connection (parallel transport between tangent planes) keeps
// "the same direction in space" where strokes are sparse, which is what a
// painted stroke on a curved model means to the artist, and it is linear, so
// one solve serves x, y and z. Weights: laplacian.hpp; solver: multigrid.hpp.
#include <cmath>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/field.hpp"
#include "exsynth/parallel.hpp"
#include "field/laplacian.hpp"
#include "field/tangent.hpp"

namespace exsynth {
namespace {

void validate(const TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& given, const DirectionFieldOptions& opt) {
  validate_mesh(mesh, "mesh");
  if (given.size() != mesh.vertices.size())
    throw InvalidInput("the direction field has " + std::to_string(given.size()) + " vectors but the mesh has " +
                       std::to_string(mesh.vertices.size()) + " vertices; give one vector per vertex (zero = free)");
  for (std::size_t i = 0; i < given.size(); ++i)
    if (!given[i].allFinite())
      throw InvalidInput("vector " + std::to_string(i) + " of the direction field is not finite (NaN or Inf); "
                         "use a zero vector for a free vertex");
  if (!opt.fallback_axis.allFinite() || opt.fallback_axis.norm() == 0)
    throw InvalidInput("fallback_axis must be a finite, non-zero vector");
}

}  // namespace

std::vector<Eigen::Vector3f> diffuse_direction_field(const TriangleMesh& mesh,
                                                     const std::vector<Eigen::Vector3f>& given,
                                                     const DirectionFieldOptions& opt, ExecContext* ctx) {
  validate(mesh, given, opt);
  const std::size_t n = mesh.vertices.size();
  StageProgress prepare(ctx, "direction field: weights", 0.0, 0.05, 1);
  const std::vector<Eigen::Vector3d> normal = field::vertex_normals_d(mesh);

  // Constraints: projected and normalised, so a stroke's length does not
  // weigh and only its direction in the surface counts.
  std::vector<char> fixed(n, 0);
  Eigen::MatrixX3d fixed_values = Eigen::MatrixX3d::Zero(Eigen::Index(n), 3);
  std::size_t non_zero = 0, usable = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3d g = given[v].cast<double>();
    const double len = g.norm();
    if (len == 0) continue;
    ++non_zero;
    const Eigen::Vector3d t = field::project(g, normal[v]);
    if (t.norm() <= field::kParallelTolerance * len) continue;  // along the normal: no direction in the surface
    fixed[v] = 1;
    fixed_values.row(Eigen::Index(v)) = t.normalized().transpose();
    ++usable;
  }
  if (non_zero == 0)
    throw InvalidInput("the direction field has no non-zero vectors; paint at least one stroke or use a preset");
  if (usable == 0)
    throw InvalidInput("every non-zero vector of the direction field points along the surface normal, so none gives "
                       "a direction in the surface; paint along the surface or use a preset");

  const std::vector<field::Edge> edges = field::edge_weights(mesh, opt.weights);
  const field::HarmonicResult h = field::harmonic_interpolate(n, edges, fixed, fixed_values, ctx);

  const Eigen::Vector3d fallback = opt.fallback_axis.cast<double>().normalized();
  std::vector<Eigen::Vector3f> out(n);
  StageProgress project(ctx, "direction field: project", 0.95, 1.0, n);
  parallel_chunks(n, 4096, project, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t v = lo; v < hi; ++v) {
      Eigen::Vector3d t;
      if (fixed[v])
        t = fixed_values.row(Eigen::Index(v)).transpose();
      else if (h.solved[v])
        // The average of unit vectors is at most 1 long; one this short
        // means they cancel (or it lies along the normal): no direction.
        t = field::unit_tangent_or(h.values.row(Eigen::Index(v)).transpose(), normal[v], 1e-6, fallback);
      else
        t = field::fallback_tangent(normal[v], fallback);  // a component nobody painted
      out[v] = t.cast<float>();
    }
  });
  return out;
}

}  // namespace exsynth
