#pragma once
// Patch-based geometry texture synthesis on point-set surfaces (the seed
// method of issue 9: patches chosen by an SDF metric, TPS-warped, blended).
//
// A geometry texture is an oriented point set (positions + unit normals)
// over a reference plane z = 0: its exemplar box is an axis-aligned square
// [box_min, box_max] in x, y, and the geometry extends past the box (the
// padding) so that patches near the border still have whole neighbourhoods.
//
// Synthesis places square patches of side `patch_size` in scan-line order,
// each overlapping the already placed ones by the extra region E. For every
// candidate position in the exemplar the distance between the exemplar's
// signed distance field (Adamson & Alexa's point-set surface) and the
// output's field inside the overlap is computed (the exemplar's field is
// sampled once, so D(T_in) is a window of one grid); one of the candidates
// within (1 + epsilon) of the best is picked at random from (seed, patch).
// The patch is warped by a thin-plate spline fitted to pairs between its
// overlap points and the output's (iterated greedy pairing with a cost on
// position, normal and surface variation and a coherence term), normals go
// through the spline's Jacobian, and the overlap is blended by moving each
// point toward its projection on the other side's surface, weighted by how
// far it lies into the patch. The output lives in a hashed grid of buckets;
// the border strip E is cropped and the density relaxed at the end.
//
// On curved targets (synthesize_points_on_mesh) the same steps run in a
// local chart per patch: tangent frame from the target's direction field,
// chart coordinates (u, v, h) = (tangent-plane position of the foot point on
// the target, height along its normal).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "exsynth/exec_context.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/mesh.hpp"

