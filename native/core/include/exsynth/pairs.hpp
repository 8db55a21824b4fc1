#pragma once
// Built-in exemplar pairs A -> A' for geometric texture by analogy (Bhat,
// Ingram & Turk 2004, Figures 2 and 7), generated at any resolution:
//
//   Spikes   flat slab -> slab with cones on top
//   Pits     flat slab -> slab with spherical dents in its top
//   Holes    flat slab -> slab with cylindrical holes through it
//   Grooves  cylinder  -> cylinder with grooves running around or along it
//   Dilate   sphere    -> larger sphere (an isotropic analogy)
//
// Every shape is an analytic signed distance (positive outside, world units)
// built from exact primitives with min (union) and max (difference): the
// zero set is exact, and values are true distances outside unions and near
// the surface (differences underestimate a little beside sharp rims).
//
// The grid is a cube of `resolution` voxels per edge covering the world cube
// [-1, 1]^3 (voxel centres at -1 + h/2 + h * i, h = 2 / resolution). Slabs
// are horizontal (normal +z, centred on z = 0) and the cylinder's axis is z;
// both run through the grid's faces, so no edges or end caps enter the
// exemplar. Features sit on a square lattice of `spacing` anchored at the
// world origin (centres at ((i + 1/2) spacing, (j + 1/2) spacing)), so when
// 2 / spacing is an integer the pattern tiles the grid.
#include <cstddef>
#include <cstdint>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {

enum class PairPreset { Spikes, Pits, Holes, Grooves, Dilate };

enum class GrooveDirection {
  Around,  ///< rings around the cylinder's axis (field: circles around z)
  Along,   ///< straight grooves parallel to the axis (field: +z)
};

/// Grid resolution limits (make_exemplar_pair checks 8..512; keep them in step).
constexpr int kMinPairResolution = 8;
constexpr int kMaxPairResolution = 512;

/// The pair's voxels across its cube from which its features keep their
/// shape (measured, A' against A: spikes add 19 % of the slab's top area at
/// 32 voxels, 27 % at 64, 30 % at 192; grooves 7.5 %, 12 %, 16 %).
constexpr int kPairDetailResolution = 64;
/// The most voxels along B's longest side that the pattern raises B's grid to.
constexpr int kMaxPatternResolution = 512;

/// B's resolution (voxels along its longest side) for a built-in pair that
/// covers `pattern_scale` of B's longest side: A and B share a voxel, so the
/// pair has round(pattern_scale * resolution) voxels across, and a small
/// pattern on a coarse grid makes lumps. Returns `resolution`, raised to the
/// least value that gives the pair kPairDetailResolution voxels, but not
/// past max(resolution, kMaxPatternResolution). Throws InvalidInput unless
/// resolution >= 1 and pattern_scale > 0.
int resolution_for_pattern(int resolution, double pattern_scale);

struct PairOptions {
  int resolution = 64;            ///< voxels per grid edge (8..512); the grid spans [-1, 1]^3
  // ---- slabs (spikes, pits, holes) ----
  double thickness = 0.4;         ///< slab thickness (world units; the grid is 2 wide)
  double spacing = 0.5;           ///< centre-to-centre distance of features (also grooves)
  double feature_radius = 0.12;   ///< cone base / pit sphere / hole / groove tube radius (< spacing / 2)
  double feature_height = 0.3;    ///< spike (cone) height above the slab's top
  double jitter = 0.0;            ///< random offset of slab features, fraction of spacing (0..0.25), seeded
  // ---- cylinder (grooves) ----
  double cylinder_radius = 0.6;
  GrooveDirection groove_direction = GrooveDirection::Around;
  // ---- sphere (dilate) ----
  double sphere_radius = 0.5;
  double dilation = 0.15;         ///< how much A' is larger: its radius is sphere_radius + dilation
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;         ///< drives the jitter only; the jitter of a feature depends on (seed, lattice cell)
};

struct ExemplarPair {
  Volume a, a_prime;  ///< 1 channel each: signed distance, positive outside, world units; same grid and transform
  Volume field_a;     ///< 3 channels: unit direction T per voxel, the direction the pattern runs
                      ///< (slabs and dilate: +x; grooves: along the grooves)
};

/// Builds the pair. Throws InvalidInput for an option out of range (naming
/// it and the fix), OverBudget before allocating more than memory_budget,
/// Cancelled via ctx.
ExemplarPair make_exemplar_pair(PairPreset preset, const PairOptions& opt = {}, ExecContext* ctx = nullptr);

/// Throws InvalidInput naming the first option out of range and the fix
/// (what make_exemplar_pair checks first, without building anything).
void validate_pair_options(PairPreset preset, const PairOptions& opt);

/// "spikes", "pits", "holes", "grooves", "dilate".
const char* pair_preset_name(PairPreset preset);
/// Every preset, in the order above.
constexpr PairPreset kPairPresets[] = {PairPreset::Spikes, PairPreset::Pits, PairPreset::Holes, PairPreset::Grooves,
                                       PairPreset::Dilate};

}  // namespace exsynth
