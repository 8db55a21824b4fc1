#include "exsynth/voxelize.hpp"
#include "exsynth/format.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "voxel/axis_rays.hpp"
#include "voxel/distance_transform.hpp"
#include "voxel/line_coverage.hpp"
#include "voxel/narrow_band.hpp"
#include "voxel/triangle_distance.hpp"

namespace exsynth {
namespace {

void validate_options(const VoxelizeOptions& opt) {
  if (!std::isfinite(opt.voxel_size) || opt.voxel_size < 0)
    throw InvalidInput("voxel_size must be a finite number >= 0 (0 means: use resolution), got " +
                       format_number(opt.voxel_size));
  if (opt.voxel_size == 0 && (opt.resolution < 1 || opt.resolution > kMaxVoxelResolution))
    throw InvalidInput("resolution must be between 1 and " + std::to_string(kMaxVoxelResolution) +
                       " voxels along the longest axis, got " + std::to_string(opt.resolution));
  if (opt.padding < 0 || opt.padding > kMaxVoxelPadding)
    throw InvalidInput("padding must be between 0 and " + std::to_string(kMaxVoxelPadding) + " voxels, got " + std::to_string(opt.padding));
  if (opt.supersample < 1 || opt.supersample > kMaxSupersample)
    throw InvalidInput("supersample must be between 1 and " + std::to_string(kMaxSupersample) + " sub-rays per voxel edge, got " +
                       std::to_string(opt.supersample));
}

// Peak bytes: three coverage volumes + votes + density while stabbing;
// density + votes + squared distance (turned into the sdf in place) + labels
// afterwards: 17 and 13 per voxel (21 for a moment while the density is blended), plus the mesh copies (index-space vertices, Embree's BVH).
double estimate_bytes(const VoxelGridSpec& g, const TriangleMesh& mesh) {
  const double voxels = double(g.nx) * g.ny * g.nz;
  return voxels * 21.0 + double(mesh.faces.size()) * 96.0 + double(mesh.vertices.size()) * 32.0;
}

}  // namespace

VoxelGridSpec voxel_grid_spec(const TriangleMesh& mesh, const VoxelizeOptions& opt) {
  validate_mesh(mesh, "mesh");
  Eigen::Vector3d lo = mesh.vertices[0].cast<double>(), hi = lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  return voxel_grid_spec(lo, hi, opt);
}

VoxelGridSpec voxel_grid_spec(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const VoxelizeOptions& opt) {
  validate_options(opt);
  if (!lo.allFinite() || !hi.allFinite() || (hi - lo).minCoeff() < 0)
    throw InvalidInput("the bounding box must be finite with lo <= hi on every axis");
  const Eigen::Vector3d extent = hi - lo;
  const double longest = extent.maxCoeff();
  if (!(longest > 0))
    throw InvalidInput("mesh has zero size (all vertices at one point); give it some extent");
  const double h = opt.voxel_size > 0 ? opt.voxel_size : longest / opt.resolution;

  VoxelGridSpec g;
  int* dims[3] = {&g.nx, &g.ny, &g.nz};
  for (int k = 0; k < 3; ++k) {
    const double cells = std::ceil(extent[k] / h - 1e-9);
    if (cells > kMaxVoxelResolution)
      throw InvalidInput("voxel_size " + format_number(h) + " gives " + std::to_string(long(cells)) +
                         " voxels along an axis (max " + std::to_string(kMaxVoxelResolution) + "); use a larger voxel_size");
    *dims[k] = std::max(1, int(cells)) + 2 * opt.padding;
    // Centre the grid on the bounding box.
    g.transform.origin[k] = 0.5 * (lo[k] + hi[k]) - 0.5 * (*dims[k] - 1) * h;
  }
  g.transform.voxel_size = h;
  return g;
}

namespace {

// The grid's axis lengths and strides, shared by the stages below.
struct GridShape {
  int n[3];
  std::size_t voxels, stride[3];
  explicit GridShape(const VoxelGridSpec& g)
      : n{g.nx, g.ny, g.nz}, voxels(std::size_t(g.nx) * g.ny * g.nz),
        stride{1, std::size_t(g.nx), std::size_t(g.nx) * g.ny} {}
};

// The mesh in voxel-index space: voxel (x, y, z)'s centre is at (x, y, z).
TriangleMesh index_space(const TriangleMesh& input, const VoxelGridSpec& g) {
  TriangleMesh mesh;
  mesh.faces = input.faces;
  mesh.vertices.reserve(input.vertices.size());
  for (const auto& v : input.vertices) {
    Eigen::Vector3f p;
    for (int k = 0; k < 3; ++k) p[k] = float((double(v[k]) - g.transform.origin[k]) / g.transform.voxel_size);
    mesh.vertices.push_back(p);
  }
  return mesh;
}

// Ray stabbing along each axis: S x S sub-rays per line give the exact 1-D
// coverage of every voxel (cov[a]), one centre ray gives the parity vote
// (votes: how many axes say inside).
void stab(const voxel::AxisRayCaster& caster, const GridShape& s, int S, std::vector<float> (&cov)[3],
          std::vector<std::uint8_t>& votes, ExecContext* ctx) {
  votes.assign(s.voxels, 0);
  std::size_t lines_total = 0;
  for (int a = 0; a < 3; ++a) lines_total += s.voxels / std::size_t(s.n[a]);
  StageProgress progress(ctx, "voxelize: ray parity", 0.05, 0.5, lines_total);
  for (int a = 0; a < 3; ++a) {
    // Enumerate lines with the smaller-stride axis fastest, so neighbouring
    // lines write neighbouring memory (the scatter is the costly part).
    const int p = a == 0 ? 1 : 0, q = a == 2 ? 1 : 2;
    cov[a].assign(s.voxels, 0.0f);
    parallel_chunks(std::size_t(s.n[p]) * s.n[q], 16, progress, [&](std::size_t begin, std::size_t end) {
      std::vector<voxel::Crossing> xs;
      std::vector<float> line_cov(s.n[a]);
      std::vector<std::uint8_t> inside(s.n[a]);
      const float w = 1.0f / float(S * S);
      float pos[3] = {0, 0, 0};
      auto cast = [&](float jp, float jq) {
        pos[p] = jp;
        pos[q] = jq;
        caster.crossings(a, pos[(a + 1) % 3], pos[(a + 2) % 3], xs);
      };
      for (std::size_t line = begin; line < end; ++line) {
        const int jp = int(line % s.n[p]), jq = int(line / s.n[p]);
        std::fill(line_cov.begin(), line_cov.end(), 0.0f);
        for (int sp = 0; sp < S; ++sp)
          for (int sq = 0; sq < S; ++sq) {
            cast(jp + (sp + 0.5f) / S - 0.5f, jq + (sq + 0.5f) / S - 0.5f);
            voxel::accumulate_coverage(xs, s.n[a], w, line_cov.data());
          }
        cast(float(jp), float(jq));
        voxel::centre_parity(xs, s.n[a], inside.data());
        const std::size_t base = jp * s.stride[p] + jq * s.stride[q];
        for (int i = 0; i < s.n[a]; ++i) {
          cov[a][base + i * s.stride[a]] = std::min(1.0f, line_cov[i]);
          votes[base + i * s.stride[a]] += inside[i];
        }
      }
    });
  }
}

// Density. Each axis's coverage is exact along its own rays but
// point-sampled across them, so it is exact only where the surface faces
// that axis. Blend the axes by the squared components of the surface
// normal (estimated from the gradient of the median coverage): an
// axis-aligned face is then exact, and a tilted one is integrated by the
// sub-ray midpoint rule, exact for a plane. An axis that disagrees with the
// median by more than half a voxel is a leak through a hole in the mesh and
// is replaced by the median: the continuous form of the 2-of-3 vote.
void blend_density(const GridShape& s, std::vector<float> (&cov)[3], Volume& density, ExecContext* ctx) {
  StageProgress vote(ctx, "voxelize: density vote", 0.5, 0.55, 2 * s.voxels);
  float* median = density.data();
  parallel_chunks(s.voxels, 1 << 16, vote, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      const float x = cov[0][v], y = cov[1][v], z = cov[2][v];
      median[v] = std::max(std::min(x, y), std::min(std::max(x, y), z));
    }
  });
  // The blend goes into cov[0] in place: voxel v reads only its own
  // coverages and its neighbours' medians. Reusing the buffer saves a
  // fresh allocation's page faults (~10 % of the run at 256^3).
  std::vector<float>& blended = cov[0];
  const std::size_t nx = std::size_t(s.n[0]), ny = std::size_t(s.n[1]);
  parallel_chunks(s.voxels, 1 << 14, vote, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      const float m = median[v];
      const int p[3] = {int(v % nx), int((v / nx) % ny), int(v / (nx * ny))};
      float grad[3], norm2 = 0.0f;
      for (int a = 0; a < 3; ++a) {
        const std::size_t lo = p[a] > 0 ? v - s.stride[a] : v, hi = p[a] + 1 < s.n[a] ? v + s.stride[a] : v;
        grad[a] = median[hi] - median[lo];
        norm2 += grad[a] * grad[a];
      }
      if (norm2 == 0.0f) {
        blended[v] = m;
        continue;
      }
      float sum = 0.0f;
      for (int a = 0; a < 3; ++a) {
        const float c = std::abs(cov[a][v] - m) > 0.5f ? m : cov[a][v];
        sum += grad[a] * grad[a] * c;
      }
      blended[v] = std::min(1.0f, std::max(0.0f, sum / norm2));
    }
  });
  density.values().swap(blended);
}

