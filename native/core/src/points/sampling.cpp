#include "points/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <queue>

#include "exsynth/errors.hpp"
#include "exsynth/field.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/rng.hpp"
#include "search/point_index.hpp"

namespace exsynth::points {

double surface_area(const TriangleMesh& mesh) {
  double a = 0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d p0 = mesh.vertices[f[0]].cast<double>(), p1 = mesh.vertices[f[1]].cast<double>(),
                          p2 = mesh.vertices[f[2]].cast<double>();
    a += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  return a;
}

namespace {

// Yuksel's weight of a neighbour at distance d: (1 - d / 2 r_max)^8.
double elimination_weight(double d, double r2max) { return std::pow(1.0 - std::min(d, r2max) / r2max, 8.0); }

std::vector<std::size_t> eliminate(const std::vector<Eigen::Vector3f>& cands, std::size_t keep, double r_max,
                                   StageProgress& progress) {
  const search::PointIndex index(cands);
  const double r2max = 2.0 * r_max;
  std::vector<std::vector<std::pair<std::size_t, float>>> near(cands.size());
  std::vector<double> weight(cands.size(), 0.0);
  parallel_chunks(cands.size(), 4096, progress, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      index.radius(cands[i], float(r2max), near[i]);
      double w = 0;
      for (const auto& [j, d2] : near[i])
        if (j != i) w += elimination_weight(std::sqrt(double(d2)), r2max);
      weight[i] = w;
    }
  });
  // Max-heap on (weight, index) with lazy deletion: ties go to the higher index.
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry> heap;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    progress.check_every(i);
    heap.push({weight[i], i});
  }
  std::vector<char> removed(cands.size(), 0);
  std::size_t alive = cands.size();
  // Serial: a curved target's 3 x 400 k candidates ran ~0.5 s between checks.
  for (std::size_t step = 0; alive > keep && !heap.empty(); ++step) {
    progress.check_every(step);
    const auto [w, i] = heap.top();
    heap.pop();
    if (removed[i] || w != weight[i]) continue;
    removed[i] = 1;
    --alive;
    for (const auto& [j, d2] : near[i]) {
      if (j == i || removed[j]) continue;
      weight[j] -= elimination_weight(std::sqrt(double(d2)), r2max);
      heap.push({weight[j], j});
    }
  }
  std::vector<std::size_t> out;
  out.reserve(keep);
  for (std::size_t i = 0; i < cands.size(); ++i)
    if (!removed[i]) out.push_back(i);
  return out;
}

}  // namespace

SurfaceSamples sample_surface(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed, ExecContext* ctx) {
  validate_mesh(mesh, "mesh to sample");
  std::vector<double> cum(mesh.faces.size());
  double total = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    const Eigen::Vector3d p0 = mesh.vertices[t[0]].cast<double>(), p1 = mesh.vertices[t[1]].cast<double>(),
                          p2 = mesh.vertices[t[2]].cast<double>();
    total += 0.5 * (p1 - p0).cross(p2 - p0).norm();
    cum[f] = total;
  }
  if (!(total > 0)) throw InvalidInput("the mesh to sample has zero surface area; give it faces with some extent");
  const std::vector<Eigen::Vector3f> vn = vertex_normals(mesh);
  const std::size_t ncand = 3 * count;
  SurfaceSamples cand;
  cand.points.positions.resize(ncand);
  cand.points.normals.resize(ncand);
  cand.face.resize(ncand);
  cand.bary.resize(ncand);
  StageProgress draw(ctx, "sampling the surface", 0.0, 0.3, ncand);
  parallel_chunks(ncand, 8192, draw, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      IndexRng rng(seed, i, 0x5A3D);
      const double r = rng.uniform() * total;
      const std::size_t f = std::min<std::size_t>(std::size_t(std::upper_bound(cum.begin(), cum.end(), r) - cum.begin()),
                                                  cum.size() - 1);
      const double s = std::sqrt(rng.uniform()), t = rng.uniform();
      const Eigen::Vector3f w(float(1 - s), float(s * (1 - t)), float(s * t));
      const auto& tri = mesh.faces[f];
      cand.points.positions[i] = w[0] * mesh.vertices[tri[0]] + w[1] * mesh.vertices[tri[1]] + w[2] * mesh.vertices[tri[2]];
      Eigen::Vector3f n = w[0] * vn[tri[0]] + w[1] * vn[tri[1]] + w[2] * vn[tri[2]];
      if (n.norm() < 1e-6f)
        n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
      cand.points.normals[i] = n.normalized();
      cand.face[i] = std::uint32_t(f);
      cand.bary[i] = w;
    }
  });
  // r_max for `count` samples on area `total` (hexagonal packing, Yuksel eq. 5).
  const double r_max = std::sqrt(total / (2.0 * std::sqrt(3.0) * double(count)));
  StageProgress elim(ctx, "even spacing (sample elimination)", 0.3, 1.0, ncand);
  const std::vector<std::size_t> kept = eliminate(cand.points.positions, count, r_max, elim);
  SurfaceSamples out;
  for (std::size_t i : kept) {
    out.points.positions.push_back(cand.points.positions[i]);
    out.points.normals.push_back(cand.points.normals[i]);
    out.face.push_back(cand.face[i]);
    out.bary.push_back(cand.bary[i]);
  }
  return out;
}

}  // namespace exsynth::points
