// Entry points of the point-set geometry texture synthesis: over a plane
// (scan-line patches) and over a target mesh (patches at evenly spread
// centres in front order), then crop and density relaxation.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <chrono>
#include <limits>
#include <numeric>
#include <queue>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/field.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/points.hpp"
#include <Eigen/Geometry>

#include "points/patch_solver.hpp"
#include "search/point_grid.hpp"
#include "points/sampling.hpp"

namespace exsynth {
namespace {

using Clock = std::chrono::steady_clock;
using V3 = Eigen::Vector3f;

// Density relaxation: drop a point that has an earlier one (index order)
// closer than half the spacing on a like-oriented sheet (where two patches'
// points ended up doubled), then a few Jacobi rounds of tangential
// repulsion between like-oriented neighbours. Deterministic: every point
// reads the previous round only.
OrientedPoints relax(OrientedPoints pts, double spacing, int rounds, ExecContext* ctx) {
  if (pts.size() < 2 || rounds <= 0) return pts;
  {
    StageProgress progress(ctx, "relaxing the density", 0.9, 0.95, pts.size());
    // Cells of 1.5 spacings, as the rounds below: cells of the query radius
    // (half a spacing) held about one point each and their table cost 130 MB at 2.9 M points.
    const search::PointGrid index(pts.positions, float(1.5 * spacing));
    std::vector<char> drop(pts.size(), 0);
    const float r = float(0.5 * spacing);
    parallel_chunks(pts.size(), 4096, progress, [&](std::size_t b, std::size_t e) {
      std::vector<std::pair<std::size_t, float>> near;
      for (std::size_t i = b; i < e; ++i) {
        index.radius(pts.positions[i], r, near);
        for (const auto& [j, d2] : near)
          if (j < i && pts.normals[j].dot(pts.normals[i]) > 0.5f) {
            drop[i] = 1;
            break;
          }
      }
    });
    OrientedPoints kept;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (!drop[i]) {
        kept.positions.push_back(pts.positions[i]);
        kept.normals.push_back(pts.normals[i]);
      }
    pts = std::move(kept);
  }
  StageProgress progress(ctx, "relaxing the density", 0.95, 1.0, pts.size() * std::size_t(rounds));
  const float r = float(1.5 * spacing);
  for (int round = 0; round < rounds; ++round) {
    const search::PointGrid index(pts.positions, r);
    std::vector<V3> next(pts.positions);
    parallel_chunks(pts.size(), 4096, progress, [&](std::size_t b, std::size_t e) {
      std::vector<std::pair<std::size_t, float>> near;
      for (std::size_t i = b; i < e; ++i) {
        const V3& p = pts.positions[i];
        const V3& n = pts.normals[i];
        index.radius(p, r, near);
        V3 force = V3::Zero();
        for (const auto& [j, d2] : near) {
          if (j == i || pts.normals[j].dot(n) < 0.7f) continue;
          const float d = std::sqrt(d2);
          if (d < 1e-9f) continue;
          force += (p - pts.positions[j]) / d * (1.0f - d / r);
        }
        force -= force.dot(n) * n;  // stay on the surface: move in the tangent plane
        V3 step = 0.1f * float(spacing) * force;
        const float len = step.norm(), cap = 0.25f * float(spacing);
        if (len > cap) step *= cap / len;
        next[i] = p + step;
      }
    });
    pts.positions = std::move(next);
  }
  return pts;
}

// The output's points that no later patch replaced, in the order they were added.
OrientedPoints alive_points(const points::OutputStore& out) {
  OrientedPoints alive;
  for (std::size_t i = 0; i < out.positions.size(); ++i)
    if (out.alive[i]) {
      alive.positions.push_back(out.positions[i]);
      alive.normals.push_back(out.normals[i]);
    }
  return alive;
}

void finish_density(PointTextureResult& r, const PointExemplar& ex) {
  std::size_t inside = 0;
  for (const auto& p : ex.points.positions)
    inside += p.x() >= ex.box_min.x() && p.x() <= ex.box_max.x() && p.y() >= ex.box_min.y() && p.y() <= ex.box_max.y();
  r.density = double(inside) / ((ex.box_max.x() - ex.box_min.x()) * (ex.box_max.y() - ex.box_min.y()));
}

// The solver's counters and stage times into the result; "other" is the
// whole call's time not in search, warp or blend.
PointTextureResult with_stats(PointTextureResult result, const PointTextureResult& st, Clock::time_point t_start) {
  result.patches = st.patches;
  result.pairs = st.pairs;
  result.fallbacks = st.fallbacks;
  result.spacing = st.spacing;
  result.times = st.times;
  const double total = std::chrono::duration<double>(Clock::now() - t_start).count();
  result.times.other = std::max(0.0, total - result.times.search - result.times.warp - result.times.blend);
  return result;
}

}  // namespace

PointTextureResult synthesize_points(const PointExemplar& exemplar, double width, double depth,
                                     const PointTextureOptions& opt, ExecContext* ctx) {
  const auto t_start = Clock::now();
  if (!(width > 0) || !(depth > 0) || !std::isfinite(width) || !std::isfinite(depth))
    throw InvalidInput("the output size (width, depth) must be positive lengths in exemplar units");
  points::PatchSolver solver(exemplar, opt, ctx);
  PointTextureResult result;
  finish_density(result, exemplar);
  const double P = solver.patch(), E = solver.overlap(), s = P - E;
  const int nx = 1 + int(std::ceil(std::max(0.0, width + 2 * E - P) / s));
  const int ny = 1 + int(std::ceil(std::max(0.0, depth + 2 * E - P) / s));
  const double est = result.density * (width + 2 * E) * (depth + 2 * E) * 1.5;
  check_memory_budget(est * 120.0, opt.memory_budget, "a point texture of about " + format_count(est) + " points",
                      "lower the output size or the exemplar's density");
  points::OutputStore out(float(0.5 * P));
  {
    StageProgress progress(ctx, "placing patches", 0.05, 0.9, std::size_t(nx) * ny);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        progress.check();
        const points::PlaneChart chart(float(-E + 0.5 * P + i * s), float(-E + 0.5 * P + j * s));
        solver.place(chart, std::uint64_t(j) * std::uint64_t(nx) + std::uint64_t(i), out);
        progress.advance();
      }
  }
  OrientedPoints alive = alive_points(out);
  // Relax with the border strip still there (whole neighbourhoods), then crop it.
  alive = relax(std::move(alive), solver.spacing(), opt.relax_iterations, ctx);
  for (std::size_t i = 0; i < alive.size(); ++i) {
    const V3& p = alive.positions[i];
    if (p.x() >= 0 && p.x() <= width && p.y() >= 0 && p.y() <= depth) {
      result.points.positions.push_back(p);
      result.points.normals.push_back(alive.normals[i]);
    }
  }
  return with_stats(std::move(result), solver.stats(), t_start);
}