// Signed distance: exact narrow band -> feature transform carrying the
// nearest triangle -> exact distance to that triangle everywhere; negative
// where at least two axes' parity says inside. `dist2` is a scratch buffer of
// the grid's size (already paged in) that becomes the volume.
Volume signed_distance(const TriangleMesh& mesh, const VoxelGridSpec& g, const std::vector<std::uint8_t>& votes,
                       std::vector<float> dist2, ExecContext* ctx) {
  const std::size_t voxels = std::size_t(g.nx) * g.ny * g.nz;
  std::vector<std::int32_t> label;
  {
    StageProgress band(ctx, "voxelize: narrow band", 0.55, 0.65, std::size_t(g.nz + 3) / 4);
    voxel::narrow_band(mesh, g.nx, g.ny, g.nz, dist2, label, band);
  }
  {
    const std::size_t lines = std::size_t(g.ny) * g.nz + std::size_t(g.nx) * g.nz + std::size_t(g.nx) * g.ny;
    StageProgress edt(ctx, "voxelize: distance transform", 0.65, 0.85, lines);
    voxel::distance_transform(g.nx, g.ny, g.nz, dist2, label, edt);
  }
  // Signed distances overwrite the squared ones in place (each voxel reads
  // only its own), and the buffer becomes the volume.
  StageProgress exact(ctx, "voxelize: exact distances", 0.85, 1.0, voxels);
  float* s = dist2.data();
  const float h = float(g.transform.voxel_size);
  parallel_chunks(voxels, 1 << 14, exact, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      float d2 = dist2[v];
      if (d2 > 1.0f) {  // outside the exact band: measure to the carried triangle
        const int x = int(v % g.nx), y = int((v / g.nx) % g.ny), z = int(v / (std::size_t(g.nx) * g.ny));
        const auto& t = mesh.faces[label[v]];
        d2 = voxel::point_triangle_distance2(Eigen::Vector3f(float(x), float(y), float(z)), mesh.vertices[t[0]],
                                             mesh.vertices[t[1]], mesh.vertices[t[2]]);
      }
      const float d = std::sqrt(d2) * h;
      s[v] = votes[v] >= 2 ? -d : d;
    }
  });
  return Volume(g.nx, g.ny, g.nz, 1, std::move(dist2), g.transform);
}

}  // namespace

