#pragma once
// The two synthesis methods (private); synthesize_surface validates the
// inputs, builds the texel frames and calls one of them.
#include "exsynth/surface.hpp"
#include "surface/charts.hpp"
#include "surface/texels.hpp"

namespace exsynth::surface {

/// Texels visited face by face in breadth-first order over the ptex
/// adjacency; inside a face, rows run away from the edge it was reached
/// through, so each scanline starts next to synthesized texels.
std::vector<std::size_t> synthesis_order(const SubdivSurface& surface, const TexelGrid& grid);

/// §5: one pass in synthesis_order; fills out.texels and out.source.
/// charts: null = walk every neighbourhood sample.
void run_coherent(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts* charts,
                  const Image& exemplar, const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx);

/// §4: Gaussian pyramids, brute force at the coarsest level, two passes per finer level.
void run_multiscale(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts* charts,
                    const Image& exemplar, const SurfaceSynthesisOptions& opt, SurfaceTexture& out,
                    ExecContext* ctx);

/// Levels the multiscale method uses for these inputs (>= 1).
int multiscale_levels(const Image& exemplar, const TexelGrid& grid, const SurfaceSynthesisOptions& opt);

}  // namespace exsynth::surface

namespace exsynth::surface {

/// Adds per-thread sample counts into the totals of a texture.
inline void add_stats(SurfaceTexture& out, const ChartStats& s) {
  out.chart_samples += s.in_chart;
  out.walked_samples += s.walked;
}

/// The neighbourhood samples of the synthesis: through the charts when
/// given (chart_points), else marched on the surface (march_points).
inline void neighbourhood_points(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts* charts,
                                 const SurfacePoint& c, std::size_t frame_texel, double h, int r, SurfacePoint* out,
                                 bool* valid, ChartStats* stats = nullptr) {
  const Eigen::Vector3d a = frames.t1[frame_texel].cast<double>() * h, b = frames.t2[frame_texel].cast<double>() * h;
  if (charts)
    chart_points(surface, frames, *charts, c, frames.du[frame_texel].cast<double>(),
                 frames.dv[frame_texel].cast<double>(), a, b, r, true, out, valid, stats);
  else
    march_points(surface, frames, c, a, b, r, true, out, valid);
  if (!charts && stats) stats->walked += std::uint64_t((2 * r + 1) * (2 * r + 1));
}

}  // namespace exsynth::surface