namespace {

// Patch centres on the target: Poisson-disk picks from its samples (index
// order, radius r), visited outward from the first along a k-nearest graph
// (Dijkstra), so each patch overlaps patches already placed, as scan lines do on a plane.
std::vector<V3> patch_centres(const std::vector<V3>& samples, float r, const StageProgress& progress) {
  points::OutputStore picked(r);
  std::vector<std::uint32_t> near;
  std::vector<V3> centres;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    progress.check_every(i);
    const V3& p = samples[i];
    picked.gather(p, r, near);
    if (near.empty()) {
      picked.add(p, V3::UnitZ());
      centres.push_back(p);
    }
  }
  const search::PointIndex index(centres);
  const std::size_t k = std::min<std::size_t>(9, centres.size());
  std::vector<double> dist(centres.size(), std::numeric_limits<double>::infinity());
  std::vector<char> done(centres.size(), 0);
  std::vector<std::size_t> order;
  using Item = std::pair<double, std::size_t>;
  std::vector<std::size_t> idx(k);
  std::vector<float> d2(k);
  for (std::size_t start = 0; start < centres.size(); ++start) {
    if (done[start]) continue;  // a new component: start again from its first centre
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    dist[start] = 0;
    heap.push({0.0, start});
    while (!heap.empty()) {
      const auto [d, i] = heap.top();
      heap.pop();
      if (done[i]) continue;
      done[i] = 1;
      order.push_back(i);
      const std::size_t m = index.knn(centres[i], k, idx.data(), d2.data());
      for (std::size_t q = 0; q < m; ++q) {
        const std::size_t j = idx[q];
        const double nd = d + std::sqrt(double(d2[q]));
        if (!done[j] && nd < dist[j]) {
          dist[j] = nd;
          heap.push({nd, j});
        }
      }
    }
  }
  std::vector<V3> ordered;
  for (std::size_t i : order) ordered.push_back(centres[i]);
  return ordered;
}

}  // namespace

