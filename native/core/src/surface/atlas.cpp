// Packing the face maps into one atlas with gutters, and the tessellated
// limit mesh with UVs into it.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "surface/texels.hpp"
#include "surface/walk.hpp"

namespace exsynth {

namespace {

/// The face and (u, v) a point outside face f's unit square lands on, by
/// crossing at most two edges (the second for corner regions). Boundary
/// edges clamp to the face.
SurfacePoint cross_edges(const SubdivSurface& s, SurfacePoint p) {
  for (int hop = 0; hop < 2; ++hop) {
    int e = -1;
    double worst = 0;
    const double out[4] = {-p.v, p.u - 1, p.v - 1, -p.u};  // how far beyond edges 0..3
    for (int k = 0; k < 4; ++k)
      if (out[k] > worst) {
        worst = out[k];
        e = k;
      }
    if (e < 0) break;
    double t, d;
    surface::to_edge(e, p.u, p.v, t, d);  // d < 0 outside
    const SubdivSurface::EdgeCrossing nb = s.cross_edge(p.face, e, std::clamp(t, 0.0, 1.0));
    if (nb.face < 0) break;
    double u, v;
    surface::from_edge(nb.edge, nb.t, -d * nb.scale, u, v);
    p = {nb.face, u, v};
  }
  p.u = std::clamp(p.u, 0.0, 1.0);
  p.v = std::clamp(p.v, 0.0, 1.0);
  return p;
}

/// Bilinear lookup inside one face's map (clamped at its border).
void face_bilinear(const SurfaceTexture& tex, const SurfacePoint& p, float* out) {
  const int r = tex.face_resolution[std::size_t(p.face)], C = tex.channels;
  const double x = std::clamp(p.u * r - 0.5, 0.0, double(r - 1)), y = std::clamp(p.v * r - 0.5, 0.0, double(r - 1));
  const int x0 = std::min(int(x), r - 1), y0 = std::min(int(y), r - 1);
  const int x1 = std::min(x0 + 1, r - 1), y1 = std::min(y0 + 1, r - 1);
  const float fx = float(x - x0), fy = float(y - y0);
  const float* base = tex.texels.data() + tex.face_offset[std::size_t(p.face)] * std::size_t(C);
  auto at = [&](int i, int j) { return base + (std::size_t(j) * std::size_t(r) + std::size_t(i)) * std::size_t(C); };
  for (int c = 0; c < C; ++c)
    out[c] = (1 - fy) * ((1 - fx) * at(x0, y0)[c] + fx * at(x1, y0)[c]) + fy * ((1 - fx) * at(x0, y1)[c] + fx * at(x1, y1)[c]);
}

void check_texture(const SubdivSurface& s, const SurfaceTexture& tex) {
  if (tex.face_resolution.size() != std::size_t(s.ptex_face_count()) ||
      tex.face_offset.size() != tex.face_resolution.size() + 1 ||
      tex.texels.size() != tex.texel_count() * std::size_t(tex.channels))
    throw InvalidInput("surface texture does not belong to this surface (face count or sizes differ)");
}

}  // namespace

Eigen::Vector2f SurfaceAtlas::uv(const SurfaceTexture& tex, const SurfacePoint& p) const {
  const auto& o = tile_origin[std::size_t(p.face)];
  const double r = tex.face_resolution[std::size_t(p.face)];
  const double x = o[0] + p.u * r, y = o[1] + p.v * r;
  return {float(x / image.width()), float(1.0 - y / image.height())};
}

SurfaceAtlas build_surface_atlas(const SubdivSurface& s, const SurfaceTexture& tex, int gutter, ExecContext* ctx) {
  check_texture(s, tex);
  if (gutter < 0 || gutter > 16) throw InvalidInput("gutter must be in [0, 16] texels");
  const int nf = s.ptex_face_count();
  std::vector<int> order(static_cast<std::size_t>(nf));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return tex.face_resolution[std::size_t(a)] > tex.face_resolution[std::size_t(b)]; });
  double area = 0;
  for (int r : tex.face_resolution) area += double(r + 2 * gutter) * (r + 2 * gutter);
  const int widest = tex.face_resolution[std::size_t(order[0])] + 2 * gutter;
  const int W = std::max(widest, int(std::ceil(std::sqrt(area * 1.02))));
  SurfaceAtlas atlas;
  atlas.gutter = gutter;
  atlas.tile_origin.resize(std::size_t(nf));
  // Shelves: left to right, a new shelf when a tile does not fit.
  int x = 0, y = 0, shelf = 0;
  for (int f : order) {
    const int side = tex.face_resolution[std::size_t(f)] + 2 * gutter;
    if (x + side > W) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    atlas.tile_origin[std::size_t(f)] = {x + gutter, y + gutter};
    x += side;
    shelf = std::max(shelf, side);
  }
  const int H = y + shelf;
  const double bytes = double(W) * H * tex.channels * 4.0;
  check_memory_budget(bytes, kDefaultMemoryBudget, "surface atlas " + std::to_string(W) + "x" + std::to_string(H),
                      "lower the texel density");
  atlas.image = Image(W, H, tex.channels, 0.0f);
  StageProgress progress(ctx, "surface atlas", 0.0, 1.0, std::size_t(nf));
  parallel_chunks(std::size_t(nf), 64, progress, [&](std::size_t b, std::size_t e) {
    for (std::size_t f = b; f < e; ++f) {
      const int r = tex.face_resolution[f];
      const auto o = atlas.tile_origin[f];
      for (int j = -gutter; j < r + gutter; ++j)
        for (int i = -gutter; i < r + gutter; ++i) {
          float* px = atlas.image.data() + atlas.image.offset(o[0] + i, o[1] + j);
          if (i >= 0 && j >= 0 && i < r && j < r) {
            const float* src = tex.texels.data() + (tex.face_offset[f] + std::size_t(j) * r + i) * std::size_t(tex.channels);
            std::copy(src, src + tex.channels, px);
          } else {
            face_bilinear(tex, cross_edges(s, {int(f), (i + 0.5) / r, (j + 0.5) / r}), px);
          }
        }
    }
  });
  return atlas;
}

