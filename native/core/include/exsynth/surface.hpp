#pragma once
// Texture synthesis directly on subdivision surfaces (Ying, Hertzmann,
// Biermann & Zorin 2001).
//
// The input mesh is the control mesh of a Catmull-Clark surface (evaluated
// with OpenSubdiv's Bfr). Every ptex face (a quad = one face, an n-gon = n
// sub-faces) owns one square texture map; texels are synthesized from an
// image exemplar by comparing neighbourhoods sampled on the limit surface in
// the tangent frame (v1, v2 = n x v1) of an orientation field. Two methods:
// Coherent (Ashikhmin-style, one pass) and Multiscale (Wei-Levoy pyramids,
// PCA + k-d tree). The result is packed into one atlas image with gutters and
// returned with the tessellated limit mesh and its UVs.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {

// ---- control mesh and limit surface ----------------------------------------

/// A polygon mesh: face f has face_sizes[f] vertices, listed counter-clockwise
/// (seen from outside) in face_vertices, faces one after the other.
struct PolygonMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<int> face_sizes;
  std::vector<int> face_vertices;
};

/// A point on the limit surface: ptex face and its (u, v) in [0, 1]^2.
struct SurfacePoint {
  int face = 0;
  double u = 0.5, v = 0.5;
};

/// Limit position and first derivatives in the ptex face's own (u, v).
struct LimitFrame {
  Eigen::Vector3d position, du, dv;
  Eigen::Vector3d normal() const { return du.cross(dv).normalized(); }
};

/// The Catmull-Clark limit surface of a control mesh, per ptex face. Built
/// once (validates the mesh: manifold, consistently oriented, no zero-area
/// faces); evaluation and walking are const and thread-safe.
/// Subdivision rules match Blender's Subdivision modifier with "Boundary
/// Smooth: All" and "Use Limit Surface" (boundary edges smooth, corners not
/// pinned; no creases).
class SubdivSurface {
 public:
  explicit SubdivSurface(const PolygonMesh& control, ExecContext* ctx = nullptr);
  ~SubdivSurface();
  SubdivSurface(SubdivSurface&&) noexcept;
  SubdivSurface& operator=(SubdivSurface&&) noexcept;

  int ptex_face_count() const;
  int control_vertex_count() const;
  const PolygonMesh& control_mesh() const;
  /// The control face a ptex face belongs to, and its sub-face index (0 for quads).
  int control_face(int ptex) const;
  int sub_face(int ptex) const;
  int first_ptex_face(int control_face) const;

  LimitFrame evaluate(const SurfacePoint& p) const;
  /// Per-control-vertex data (dim floats per vertex, e.g. a field) evaluated
  /// on the limit surface with the same stencils as the positions.
  class VertexData;
  VertexData prepare_vertex_data(const std::vector<float>& data, int dim) const;
  void evaluate_data(const VertexData& data, const SurfacePoint& p, double* out) const;

  /// Ptex edges: 0 = (v = 0), 1 = (u = 1), 2 = (v = 1), 3 = (u = 0), each
  /// parametrised by t in [0, 1] counter-clockwise. Crossing edge `edge` of
  /// `ptex` at t lands on edge `edge` of ptex face `face` at its t (face = -1
  /// at a boundary); scale = |dt_neighbour / dt| (2 or 0.5 where a quad meets
  /// the half-edges of an n-gon's sub-faces, else 1).
  struct EdgeCrossing {
    int face = -1, edge = -1;
    double t = 0, scale = 1;
  };
  EdgeCrossing cross_edge(int ptex, int edge, double t) const;
  /// The neighbour across the middle of an edge (for traversals).
  struct Neighbour {
    int face = -1, edge = -1;
  };
  Neighbour neighbour(int ptex, int edge) const;

  /// Moves p along the surface by the tangent displacement d (3D; re-projected
  /// into each tangent plane on the way, so its length is kept as arc length),
  /// stepping from face to face across edges and around corners. Returns false
  /// (p stops at the edge) when the walk leaves the surface at a boundary.
  bool walk(SurfacePoint& p, Eigen::Vector3d d) const;

