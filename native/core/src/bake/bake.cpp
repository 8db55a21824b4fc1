#include "exsynth/bake.hpp"

#include <algorithm>
#include <cmath>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/sample.hpp"

namespace exsynth {
namespace {

void check_volume(const Volume& vol) {
  if (vol.empty()) throw InvalidInput("the volume to sample is empty");
  if (!(vol.transform().voxel_size > 0)) throw InvalidInput("the volume's voxel_size must be > 0");
}

void sample_at(const Volume& vol, const Eigen::Vector3f& p, Boundary b, Interpolation interp, float* out) {
  const auto idx = vol.transform().world_to_index(p.x(), p.y(), p.z());
  sample_volume_at(vol, idx[0], idx[1], idx[2], out, interp, b);
}

constexpr int kBand = 16;  // image rows per parallel task; a task owns its rows

float edge_function(const Eigen::Vector2f& a, const Eigen::Vector2f& b, const Eigen::Vector2f& p) {
  return (b - a).x() * (p - a).y() - (b - a).y() * (p - a).x();
}

// Whether a triangle (in texel-centre coordinates) contains any texel
// centre, anywhere in the image plane. Exact for triangles whose bounding
// box holds at most 16 lattice points; larger ones are taken to cover one.
bool covers_a_texel_centre(const Eigen::Vector2f t[3]) {
  const int x0 = int(std::ceil(std::min({t[0].x(), t[1].x(), t[2].x()})));
  const int x1 = int(std::floor(std::max({t[0].x(), t[1].x(), t[2].x()})));
  const int y0 = int(std::ceil(std::min({t[0].y(), t[1].y(), t[2].y()})));
  const int y1 = int(std::floor(std::max({t[0].y(), t[1].y(), t[2].y()})));
  if (x1 < x0 || y1 < y0) return false;
  if (std::int64_t(x1 - x0 + 1) * (y1 - y0 + 1) > 16) return true;
  const float area = edge_function(t[0], t[1], t[2]);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2f p{float(x), float(y)};
      const float w0 = edge_function(t[1], t[2], p) / area, w1 = edge_function(t[2], t[0], p) / area,
                  w2 = edge_function(t[0], t[1], p) / area;
      if (w0 >= -1e-6f && w1 >= -1e-6f && w2 >= -1e-6f) return true;
    }
  return false;
}

}  // namespace

void sample_volume(const Volume& vol, const std::vector<Eigen::Vector3f>& points, bool wrap, float* out,
                   ExecContext* ctx, Interpolation interp) {
  check_volume(vol);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InvalidInput("point " + std::to_string(i) + " is not finite; fix the positions first");
  const Boundary b = wrap ? Boundary::Wrap : Boundary::Clamp;
  StageProgress progress(ctx, "sample volume", 0.0, 1.0, points.size());
  const int C = vol.channels();
  parallel_chunks(points.size(), 4096, progress, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sample_at(vol, points[i], b, interp, out + i * C);
  });
}