LimitMesh surface_limit_mesh(const SubdivSurface& s, const SurfaceTexture& tex, const SurfaceAtlas& atlas,
                             int segments, int displacement_channel, double displacement_scale,
                             double displacement_midlevel, ExecContext* ctx) {
  check_texture(s, tex);
  if (segments < 1 || segments > kMaxSurfaceSegments)
    throw InvalidInput("segments per face must be in [1, " + std::to_string(kMaxSurfaceSegments) + "]");
  if (displacement_channel >= tex.channels)
    throw InvalidInput("displacement channel " + std::to_string(displacement_channel) + " is not among the " +
                       std::to_string(tex.channels) + " channels");
  if (atlas.tile_origin.size() != std::size_t(s.ptex_face_count()))
    throw InvalidInput("atlas does not belong to this surface");
  const int nf = s.ptex_face_count();
  // Quads get twice the segments of n-gon sub-faces, which span half a
  // control edge: borders then match vertex for vertex (as Blender's
  // Subdivision modifier: level L = 2^L per quad edge, 2^(L-1) per sub-face).
  std::vector<int> seg(static_cast<std::size_t>(nf));
  std::vector<std::size_t> first(std::size_t(nf) + 1, 0);
  for (int f = 0; f < nf; ++f) {
    seg[std::size_t(f)] = s.control_mesh().face_sizes[std::size_t(s.control_face(f))] == 4 ? 2 * segments : segments;
    first[std::size_t(f) + 1] = first[std::size_t(f)] + std::size_t(seg[std::size_t(f)] + 1) * std::size_t(seg[std::size_t(f)] + 1);
  }
  check_memory_budget(double(first.back()) * 60.0, kDefaultMemoryBudget, "limit mesh", "lower segments per face");
  // Evaluate every face's grid in parallel, weld afterwards in face order.
  std::vector<Eigen::Vector3f> pos(first.back()), nrm(first.back());
  std::vector<SurfacePoint> where(first.back());
  StageProgress progress(ctx, "limit mesh", 0.0, 1.0, std::size_t(nf));
  parallel_chunks(std::size_t(nf), 64, progress, [&](std::size_t b, std::size_t e) {
    for (std::size_t f = b; f < e; ++f) {
      const int S = seg[f];
      for (int j = 0; j <= S; ++j)
        for (int i = 0; i <= S; ++i) {
          const SurfacePoint p{int(f), double(i) / S, double(j) / S};
          const LimitFrame lf = s.evaluate(p);
          Eigen::Vector3d n = lf.du.cross(lf.dv);
          n = n.norm() > 0 ? n.normalized() : Eigen::Vector3d(0, 0, 1);
          const std::size_t k = first[f] + std::size_t(j * (S + 1) + i);
          pos[k] = lf.position.cast<float>();
          nrm[k] = n.cast<float>();
          where[k] = p;
        }
    }
  });
  // Weld coincident border vertices: a hash grid with cell = tolerance,
  // looking in the 27 cells around each point.
  Eigen::Vector3f lo = pos[0], hi = pos[0];
  for (const auto& p : pos) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float tol = std::max(1e-6f * (hi - lo).norm(), 1e-12f);
  auto cell = [&](const Eigen::Vector3f& p, int dx, int dy, int dz) {
    const auto q = ((p - lo) / tol).array().floor().cast<std::int64_t>();
    return std::uint64_t((q[0] + dx) * 73856093) ^ std::uint64_t((q[1] + dy) * 19349663) ^
           std::uint64_t((q[2] + dz) * 83492791);
  };
  std::unordered_multimap<std::uint64_t, int> grid;
  grid.reserve(pos.size());
  LimitMesh mesh;
  std::vector<int> index(pos.size());
  for (std::size_t k = 0; k < pos.size(); ++k) {
    int found = -1;
    for (int dz = -1; dz <= 1 && found < 0; ++dz)
      for (int dy = -1; dy <= 1 && found < 0; ++dy)
        for (int dx = -1; dx <= 1 && found < 0; ++dx) {
          auto range = grid.equal_range(cell(pos[k], dx, dy, dz));
          for (auto it = range.first; it != range.second; ++it)
            if ((mesh.vertices[std::size_t(it->second)] - pos[k]).norm() <= tol) {
              found = it->second;
              break;
            }
        }
    if (found < 0) {
      found = int(mesh.vertices.size());
      mesh.vertices.push_back(pos[k]);
      mesh.normals.push_back(nrm[k]);
      grid.emplace(cell(pos[k], 0, 0, 0), found);
    }
    index[k] = found;
  }
  // Displace the welded vertices, each by the map of the first face using it
  // (as Blender's Displace modifier), so shared vertices move once.
  if (displacement_channel >= 0) {
    std::vector<char> moved(mesh.vertices.size(), 0);
    std::vector<float> val(std::size_t(tex.channels));
    for (std::size_t k = 0; k < pos.size(); ++k) {
      const int v = index[k];
      if (moved[std::size_t(v)]) continue;
      moved[std::size_t(v)] = 1;
      face_bilinear(tex, where[k], val.data());
      mesh.vertices[std::size_t(v)] += mesh.normals[std::size_t(v)] *
          float(displacement_scale * (val[std::size_t(displacement_channel)] - displacement_midlevel));
    }
  }
  for (int f = 0; f < nf; ++f) {
    const int S = seg[std::size_t(f)];
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        const int c[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
        Eigen::Vector4i q;
        for (int k = 0; k < 4; ++k) {
          q[k] = index[first[std::size_t(f)] + std::size_t(c[k][1] * (S + 1) + c[k][0])];
          mesh.corner_uvs.push_back(atlas.uv(tex, {f, double(c[k][0]) / S, double(c[k][1]) / S}));
        }
        mesh.quads.push_back(q);
      }
  }
  return mesh;
}

}  // namespace exsynth