namespace exsynth {

struct OrientedPoints {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  ///< unit length, one per position
  std::size_t size() const { return positions.size(); }
};

struct PointExemplar {
  OrientedPoints points;
  Eigen::Vector2d box_min{0.0, 0.0};  ///< the exemplar box in the reference plane (x, y);
  Eigen::Vector2d box_max{1.0, 1.0};  ///< points outside it are the padding
};

struct PointTextureOptions {
  double patch_size = 0.35;     ///< patch side, exemplar units (must fit in the padded exemplar)
  double extra = 0.3;           ///< the overlap E as a fraction of the patch side (paper: 1/4 - 1/3)
  double epsilon = 0.1;         ///< candidates within (1 + epsilon) of the best distance are eligible
  int grid_resolution = 12;     ///< SDF cells along a patch side (the metric's grid)
  double w_sdf = 1.0;           ///< metric: weight of the signed-distance difference
  double w_gradient = 0.25;     ///< metric: weight of the gradient (normal) difference
  // Pairing cost, the paper's Equation 2 with positions in point spacings s:
  // c = w_p |dp|^2 / s^2 + (w_n / 2)(1 - n.n') + w_v (sigma - sigma')^2 ...
  double w_p = 1.0;
  double w_n = 2.0;
  double w_v = 20.0;
  double max_pair_distance = 3.0;   ///< ... pairs farther than this many spacings are refused
  double min_pair_normal_dot = 0.5; ///< ... and pairs whose normals disagree more
  double max_pair_variation = 0.1;  ///< ... or whose surface variations differ more
  // Coherence g with the neighbouring pairs (Gaussian-weighted means f_l, f_d of their displacements):
  double w_l = 1.0;             ///< w_l | |d| - f_l | / s: length difference of the displacement
  double w_d = 2.0;             ///< (w_d / 2)(1 - f_d . d / |d|): direction difference
  int pairing_iterations = 3;   ///< greedy rounds (the first without coherence)
  int max_pairs = 160;          ///< TPS centres (pairs are thinned to one per metric cell)
  double tps_regularization = 1e-6;
  int blend_iterations = 2;     ///< progressive projection steps in the overlap
  int relax_iterations = 2;     ///< density relaxation rounds at the end (0 = off)
  double bandwidth = 1.5;       ///< point-set surface Gaussian width, in point spacings
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;
};

/// Options per built-in exemplar: the pairing weights are the paper's Table 1
/// rows ("heightfield", also the preset of "bumps" and of height-field
/// exemplars; "chainmail", "weave", "flowers"), the patch sizes and the
/// metric's weights ours. "default" (user exemplars) keeps the struct's
/// defaults. Throws InvalidInput for other names.
PointTextureOptions point_texture_preset(const std::string& name);
constexpr const char* kPointPresetNames = "default, heightfield, bumps, chainmail, weave or flowers";
/// The exemplar density the add-on and the CLI start from (points per unit of
/// surface area of a built-in or sampled exemplar).
constexpr double kDefaultPointDensity = 8000.0;
/// The built-in exemplars (make_point_exemplar's names).
constexpr const char* kPointBuiltins[] = {"bumps", "chainmail", "weave", "flowers"};

struct PointTextureTimes {
  double search = 0, warp = 0, blend = 0, other = 0;  ///< seconds, as the paper's Table 1
};

struct PointTextureResult {
  OrientedPoints points;
  std::size_t patches = 0;
  std::size_t pairs = 0;          ///< TPS pairs over all patches
  std::size_t fallbacks = 0;      ///< blend projections that used the two-ray intersection
  double spacing = 0;             ///< the exemplar's mean nearest-neighbour distance
  double density = 0;             ///< exemplar points per unit area of its box
  PointTextureTimes times;
};

/// Grows `exemplar` over [0, width] x [0, depth] of the reference plane (the
/// exemplar's units). Throws InvalidInput, OverBudget, Cancelled.
PointTextureResult synthesize_points(const PointExemplar& exemplar, double width, double depth,
                                     const PointTextureOptions& opt = {}, ExecContext* ctx = nullptr);

/// Grows `exemplar` over the surface of `target`, the exemplar's reference
/// plane laid onto the surface and its x axis along `field` (one tangent
/// vector per vertex of target; zero vectors are filled from the normal).
/// `scale`: target units per exemplar unit. Throws InvalidInput, OverBudget, Cancelled.
PointTextureResult synthesize_points_on_mesh(const PointExemplar& exemplar, const TriangleMesh& target,
                                             const std::vector<Eigen::Vector3f>& field, double scale,
                                             const PointTextureOptions& opt = {}, ExecContext* ctx = nullptr);

/// What synthesize_points_on_mesh makes, estimated before any work from
/// the exemplar's density (points per unit of its box), the target's surface
/// area and the scale; its memory check uses the same figures.
struct PointTextureEstimate {
  double patches = 0;  ///< patch centres: Poisson-disk, 0.42 patch sides apart
  double points = 0;   ///< output points (measured: 0.8-1.0 of this)
  double bytes = 0;    ///< peak memory of the synthesis
  double seconds = 0;  ///< at kPointSecondsPerPoint
};

/// Seconds per output point on the 2-core machine the benchmarks run on
/// (chainmail and bumps on a cube and the bunny: 80-115 microseconds).
constexpr double kPointSecondsPerPoint = 1.1e-4;
/// The default scale aims at this many output points (about 30 s there).
constexpr double kDefaultPointsOnMesh = 250000;

PointTextureEstimate estimate_points_on_mesh(double exemplar_density, double target_area, double scale,
                                             const PointTextureOptions& opt);

/// The scale (target units per exemplar unit) giving about
/// kDefaultPointsOnMesh points over `target_area`. Throws InvalidInput if
/// either figure is not a positive number.
double default_points_scale(double exemplar_density, double target_area);

/// A built-in exemplar's surface area per unit of box area (chainmail about
/// 2.9): its points per unit of box area are its density times this.
double point_exemplar_surface_ratio(const std::string& name);

/// Checks positions/normals (same count, finite, unit normals within 1e-2,
/// non-empty, points inside the box); throws InvalidInput naming `what`.
void validate_exemplar(const PointExemplar& exemplar, const char* what = "exemplar");

// ---- exemplars ---------------------------------------------------------------

/// Even sampling of a mesh's surface: `density` points per unit area,
/// uniform random (area-weighted, from (seed, index)) with 4x oversampling,
/// then Poisson-disk elimination in index order on a hashed grid (minimum
/// distance 0.75 / sqrt(density)). Normals are the faces'.
/// Throws InvalidInput (empty mesh, zero area, density <= 0), OverBudget.
OrientedPoints sample_mesh_points(const TriangleMesh& mesh, double density, std::uint64_t seed = 0,
                                  std::size_t memory_budget = kDefaultMemoryBudget, ExecContext* ctx = nullptr);

/// Built-in generated geometry textures, exemplar box [0, 1]^2, padding
/// `padding` on every side: "bumps" (a height field of round bumps),
/// "chainmail" (interlocked tori), "weave" (over-under tubes), "flowers"
/// (small flowers on stems over a ground plane). `density`: points per unit
/// surface area. Throws InvalidInput for unknown names or density <= 0.
PointExemplar make_point_exemplar(const std::string& name, double density = 20000.0, double padding = 0.35,
                                  std::uint64_t seed = 0, ExecContext* ctx = nullptr);

/// A height-field exemplar: heights (rows = y, cols = x, row-major) of
/// `pixel_size` units per pixel, sampled evenly at `density`; the box is the
/// image's inner part, `padding` pixels on every side being padding.
PointExemplar height_field_exemplar(const std::vector<float>& heights, int rows, int cols, double pixel_size,
                                    double density, int padding, std::uint64_t seed = 0,
                                    ExecContext* ctx = nullptr);

}  // namespace exsynth

namespace exsynth {

// ---- surface from the points ---------------------------------------------------

struct PointMeshOptions {
  double radius = 1.5;      ///< sphere radius, in point spacings (smaller leaves gaps between the spheres: the inner shell joins the outer)
  double voxel = 0.75;      ///< voxel size, in point spacings
  int smoothing = 1;        ///< mean-curvature flow passes on the level set (0 = none)
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;   ///< unused: deterministic
};

/// A renderable mesh from an oriented point set: a sphere of radius r at
/// p - r n for every point (tangent to the surface from inside, so the outer
/// side of the union is the surface), OpenVDB's particles-to-level-set, a
/// little smoothing, then volume-to-mesh. `spacing` <= 0: measured. Closed
/// shapes come out as their surface; open sheets as a slab 2 r thick below
/// them. Throws InvalidInput, OverBudget, Cancelled.
TriangleMesh points_to_mesh(const OrientedPoints& points, double spacing = 0.0, const PointMeshOptions& opt = {},
                            ExecContext* ctx = nullptr);

}  // namespace exsynth
