#pragma once
// Texel grids on ptex faces and the per-texel limit frames (private).
//
// Every ptex face f has an R_f x R_f map; texel (i, j) sits at the centre
// u = (i + 0.5) / R_f, v = (j + 0.5) / R_f. The finest grid caches the limit
// position, derivatives and orientation frame at each texel centre: walks
// then evaluate the surface to first order from the nearest cached texel
// instead of calling Bfr (exact on the affine parts of the surface, within
// a texel's curvature elsewhere).
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/surface.hpp"

namespace exsynth::surface {

/// Sizes and offsets of one resolution of texels.
struct TexelGrid {
  std::vector<int> res;               ///< per ptex face
  std::vector<std::size_t> offset;    ///< per ptex face, + total
  std::vector<int> face_of;           ///< per texel

  explicit TexelGrid(std::vector<int> resolution = {});
  std::size_t size() const { return offset.empty() ? 0 : offset.back(); }
  /// Texel containing (u, v) of face f.
  std::size_t texel(const SurfacePoint& p) const;
  SurfacePoint centre(std::size_t t) const;
  /// The grid with every face's resolution halved (at least 1).
  TexelGrid coarser() const;
};

/// Limit frames at the texel centres of a grid.
struct TexelFrames {
  TexelGrid grid;
  std::vector<Eigen::Vector3f> position, du, dv;
  std::vector<Eigen::Vector3f> t1, t2;  ///< orientation v1 and v2 = n x v1 (unit)

  /// First-order limit frame at p from the nearest cached texel.
  LimitFrame approx(const SurfacePoint& p) const;
};

/// Evaluates frames at every texel of `grid` (parallel, deterministic). The
/// field (per-vertex vectors) is evaluated with the limit stencils and
/// projected into each tangent plane; where it vanishes, du's direction.
TexelFrames build_texel_frames(const SubdivSurface& surface, TexelGrid grid,
                               const std::vector<Eigen::Vector3f>& field, ExecContext* ctx);

/// Walk with the texel cache (see SubdivSurface::walk). landing_only: a
/// looser tolerance, for walks that only need the texel they end in.
bool walk_cached(const SubdivSurface& surface, const TexelFrames& frames, SurfacePoint& p,
                 const Eigen::Vector3d& d, bool landing_only = false);

/// The (2r+1)^2 sample points around texel t at spacing h in its frame:
/// sample (l, m) (l, m in [-r, r], row-major over m then l) is reached by
/// walking h (l v1 - m v2) — exemplar x along v1, exemplar rows (y down)
/// along -v2, so the exemplar is not mirrored seen from outside. valid[k] is
/// false when the walk left the surface at a boundary.
void sample_points(const SubdivSurface& surface, const TexelFrames& frames, std::size_t t, double h, int r,
                   SurfacePoint* out, bool* valid);

/// Largest sample grid: 11 x 11.
constexpr int kMaxSamples = 121;

/// The same sample grid as sample_points around point c, for steps a = h v1
/// and b = h v2, marched: each row starts one step from the previous row's
/// start, each sample one step from its neighbour towards the centre column
/// (the walk re-projects the step into each tangent plane). Walking every
/// sample from the centre cost 2-3x more face crossings. A sample past a
/// boundary (valid false) keeps the point where its walk stopped.
void march_points(const SubdivSurface& surface, const TexelFrames& frames, const SurfacePoint& c,
                  const Eigen::Vector3d& a, const Eigen::Vector3d& b, int r, bool landing_only, SurfacePoint* out,
                  bool* valid);

class VertexCharts;
struct ChartStats;

/// The same sample grid as march_points, placed through a vertex chart
/// (Ying et al. §4.2, steps 1-5): c goes into the chart of the corner of its
/// face nearest to it, the steps a, b (3D, in c's tangent plane) become
/// chart steps through the chart's Jacobian and the surface derivatives
/// du, dv at c (least squares, as a walk's first step), and sample (l, m)
/// at y + l tau_a - m tau_b is mapped back to the face it falls in, then
/// moved within the chart until its offset from c is l a - m b to 0.1 step
/// (at most 2 quasi-Newton steps: the regular chart layout bends straight
/// lines where the real star's angles differ, as on triangles). Samples
/// where the chart ends (past its ring, a boundary, a T-junction; corners
/// without a chart) are walked from c instead. stats (optional) counts both.
void chart_points(const SubdivSurface& surface, const TexelFrames& frames, const VertexCharts& charts,
                  const SurfacePoint& c, const Eigen::Vector3d& du, const Eigen::Vector3d& dv,
                  const Eigen::Vector3d& a, const Eigen::Vector3d& b, int r, bool landing_only, SurfacePoint* out,
                  bool* valid, ChartStats* stats = nullptr);

/// Bilinear exemplar lookup at float pixel (x, y): clamped or wrapped.
void sample_exemplar(const Image& ex, double x, double y, bool wrap, float* out);

}  // namespace exsynth::surface