VoxelizeResult voxelize(const TriangleMesh& input, const VoxelizeOptions& opt, ExecContext* ctx) {
  const VoxelGridSpec g = voxel_grid_spec(input, opt);
  check_memory_budget(estimate_bytes(g, input), opt.memory_budget,
                      "voxelizing at " + std::to_string(g.nx) + "x" + std::to_string(g.ny) + "x" +
                          std::to_string(g.nz) + " voxels",
                      opt.voxel_size > 0 ? "raise voxel_size or the memory budget"
                                         : "lower the resolution or raise the memory budget");
  const GridShape shape(g);
  const TriangleMesh mesh = index_space(input, g);

  StageProgress build(ctx, "voxelize: ray scene", 0.0, 0.05, 1);
  voxel::AxisRayCaster caster(mesh);  // one Embree build: checked after it
  build.check();
  build.advance();

  std::vector<float> cov[3];
  std::vector<std::uint8_t> votes;
  stab(caster, shape, opt.supersample, cov, votes, ctx);
  VoxelizeResult result;
  result.density = Volume(g.nx, g.ny, g.nz, 1, 0.0f, g.transform);
  blend_density(shape, cov, result.density, ctx);
  if (opt.compute_sdf) {
    std::vector<float> scratch = std::move(cov[1]);  // already paged in
    std::vector<float>().swap(cov[2]);
    std::vector<float>().swap(cov[0]);
    result.sdf = signed_distance(mesh, g, votes, std::move(scratch), ctx);
  }
  if (ctx) ctx->set_progress(1.0);
  return result;
}

}  // namespace exsynth
