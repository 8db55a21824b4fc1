#pragma once
// Vertex charts (Ying et al. 2001, §4.2) over the ptex faces (private).
//
// Every corner shared by ptex faces (control vertices, n-gon centres and
// edge midpoints) with a star of k faces has a chart: a plane in which face
// j of the star is sector j of the regular k-gon star (opening 2 pi / k;
// pi / k on a boundary: the half-star), mapped by the Catmull-Clark limit of
// the regular star's linear layout (the centre, the rays at angles 2 pi j / k
// and one more ring, subdivided to the limit; its leading term at the centre
// is the characteristic map, so the surface seen through the chart is C1
// there, and on regular vertices the map is exactly linear). The limit is
// tabulated per valence on a (2N + 1)^2 grid over the sector's star face and
// its ring (sector coordinates [0, 2]^2) and read bilinearly; the inverse is
// point location (the sector by angle, the rays being exact) + Newton on the
// bilinear table. A chart point past a star face's outer edge lands in the
// ring face across that edge (stepped over the edge by cross_edge); beyond a
// star face's far corner, past the ring, past a boundary or at a T-junction
// (a quad's edge meeting an n-gon's edge midpoint) the chart ends and
// from_chart says so (callers walk instead).
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "exsynth/surface.hpp"

namespace exsynth::surface {

/// The tabulated limit map of one sector of a regular star: y(s, t) for
/// sector coordinates (s, t) in [0, 2]^2 (the star face is [0, 1]^2, s
/// along the ray at angle j * opening, t along the next ray).
struct SectorTable {
  int cells = 16;                     ///< cells per unit of (s, t)
  Eigen::Vector2d ray0, ray1;         ///< unit directions of the sector's two rays
  /// (2 cells + 1)^2 nodes, row-major over t then s: the limit point and its
  /// derivatives in s and t.
  std::vector<Eigen::Vector2d> y, ys, yt;
  /// The regular stars (valence 4 inside, 2 on a boundary): the limit of
  /// the linear layout is the layout itself, y = s ray0 + t ray1.
  bool linear = false;

  /// y(s, t), Hermite-interpolated between the nodes (bicubic, no twist:
  /// C1 across cells, so the sampling Jacobian does not jump where a
  /// neighbourhood crosses a cell; bilinear cells put the two sides of a
  /// texel centre on a cell border 2-3 % apart), and its Jacobian
  /// d y / d(s, t) (columns).
  Eigen::Vector2d eval(double s, double t, Eigen::Matrix2d* jac = nullptr) const;
  /// (s, t) with eval(s, t) = y. exact: Newton to round-off (false when it
  /// does not converge); else the tabulated inverse read bilinearly (within
  /// 1e-3 of a face: enough for the texel a sample lands in; a third of the
  /// cost of the neighbourhood stage with Newton).
  bool invert(const Eigen::Vector2d& y, double& s, double& t, bool exact = true) const;

  /// The inverse, tabulated over the linear layout's coordinates (ls, lt) =
  /// [ray0 ray1]^-1 y in [0, kInverseRange]^2: (s, t) at the nodes.
  static constexpr double kInverseRange = 3.0;
  std::vector<Eigen::Vector2d> inverse;
  Eigen::Matrix2d to_linear;  ///< [ray0 ray1]^-1
  void build_inverse();
};

class VertexCharts {
 public:
  explicit VertexCharts(const SubdivSurface& surface);

  /// The chart of corner q (0..3 = (0,0), (1,0), (1,1), (0,1)) of a ptex
  /// face; -1 where the corner has none (valence 2 inside, one face on a
  /// boundary, T-junctions).
  int chart(int face, int corner) const {
    const int c = corner_chart_[std::size_t(face) * 4 + std::size_t(corner)];
    return c >= 0 && !charts_[std::size_t(c)].unused ? c : -1;
  }
  /// Stars with a face touching a corner without a chart (next to an open
  /// mesh's corners) are built but not used (chart() gives -1 there).
  bool used(int chart) const { return !charts_[std::size_t(chart)].unused; }
  /// The corner of (u, v)'s quarter of the face (the nearest in parameter).
  static int nearest_corner(double u, double v) { return u < 0.5 ? (v < 0.5 ? 0 : 3) : (v < 0.5 ? 1 : 2); }
  int chart_count() const { return int(charts_.size()); }
  int valence(int chart) const { return charts_[std::size_t(chart)].k; }
  bool boundary(int chart) const { return charts_[std::size_t(chart)].boundary; }
  /// The star faces of a chart, in sector order (counter-clockwise).
  std::vector<int> star_faces(int chart) const;

  /// Chart coordinates of p, which must lie on a face of the chart's star
  /// (p.face has a corner in this chart), and d y / d(u, v) (columns).
  Eigen::Vector2d to_chart(int chart, const SurfacePoint& p, Eigen::Matrix2d* jac = nullptr) const;
  /// The surface point at chart coordinates y: false where the chart ends
  /// (see the header comment; out is then unchanged).
  /// exact: see SectorTable::invert. sector_hint: where to start looking
  /// (the sector of the neighbourhood's centre; sectors are searched from it
  /// by the side of the rays y falls on).
  bool from_chart(int chart, const Eigen::Vector2d& y, SurfacePoint& out, bool exact = true,
                  int sector_hint = 0) const;
  /// The sector of the chart that p's face is in.
  int sector_of(int chart, int face) const;

 private:
  struct Star {
    int first = 0, k = 0;  // star_[first .. first + k): (face, corner) by sector
    bool boundary = false;
    bool unused = false;   // see used()
    double opening = 0;    // sector angle
    const std::vector<SectorTable>* tables = nullptr;  // per sector (one shared when interior)
  };
  const SectorTable& table(const Star& st, int sector) const {
    return (*st.tables)[st.tables->size() == 1 ? 0 : std::size_t(sector)];
  }
  /// A star face: ptex face, its corner at the chart's centre, and the
  /// scale from its corner-local (s, t) to sector coordinates: 2 for a quad
  /// in a star with n-gon sub-faces (a sub-face spans half a control edge, so
  /// the quad's quarter at the corner is the refined mesh's face), else 1.
  struct StarFace {
    int face = 0, corner = 0;
    double scale = 1;
  };
  const SubdivSurface& surface_;
  std::vector<Star> charts_;
  std::vector<StarFace> star_;
  std::vector<int> corner_chart_, corner_sector_;
  std::map<std::pair<int, bool>, std::unique_ptr<std::vector<SectorTable>>> tables_;  // (valence, boundary)
};

/// Per-neighbourhood counts of how samples were placed (for measurements).
struct ChartStats {
  std::uint64_t in_chart = 0, walked = 0;
};

}  // namespace exsynth::surface
