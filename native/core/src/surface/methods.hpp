#pragma once
// The two synthesis methods (private); synthesize_surface validates the
// inputs, builds the texel frames and calls one of them.
#include "exsynth/surface.hpp"
#include "surface/texels.hpp"

namespace exsynth::surface {

/// Texels visited face by face in breadth-first order over the ptex
/// adjacency; inside a face, rows run away from the edge it was reached
/// through, so each scanline starts next to synthesized texels.
std::vector<std::size_t> synthesis_order(const SubdivSurface& surface, const TexelGrid& grid);

/// §5: one pass in synthesis_order; fills out.texels and out.source.
void run_coherent(const SubdivSurface& surface, const TexelFrames& frames, const Image& exemplar,
                  const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx);

/// §4: Gaussian pyramids, brute force at the coarsest level, two passes per finer level.
void run_multiscale(const SubdivSurface& surface, const TexelFrames& frames, const Image& exemplar,
                    const SurfaceSynthesisOptions& opt, SurfaceTexture& out, ExecContext* ctx);

/// Levels the multiscale method uses for these inputs (>= 1).
int multiscale_levels(const Image& exemplar, const TexelGrid& grid, const SurfaceSynthesisOptions& opt);

}  // namespace exsynth::surface