  /// Total limit-surface area of each ptex face (Gauss quadrature).
  std::vector<double> ptex_face_areas() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

class SubdivSurface::VertexData {
 public:
  int dim = 0;
  std::vector<std::vector<double>> patch_points;  ///< per control face
};

// ---- orientation -------------------------------------------------------------

/// A smooth unit tangent field on the control vertices when the mesh has none:
/// starts from `axis` projected into each tangent plane and minimises the
/// cosine energy sum_edges (1 - cos(angle between neighbours)) (no 90-degree
/// symmetry) by repeated neighbour averaging. Singularities are allowed.
std::vector<Eigen::Vector3f> smooth_surface_field(const PolygonMesh& control, const Eigen::Vector3f& axis,
                                                  int iterations = 50, ExecContext* ctx = nullptr);

// ---- synthesis ----------------------------------------------------------------

enum class SurfaceMethod { Coherent, Multiscale };

/// Most channels an exemplar may have (colour, alpha, height, ...).
constexpr int kMaxSurfaceChannels = 16;

struct SurfaceSynthesisOptions {
  SurfaceMethod method = SurfaceMethod::Coherent;
  /// Texels per unit of surface length; each ptex face gets
  /// ceil(texels_per_unit * sqrt(area)) texels a side (clamped to
  /// [min_face_resolution, max_face_resolution]). 0 = use face_resolution.
  double texels_per_unit = 0.0;
  int face_resolution = 16;  ///< texels a side of every ptex face when texels_per_unit = 0
  int min_face_resolution = 2, max_face_resolution = 512;
  /// Exemplar pixels per texel spacing: > 1 makes the pattern smaller on the surface.
  double exemplar_scale = 1.0;
  /// Coherent: neighbourhood radius in samples (2 = 5 x 5, the paper's).
  int coherent_radius = 2;
  /// Coherent: passes in synthesis order; passes after the first see every
  /// neighbour (not only the causal ones) and keep a texel's source unless a
  /// candidate matches better.
  int coherent_passes = 2;
  /// Multiscale: pyramid levels (0 = as many as the exemplar and faces allow,
  /// at most 4), neighbourhood sizes of the current and the coarser level.
  int levels = 0;
  int fine_neighborhood = 9, coarse_neighborhood = 5;
  int knn = 4;                      ///< candidates from the k-d tree (re-ranked by exact distance)
  /// Random pick among those within this fraction of the best (paper: 0.1);
  /// the coarsest level's brute force uses at least 0.1 (else two seeds can
  /// grow the same texture from a small exemplar).
  double knn_tolerance = 0.0;
  /// Multiscale: a coherent candidate (a neighbour's source shifted back by
  /// its offset) is taken unless the best k-d tree match is more than
  /// (1 + coherence) closer in squared distance; 0 = the k-d tree alone.
  double coherence = 1.0;
  double pca_variance = 0.97;
  int max_pca_dims = 24;
  bool tileable_exemplar = false;   ///< wrap exemplar lookups (else clamp / reject)
  /// Place neighbourhood samples through vertex charts (Ying et al. §4.2:
  /// the chart of the nearest corner, its Jacobian, back to the face the
  /// sample falls in), walking on the limit surface only where a
  /// neighbourhood leaves its chart; false = walk every sample.
  bool vertex_charts = true;
  /// Per-control-vertex tangent field (the mesh's exsynth_field or a preset);
  /// empty = smooth_surface_field(axis = field_axis).
  std::vector<Eigen::Vector3f> field;
  Eigen::Vector3f field_axis = Eigen::Vector3f(0, 0, 1);
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;
};

/// One map per ptex face, all channels of the exemplar.
struct SurfaceTexture {
  int channels = 0;
  std::vector<int> face_resolution;          ///< texels a side, per ptex face
  std::vector<std::size_t> face_offset;      ///< first texel of each face (+ total at the end)
  std::vector<float> texels;                 ///< texel (i, j) of face f: (face_offset[f] + j * R + i) * C
  std::vector<float> source;                 ///< exemplar (x, y) each texel came from, 2 per texel
  double sample_spacing = 0.0;               ///< surface length of one exemplar pixel
  /// Neighbourhood samples placed through vertex charts, and walked on the
  /// limit surface (where a neighbourhood left its chart, or without charts).
  std::uint64_t chart_samples = 0, walked_samples = 0;
  std::size_t texel_count() const { return face_offset.empty() ? 0 : face_offset.back(); }
};

/// Texel resolution per ptex face for the options (validates them); also
/// used to refuse an over-large texel budget before allocating.
std::vector<int> surface_face_resolutions(const SubdivSurface& surface, const SurfaceSynthesisOptions& opt);

/// Synthesizes the texture. `exemplar`: any channel count (colour, alpha,
/// height stacked as channels). Throws InvalidInput (exemplar smaller than the
/// neighbourhood, bad field or options), OverBudget, Cancelled.
SurfaceTexture synthesize_surface(const SubdivSurface& surface, const Image& exemplar,
                                  const SurfaceSynthesisOptions& opt = {}, ExecContext* ctx = nullptr);

// ---- output: atlas and limit mesh ---------------------------------------------

struct SurfaceAtlas {
  Image image;                                 ///< row 0 = top (PNG order)
  std::vector<std::array<int, 2>> tile_origin; ///< per ptex face: pixel (x, y) of the map's texel (0, 0)
  int gutter = 0;
  /// Atlas UV (origin bottom-left, as Blender and OBJ) of a point on face f.
  Eigen::Vector2f uv(const SurfaceTexture& tex, const SurfacePoint& p) const;
};

/// Packs every face map into one image (shelves by decreasing size), each
/// framed by `gutter` texels copied from the neighbouring faces (across edges
/// and corners), so bilinear filtering and mip-maps see no seams.
SurfaceAtlas build_surface_atlas(const SubdivSurface& surface, const SurfaceTexture& tex, int gutter = 2,
                                 ExecContext* ctx = nullptr);

struct LimitMesh {
  std::vector<Eigen::Vector3f> vertices;     ///< welded across face borders
  std::vector<Eigen::Vector3f> normals;      ///< limit normals per vertex
  std::vector<Eigen::Vector4i> quads;
  std::vector<Eigen::Vector2f> corner_uvs;   ///< 4 per quad, into the atlas
};

/// The limit surface tessellated with atlas UVs: segments x segments quads
/// per n-gon sub-face and 2 segments x 2 segments per quad (borders match;
/// segments = 2^(L-1) gives the vertices of Blender's Subdivision level L). displacement_channel >= 0 moves each vertex along the limit
/// normal by displacement_scale * (value - displacement_midlevel) of that texel channel.
LimitMesh surface_limit_mesh(const SubdivSurface& surface, const SurfaceTexture& tex, const SurfaceAtlas& atlas,
                             int segments, int displacement_channel = -1, double displacement_scale = 0.0,
                             double displacement_midlevel = 0.5, ExecContext* ctx = nullptr);

/// Upper end of surface_limit_mesh's segments (per n-gon sub-face).
constexpr int kMaxSurfaceSegments = 64;

// ---- the whole job ------------------------------------------------------------

struct SurfaceOutputOptions {
  int gutter = 2;                  ///< atlas texels copied from neighbouring faces
  int segments = 2;                ///< limit-mesh segments per n-gon sub-face (x2 per quad)
  int displacement_channel = -1;   ///< >= 0: displace the limit mesh by this channel
  double displacement_scale = 0.0, displacement_midlevel = 0.5;
};

struct SurfaceResult {
  SurfaceTexture texture;
  SurfaceAtlas atlas;
  LimitMesh mesh;
};

/// Control mesh + exemplar -> texture, atlas and limit mesh (all stages,
/// each reporting through ctx).
SurfaceResult texture_surface(const PolygonMesh& control, const Image& exemplar, const SurfaceSynthesisOptions& opt = {},
                              const SurfaceOutputOptions& out = {}, ExecContext* ctx = nullptr);

}  // namespace exsynth