PointTextureResult synthesize_points_on_mesh(const PointExemplar& exemplar, const TriangleMesh& target,
                                             const std::vector<V3>& field, double scale,
                                             const PointTextureOptions& opt, ExecContext* ctx) {
  const auto t_start = Clock::now();
  validate_mesh(target, "target mesh");
  if (field.size() != target.vertices.size())
    throw InvalidInput("the direction field has " + std::to_string(field.size()) + " vectors for " +
                       std::to_string(target.vertices.size()) + " vertices of the target; give one per vertex");
  for (const V3& f : field)
    if (!f.allFinite()) throw InvalidInput("the direction field has NaN or infinite vectors");
  if (std::none_of(field.begin(), field.end(), [](const V3& f) { return f.squaredNorm() > 0; }))
    throw InvalidInput("the direction field is zero everywhere, so it gives the texture no direction; give a "
                       "tangent at some vertices (zero ones are filled in from them)");
  if (!(scale > 0) || !std::isfinite(scale))
    throw InvalidInput("the scale (target units per exemplar unit) must be a positive number");
  points::PatchSolver solver(exemplar, opt, ctx);
  PointTextureResult result;
  finish_density(result, exemplar);
  const double area = points::surface_area(target);
  const PointTextureEstimate est = estimate_points_on_mesh(result.density, area, scale, opt);
  char figures[160];
  std::snprintf(figures, sizeof figures, " (%.3g units² of target at %.3g target units per exemplar unit, %.3g "
                "exemplar points per unit²)", area, scale, result.density);
  check_memory_budget(est.bytes, opt.memory_budget, "a point texture of about " + format_count(est.points) +
                      " points" + figures, "raise the scale or lower the exemplar's density");
  // The target as a point-set surface, sampled a few times finer than the metric grid.
  const double cell_world = solver.patch() / opt.grid_resolution * scale;
  const std::size_t count = std::size_t(std::clamp(area / (cell_world * cell_world) * 2.0, 2000.0, 400000.0));
  // Sampling the target took 1.7 s without a cancel check (bunny, cancel
  // latency bench): the sampler gets a context that only relays checks (its
  // own stages and progress would overwrite this job's).
  StageProgress prep(ctx, "sampling the target", 0.05, 0.05, 1);
  ExecContext relay;
  if (ctx) relay.on_check([ctx] { ctx->check(); });
  points::SurfaceSamples samples = points::sample_surface(target, count, opt.seed, ctx ? &relay : nullptr);
  points::TargetSurface surface;
  surface.positions = std::move(samples.points.positions);
  surface.normals = std::move(samples.points.normals);
  surface.field.resize(surface.positions.size());
  for (std::size_t i = 0; i < surface.positions.size(); ++i) {
    const auto& f = target.faces[samples.face[i]];
    const V3& w = samples.bary[i];
    surface.field[i] = w[0] * field[f[0]] + w[1] * field[f[1]] + w[2] * field[f[2]];
  }
  const search::PointIndex index(surface.positions);
  const double target_spacing = points::mean_spacing(surface.positions, index, &prep);
  const float max_height = std::max(std::abs(solver.z_min()), std::abs(solver.z_max()));
  surface.surface = std::make_unique<points::PointSurface>(
      surface.positions, surface.normals, float(std::max(2.0 * target_spacing, 0.25 * max_height * scale)));
  prep.check();
  const std::vector<V3> centres = patch_centres(surface.positions, float(0.42 * solver.patch() * scale), prep);
  points::OutputStore out(float(0.5 * solver.patch() * scale));
  {
    StageProgress progress(ctx, "placing patches on the target", 0.05, 0.9, centres.size());
    for (std::size_t c = 0; c < centres.size(); ++c) {
      progress.check();
      const points::SurfaceChart chart(surface, centres[c], float(scale), max_height);
      solver.place(chart, c, out);
      progress.advance();
    }
  }
  OrientedPoints alive = alive_points(out);
  result.points = relax(std::move(alive), solver.spacing() * scale, opt.relax_iterations, ctx);
  return with_stats(std::move(result), solver.stats(), t_start);
}

PointTextureEstimate estimate_points_on_mesh(double exemplar_density, double target_area, double scale,
                                             const PointTextureOptions& opt) {
  PointTextureEstimate e;
  const double centre_gap = 0.42 * opt.patch_size * scale;  // as patch_centres' radius below
  e.patches = 0.7 * target_area / (centre_gap * centre_gap);  // random close packing of those discs
  e.points = exemplar_density * target_area / (scale * scale);
  e.bytes = e.points * 1.5 * 160.0;
  e.seconds = e.points * kPointSecondsPerPoint;
  return e;
}

double default_points_scale(double exemplar_density, double target_area) {
  if (!(exemplar_density > 0) || !std::isfinite(exemplar_density))
    throw InvalidInput("the exemplar's density must be a positive number of points per unit area");
  if (!(target_area > 0) || !std::isfinite(target_area))
    throw InvalidInput("the target mesh has no surface area (all its faces are degenerate)");
  return std::sqrt(exemplar_density * target_area / kDefaultPointsOnMesh);
}

}  // namespace exsynth