BakeResult bake_volume_to_uv(const Volume& vol, const std::vector<std::array<Eigen::Vector3f, 3>>& positions,
                             const std::vector<std::array<Eigen::Vector2f, 3>>& uvs, const BakeOptions& opt,
                             ExecContext* ctx) {
  check_volume(vol);
  if (opt.width < 1 || opt.height < 1 || opt.width > kMaxBakeSize || opt.height > kMaxBakeSize)
    throw InvalidInput("the bake image must be between 1 and " + std::to_string(kMaxBakeSize) + " texels on a side, got " + std::to_string(opt.width) +
                       "x" + std::to_string(opt.height));
  if (opt.margin < 0 || opt.margin > kMaxBakeMargin)
    throw InvalidInput("margin must be between 0 and " + std::to_string(kMaxBakeMargin) + " texels");
  if (positions.size() != uvs.size())
    throw InvalidInput("positions and uvs must describe the same triangles (" + std::to_string(positions.size()) +
                       " vs " + std::to_string(uvs.size()) + ")");
  if (positions.empty()) throw InvalidInput("the mesh has no triangles to bake onto");
  for (std::size_t f = 0; f < positions.size(); ++f)
    for (int k = 0; k < 3; ++k)
      if (!positions[f][k].allFinite() || !uvs[f][k].allFinite())
        throw InvalidInput("triangle " + std::to_string(f) + " has a non-finite position or UV; fix the mesh first");

  const int W = opt.width, H = opt.height, C = vol.channels();
  const Boundary b = opt.wrap ? Boundary::Wrap : Boundary::Clamp;
  BakeResult r;
  r.image = Image(W, H, C, 0.0f);
  r.mask.assign(std::size_t(W) * H, 0);

  // Bin triangles by the bands of rows they touch (ascending ids, so
  // overlapping islands resolve the same way for any thread count).
  const int bands = (H + kBand - 1) / kBand;
  std::vector<std::vector<std::int32_t>> bins(bands);
  for (std::size_t f = 0; f < uvs.size(); ++f) {
    float lo = uvs[f][0].y(), hi = lo;
    for (int k = 1; k < 3; ++k) lo = std::min(lo, uvs[f][k].y()), hi = std::max(hi, uvs[f][k].y());
    const int y0 = std::max(0, int(std::floor(lo * H - 0.5f))), y1 = std::min(H - 1, int(std::ceil(hi * H - 0.5f)));
    if (y1 < y0) continue;
    for (int band = y0 / kBand; band <= y1 / kBand; ++band) bins[band].push_back(std::int32_t(f));
  }

  StageProgress raster(ctx, "bake: rasterize", 0.0, 0.8, std::size_t(bands));
  parallel_chunks(std::size_t(bands), 1, raster, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t band = b0; band < b1; ++band) {
      const int row0 = int(band) * kBand, row1 = std::min(H, row0 + kBand);
      for (std::int32_t f : bins[band]) {
        // Texel (x, y)'s centre is at uv ((x + 0.5) / W, (y + 0.5) / H).
        Eigen::Vector2f t[3];
        for (int k = 0; k < 3; ++k) t[k] = Eigen::Vector2f(uvs[f][k].x() * W - 0.5f, uvs[f][k].y() * H - 0.5f);
        const float area = edge_function(t[0], t[1], t[2]);
        if (std::abs(area) < 1e-12f) continue;  // degenerate in UV space: covers no texel centre
        const int x0 = std::max(0, int(std::ceil(std::min({t[0].x(), t[1].x(), t[2].x()}))));
        const int x1 = std::min(W - 1, int(std::floor(std::max({t[0].x(), t[1].x(), t[2].x()}))));
        const int y0 = std::max(row0, int(std::ceil(std::min({t[0].y(), t[1].y(), t[2].y()}))));
        const int y1 = std::min(row1 - 1, int(std::floor(std::max({t[0].y(), t[1].y(), t[2].y()}))));
        const float eps = -1e-6f;  // texel centres on a shared edge belong to both triangles
        bool covered_any = false;
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const Eigen::Vector2f p{float(x), float(y)};
            const float w0 = edge_function(t[1], t[2], p) / area, w1 = edge_function(t[2], t[0], p) / area,
                        w2 = edge_function(t[0], t[1], p) / area;
            if (w0 < eps || w1 < eps || w2 < eps) continue;
            const Eigen::Vector3f pos = w0 * positions[f][0] + w1 * positions[f][1] + w2 * positions[f][2];
            sample_at(vol, pos, b, opt.interpolation, r.image.data() + r.image.offset(x, y));
            r.mask[std::size_t(y) * W + x] = 1;
            covered_any = true;
          }
        if (!covered_any && !covers_a_texel_centre(t)) {
          // A UV island smaller than a texel covers no texel centre: give
          // the texel under its centroid the centroid's value, unless a
          // covering triangle already owns that texel.
          const Eigen::Vector2f c = (t[0] + t[1] + t[2]) / 3.0f;
          const int x = int(std::lround(c.x())), y = int(std::lround(c.y()));
          if (x >= 0 && x < W && y >= row0 && y < row1 && r.mask[std::size_t(y) * W + x] != 1) {
            const Eigen::Vector3f pos = (positions[f][0] + positions[f][1] + positions[f][2]) / 3.0f;
            sample_at(vol, pos, b, opt.interpolation, r.image.data() + r.image.offset(x, y));
            r.mask[std::size_t(y) * W + x] = 3;
          }
        }
      }
    }
  });

  for (auto& m : r.mask)
    if (m == 3) m = 1;  // sub-texel islands count as covered

  // Margin: grow islands one texel ring per pass with the mean of the filled
  // 8-neighbours, reading the previous pass only (deterministic).
  StageProgress grow(ctx, "bake: margin", 0.8, 1.0, std::size_t(opt.margin) * H);
  for (int pass = 0; pass < opt.margin; ++pass) {
    const std::vector<std::uint8_t> before = r.mask;
    parallel_chunks(std::size_t(H), 16, grow, [&](std::size_t begin, std::size_t end) {
      std::vector<float> sum(C);
      for (int y = int(begin); y < int(end); ++y)
        for (int x = 0; x < W; ++x) {
          if (before[std::size_t(y) * W + x]) continue;
          int count = 0;
          std::fill(sum.begin(), sum.end(), 0.0f);
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= W || yy >= H || !before[std::size_t(yy) * W + xx]) continue;
              // Reads only texels filled in earlier passes, never this one's.
              const float* v = r.image.data() + r.image.offset(xx, yy);
              for (int c = 0; c < C; ++c) sum[c] += v[c];
              ++count;
            }
          if (!count) continue;
          float* out = r.image.data() + r.image.offset(x, y);
          for (int c = 0; c < C; ++c) out[c] = sum[c] / float(count);
          r.mask[std::size_t(y) * W + x] = 2;
        }
    });
  }
  if (ctx) ctx->set_progress(1.0);
  return r;
}

}  // namespace exsynth
