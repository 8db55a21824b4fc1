#pragma once
// Solid texture synthesis from 2D exemplars (Kopf et al. 2007, "Solid
// Texture Synthesis from 2D Exemplars") and the same optimiser in 2D. Images
// default to another method, synthesis of exemplar coordinates
// (ImageMethod::Coordinates, native/core/src/image/coordinate_synthesis.hpp).
//
// Global texture optimisation: the energy is the sum over voxels v and the
// three axis-aligned slices through v of ||s_v,i - e_v,i||^r, where s_v,i is
// the n x n neighbourhood of v in the slice orthogonal to axis i and e_v,i
// its best match in that axis's exemplar. It alternates a search phase
// (matches for a sparse grid: every 2nd voxel along both slice axes) and an
// optimisation phase (each voxel = IRLS-weighted average of the exemplar
// texels that the overlapping matched neighbourhoods put on it, re-weighted
// for histogram matching), coarse to fine.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "exsynth/grid.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth {

/// Default working resolution (see TextureOptimizationOptions::max_exemplar_size):
/// larger exemplars are analysed at 1/2, 1/4, ... of their size (a 512^2 photo at 256^2).
constexpr int kDefaultMaxExemplarSize = 256;
/// Largest output edge: solids (size^3 voxels) and images (pixels).
constexpr int kMaxSolidSize = 2048;
/// Upper ends of TextureOptimizationOptions::levels and ::iterations (check_options).
constexpr int kMaxLevels = 8;
constexpr int kMaxIterations = 100;
/// Upper end of TextureOptimizationOptions::feature_threshold (in exemplar
/// luminance standard deviations: no pixel is that far below its window's mean).
constexpr double kMaxFeatureThreshold = 10.0;
constexpr int kMaxImageSize = 16384;

/// Smallest output edge (voxels or pixels) the optimiser accepts with these
/// levels and neighbourhood: the coarsest level, each level halving the
/// edge (rounding up), must still hold one n x n neighbourhood. The one rule
/// for solids (size) and images (width and height): 29 for the defaults.
int min_texture_size(int levels, int neighborhood);

/// How the search phase finds an exemplar neighbourhood for a voxel.
enum class SolidSearch {
  KCoherence,  ///< default: candidates from neighbours' matches + their k most similar neighbourhoods
  KdTree,      ///< paper-faithful: approximate nearest neighbour in PCA space (nanoflann, tolerance eps)
  Exact,       ///< brute force over every exemplar neighbourhood, full dimension (reference for tests)
};

/// Solids' feature_weight (SolidOptions): with it the slices of 64^3 solids
/// of 8 exemplars come out crisper (weight 2: sharpness 0.66 -> 0.88,
/// contrast 0.79 -> 0.89, hist_emd 5.3 -> 4.6; 16 of 32 slice targets against
/// 8) and the cow's cut faces show stones outlined by dark cracks where 0
/// gives soft blotches, for nn_rel 0.53 -> 0.62 and ~18 % more CPU (ninth
/// pass). 3 with histogram_values (eleventh pass): stone33's stones get
/// outlines, sharpness 0.92 -> 0.97 over the 8; slice targets 18 of 32 at
/// 64^3 (as at 2) and 21 of 32 at 128^3 (19 at 2) (drkwood2's contrast 0.81
/// at 3 without histogram_values; 4 overshoots; docs/solid.md).
constexpr double kSolidFeatureWeight = 3.0;

/// Solids' histogram_values (SolidOptions): the exemplar values match the
/// exemplars' histogram. On 64^3 slices of 8 exemplars (feature weight 2) it changes those whose
/// plain values miss the histogram (stone33: contrast 0.76 -> 0.89, hist_emd
/// 10.8 -> 7.3; granite1, brick, slate, brownground), for ~1.5-2 s more CPU
/// at 128^3 there (~10 % of the solid; twelfth pass); where the plain values
/// already match (crackedground, marble1) the plain pass writes at its own
/// cost (docs/solid.md, eleventh pass). The first step; a round that
/// overshoots halves it.
constexpr double kSolidHistogramValues = 0.3;

/// Solids' feature_threshold (SolidOptions): the feature channel marks the
/// pixels darker than their window's mean by more than one luminance
/// standard deviation (the cracks and mortar themselves, not half of every
/// window). With kSolidRotateExemplar: 23 of 24 sharpness / contrast /
/// hist_emd slice targets of 8 exemplars at 64^3, against 18 at 0, and 28
/// of 33 against 24 on 11 held-out gimp-data patterns (docs/solid.md,
/// fifteenth pass). Alone it lines up round-featured exemplars' cells as
/// parallel sheets (crackedground: 3D elongation 2.5), hence the turns.
constexpr double kSolidFeatureThreshold = 1.0;

/// When TextureOptimizationOptions::rotate_exemplar uses the exemplar's
/// quarter turns.
enum class RotateExemplar {
  Off,
  On,
  /// On when the exemplar's features are round (exemplar_feature_stretch
  /// below kRoundFeatureStretch): cracks, cells, pebbles, paper; off for
  /// what runs one way (wood, bricks, bedded stone), whose turns would put
  /// mortar and grain the wrong way.
  Auto,
};
/// The names of RotateExemplar's values, in its order.
const std::vector<std::string>& rotate_exemplar_names();
const char* rotate_exemplar_name(RotateExemplar r);
/// "off", "on" or "auto"; InvalidInput naming them otherwise.
RotateExemplar rotate_exemplar_from_name(const std::string& name);

/// The exemplar's feature stretch: sqrt(largest / smallest eigenvalue) of
/// the second moments of its luminance autocorrelation's central lobe (the
/// lags connected to 0 where the autocorrelation, after a Gaussian blur of
/// one pixel, exceeds 0.3); 1 = round features. exsynth.quality.lobe_stretch
/// is the same measure.
double exemplar_feature_stretch(const Image& exemplar);
/// RotateExemplar::Auto turns exemplars whose stretch is below this. Of 46
/// gimp-data and bundled exemplars at 128^2, those below are leopard 1.01,
/// crackedground 1.04, java 1.07, amethyst 1.15, marble2 1.18, sky 1.21,
/// paper 1.24 and terra 1.28, none with a direction; the nearest above,
/// pool 1.31, walnut 1.37, marble3 1.38, parque3 1.41 and wood5 1.45, mix
/// water and marble with wood that runs one way (docs/solid.md, fifteenth
/// pass). Conservative: round-ish exemplars with a mild direction
/// (brownground 1.58, granite1 1.70) stay unturned.
constexpr double kRoundFeatureStretch = 1.3;
/// The quarter turns' mosaic takes up to this many pixels of the
/// exemplar's central square per turn, or its quadrants when they are larger
/// (solid/exemplar_rotations.hpp): turning then costs at most the windows of
/// a 256^2 exemplar more than not turning.
constexpr int kMaxTurnedTile = 128;
/// Solids' rotate_exemplar (SolidOptions).
constexpr RotateExemplar kSolidRotateExemplar = RotateExemplar::Auto;

/// Upper end of TextureOptimizationOptions::structure_sigma, in voxels.
constexpr double kMaxStructureSigma = 8.0;

/// Upper end of TextureOptimizationOptions::feature_scale, in exemplar pixels.
constexpr int kMaxFeatureScale = 64;

/// Bins per value channel of TextureOptimizationOptions::histogram_values
/// (the quality measure's hist_emd uses 32 over the 8-bit range).
constexpr int kValueBins = 32;

/// finest_iterations = -1: this many rounds at the finest level once it is
/// at least kAutoFinestFrom voxels (pixels) across.
constexpr int kAutoFinestIterations = 2;
constexpr int kAutoFinestFrom = 64;

struct TextureOptimizationOptions {
  int levels = 3;                ///< pyramid levels (coarsest first: size / 2^(levels-1))
  int neighborhood = 8;          ///< n: n x n neighbourhoods (even or odd, >= 3)
  int iterations = 3;            ///< search + optimise rounds per level (coarsest gets 2x)
  /// Rounds at the finest level (with 2 levels or more); 0 = `iterations`;
  /// -1 (solids' default, SolidOptions) = kAutoFinestIterations once the
  /// finest level is kAutoFinestFrom voxels across, else `iterations`. With
  /// 2 rounds 64^3 solids of 8 exemplars change by <= 0.02 on every quality
  /// measure and a 128^3 solid takes ~25 % less CPU, but at 24^3-32^3 the
  /// last round still adds structure (docs/solid.md, third pass). Images
  /// keep every round (0).
  int finest_iterations = 0;
  double r = 0.8;                ///< energy exponent (IRLS weights |s - e|^(r - 2))
  double pca_variance = 0.95;    ///< PCA keeps this fraction of variance ...
  int max_pca_dims = 32;         ///< ... but never more than this many dimensions
  SolidSearch search = SolidSearch::KCoherence;
  int coherence_k = 4;           ///< k-coherence: similar neighbourhoods per exemplar pixel
  int random_candidates = 2;     ///< extra random candidates per search (exploration)
  double ann_eps = 2.0;          ///< KdTree: nanoflann's eps (approximation tolerance)
  bool histogram_matching = true;
  int histogram_bins = 16;       ///< per channel
  /// Exponent p of the histogram re-weighting: a texel whose bins the output
  /// over-represents by `excess` counts (1 + excess)^-p. 1 = the gentle
  /// weighting of before; 3 (measured, docs/solid.md) keeps the exemplar's
  /// contrast: solids 0.68 -> 0.81, images 0.89 -> 0.95 over 8 exemplars.
  double histogram_strength = 3.0;
  /// Finer levels start from the coarser level's matches applied to the finer
  /// exemplar (one optimisation pass before the first search) rather than
  /// from the trilinearly upsampled texture alone, which keeps the detail.
  bool coherent_upsampling = true;
  bool mean_shift = false;       ///< mean-shift mode of the contributions instead of the mean (sharper)
  /// Final pass at the finest level: every voxel (pixel) takes the exemplar
  /// texel its best-matching window puts there instead of the optimisation's
  /// weighted mean, so the output's values are the exemplar's (crisp; see
  /// docs/solid.md). Off = the paper's averaged result.
  bool exemplar_values = true;
  /// > 0 (with exemplar_values): the exemplar-values pass matches the
  /// exemplars' histogram. Each voxel chooses among the texels its covering
  /// windows propose (every view), by match quality against a per-bin price
  /// (kValueBins bins per value channel); histogram_value_rounds rounds of
  /// choices at fixed prices (counted on a sample of the voxels) raise the
  /// prices of over-full bins by this step times their excess share and
  /// lower under-full ones (a round that comes out farther goes back to the
  /// nearest prices with half the step), and the round nearest the histogram
  /// is written (histogram_values.cpp); a changed choice that continues no neighbour's
  /// keeps the plain texel (no speckle). 0 = off: the best-matching window's
  /// texel (images' default); solids default to kSolidHistogramValues.
  double histogram_values = 0.0;
  int histogram_value_rounds = 32;  ///< pricing rounds of histogram_values (then one pass writes)
  /// beta in [0, 1]: a proposal pays beta x the mean price of its whole
  /// window's texels and (1 - beta) x its own texel's. 0 = the texel's own
  /// (each voxel on its own: speckle); towards 1 a window's voxels move
  /// together, so the choices stay coherent pieces of exemplar.
  double histogram_value_window = 0.0;
  /// sigma > 0 (with exemplar_values): the finest level's last optimisation
  /// also runs, and the output takes its low frequencies from that weighted
  /// mean and its high ones from the exemplar values, G(mean) + values -
  /// G(values) with G a Gaussian of sigma voxels (pixels), then each value
  /// channel's histogram matched to the exemplars' (solid/structure_detail.hpp):
  /// the mean has the cells and cracks where the exemplar values blur their
  /// outlines into the grain. 0 = off, the default for solids and images
  /// alike (mixed on the 8 bench exemplars: docs/solid.md, eighteenth pass).
  /// Up to kMaxStructureSigma.
  double structure_sigma = 0.0;
  /// > 0: add the feature-distance channel (signed distance to the edges of
  /// the exemplar's dark features) with this weight relative to colours in
  /// [0, 1]; it guides matching and is dropped from the output. 0 = off
  /// (images' default); solids default to kSolidFeatureWeight.
  double feature_weight = 0.0;
  /// t >= 0: the feature channel's features are the pixels darker than
  /// their window's mean by more than t x the exemplar's luminance standard
  /// deviation (0 = darker at all, the default). At 1 the features are the
  /// cracks and mortar themselves rather than half of every window, and
  /// stone33's cow shows stones outlined by a network of cracks; not the
  /// default (brick's hist_emd and every nn_rel get worse, and
  /// crackedground's cells come out as parallel sheets: docs/solid.md,
  /// thirteenth and fourteenth passes). Up to kMaxFeatureThreshold.
  double feature_threshold = 0.0;
  /// The feature channel's scale in exemplar pixels (of the working
  /// resolution): its distance saturates this far from a feature's edge,
  /// and a feature is darker than the mean of the window of this radius
  /// (with_feature_channel); 0 = the neighbourhood's edge n (the default,
  /// 8). Larger scales tell a stone's middle from its rim: crackedground's
  /// cow shows whole round stones in a dark matrix at 16 where 8 breaks
  /// them into small cells, but on other exemplars it lines features up as
  /// sheets (marble2, sky) or loses contrast (granite1), so 0 stays the
  /// default (docs/solid.md, nineteenth pass). Up to kMaxFeatureScale.
  int feature_scale = 0;
  /// On: the exemplar is used in its four quarter turns (its central
  /// square, as one mosaic): for textures with no preferred direction
  /// (cracks, cells, pebbles), whose cells otherwise line up as parallel
  /// sheets, most at feature_threshold 1; not for wood, bricks or anything
  /// that runs one way. Auto decides per exemplar (RotateExemplar). Costs
  /// 4x the exemplar analysis (docs/solid.md, fourteenth and fifteenth
  /// passes). Images' default Off; solids default to kSolidRotateExemplar.
  RotateExemplar rotate_exemplar = RotateExemplar::Off;
  bool tileable = true;          ///< toroidal boundaries, so the output tiles
  /// Working resolution: an exemplar whose longer edge exceeds this many
  /// pixels is analysed at half, quarter, ... resolution (Gaussian pyramid
  /// steps) until it fits, so its features come out that much smaller in
  /// the output. 0 = always full resolution (memory and time grow with it).
  int max_exemplar_size = kDefaultMaxExemplarSize;
  std::size_t memory_budget = kDefaultMemoryBudget;
  std::uint64_t seed = 0;
};

/// Inputs of a solid: one exemplar per view (x, y, z = the slice orthogonal
/// to that axis). Missing views reuse the first exemplar given; a view can be
/// switched off (two-view mode). All exemplars must have the same channel
/// count. Slice orientation: x-slices map exemplar (column, row) to (y, z),
/// y-slices to (x, z), z-slices to (x, y).
struct SolidExemplars {
  std::array<Image, 3> views;             ///< empty image = reuse another view's exemplar
  std::array<bool, 3> active{true, true, true};
  /// Optional constraint (§6.2): size^3 voxels, channels = C + 1 (C target
  /// values, then a weight in [0, 1]: 1 = take the target, 0 = ignore it).
  Volume constraint;
};

/// How a solid is synthesized.
enum class SolidMethod {
  /// Kopf et al. 2007: global texture optimisation of voxel values (above).
  Optimization,
  /// Dong et al. 2008 "Lazy Solid Texture Synthesis": every voxel holds
  /// exemplar coordinates (a triple of texels whose crossbars agree, one per
  /// view), synthesized coarse to fine by coordinate upsampling and
  /// correction passes among k-coherence candidates in appearance space
  /// (PCA of 5x5 neighbourhoods); colours are looked up at the end. Uses
  /// levels, iterations (correction passes at the coarsest level; one at
  /// each finer level, the finest as finest_iterations), coordinate_coherence_k, pca_variance / max_pca_dims (at most
  /// kCoordinateFeatureDims), max_exemplar_size, tileable, memory_budget and
  /// seed; the optimiser's other options (feature_weight too) do not apply.
  /// No constraint volume yet. See docs/solid.md.
  Coordinates,
};
/// Appearance-space feature window and largest feature dimension of SolidMethod::Coordinates.
constexpr int kCoordinateWindow = 5;
constexpr int kCoordinateFeatureDims = 8;

/// The method names the bindings, add-on and CLI accept, in enum order
/// ("optimization", "coordinates"), and the default's.
const std::vector<std::string>& solid_method_names();
const char* solid_method_name(SolidMethod m);
/// Parses a name of solid_method_names(); InvalidInput naming them otherwise.
SolidMethod solid_method_from_name(const std::string& name);

struct SolidOptions : TextureOptimizationOptions {
  int size = 64;  ///< output edge length in voxels (size^3)
  /// Coordinates meets more of issue 10's slice targets (20 of 32 against
  /// 9 at 64^3, sixth pass) in about the optimiser's time at 128^3, but the
  /// demo's cow (oblique cuts) shows square blocks of crisp texture with
  /// straight seams, not the exemplar's stones, so the optimiser stays the
  /// default (docs/solid.md, fourth to sixth passes).
  SolidMethod method = SolidMethod::Optimization;
  /// Coordinates: k-coherence candidates per neighbour's texel (its most
  /// similar texels). 0 = the neighbours' own texels only: measured as good
  /// as 1 and 4, and faster (64^3, crackedground / stone33 / brick; docs/solid.md).
  int coordinate_coherence_k = 0;
  SolidOptions() {
    finest_iterations = -1;
    feature_weight = kSolidFeatureWeight;        // method Coordinates ignores both
    histogram_values = kSolidHistogramValues;
    feature_threshold = kSolidFeatureThreshold;
    rotate_exemplar = kSolidRotateExemplar;
  }
};
/// The default method's name (SolidOptions{}.method).
const char* default_solid_method_name();

struct TextureResult {
  Volume texture;                      ///< the solid (size^3 x C), or the image as a (W, H, 1) volume
  std::vector<double> energy;          ///< mean energy per match after each search, all levels in order
  std::vector<int> energy_level;       ///< level of each energy entry (0 = coarsest)
  /// With exemplar_values: per voxel (x fastest) the exemplar texel taken,
  /// view * 2^28 + pixel index (row * width + column) in that view's working
  /// exemplar; -1 where the optimised value was kept. Empty otherwise.
  std::vector<std::int32_t> source;
  /// Per view, whether its exemplar was used in its quarter turns (rotate_exemplar).
  std::array<bool, 3> rotated_exemplar{};
};

TextureResult synthesize_solid(const SolidExemplars& exemplars, const SolidOptions& opt = {},
                               ExecContext* ctx = nullptr);

/// How synthesize_image makes an image.
enum class ImageMethod {
  /// Default: synthesis of exemplar coordinates (Lefebvre & Hoppe 2005,
  /// "Parallel Controllable Texture Synthesis", in the appearance space of
  /// Lefebvre & Hoppe 2006); colours are looked up at the end, so every
  /// pixel is an exemplar pixel (docs/solid.md, "2D: coordinate synthesis").
  Coordinates,
  Optimization,  ///< the texture optimiser above (Kopf et al. 2007 in 2D)
};

/// Options of ImageMethod::Coordinates (the optimiser ignores them; of the
/// shared options it uses tileable, max_exemplar_size and seed).
struct CoordinateSynthesisOptions {
  /// Randomness r of the jitter: after upsampling, each pixel's coordinate
  /// moves by round(h * r * U(-1, 1)) per axis at levels of spacing h >=
  /// jitter_from (LH05's J_l). More jitter = smaller coherent patches (less
  /// copying) but more seams (higher nn_rel); docs/solid.md has the sweep.
  /// 0.25: the least that keeps copy_rate <= 0.35 on the 8 exemplars; with
  /// the patch refinement below, 0.5 (docs/solid.md).
  double jitter = 0.25;
  int jitter_from = 8;           ///< finest spacing (power of two) that is still jittered
  int corrections = 2;           ///< correction passes per level (each of 4 sub-passes)
  /// k-coherence candidates per neighbour (1 = the coherent one only). LH05
  /// use 2; on the 8 exemplars 2 changed no measure by more than 0.01 and
  /// cost 3x the CPU (docs/solid.md), so 1.
  int coherence_k = 1;
  /// Coherence bias: a candidate that continues a neighbour's patch wins
  /// unless another's distance is smaller by the factor (1 + coherence).
  double coherence = 1.0;
  /// Levels of spacing <= this compare 5 x 5 neighbourhoods of appearance
  /// vectors instead of 3 x 3 (0 = 3 x 3 everywhere).
  int wide_below = 0;
  int appearance_window = 5;     ///< appearance vectors: PCA of this window's colours ...
  int appearance_dims = 8;       ///< ... to this many dimensions (LH06: 5 x 5 -> 8)
  /// Spacing of the coarsest level (a power of two); 0 = the largest power
  /// of two <= a third of the exemplar's shorter edge (32 for 128^2).
  int coarsest_spacing = 0;
  /// Exhaustive correction (every exemplar position is a candidate): the
  /// reference the tests compare the k-coherence search with.
  bool exhaustive = false;
  /// Patch refinement after the finest level (refine_passes rounds, 0 =
  /// none; image/patch_refinement.hpp): each output refine_patch^2 patch
  /// (corners refine_stride apart) finds its nearest exemplar patch in colour
  /// (PatchMatch: the coordinates it holds, its neighbours' matches,
  /// refine_random random probes per halving radius), then each pixel takes
  /// the coordinate, among those its patches' matches propose, that is the
  /// medoid in colour of all of them (every pixel stays an exemplar pixel).
  /// Off by default: its best setting on the 8 exemplars with copy_rate <=
  /// 0.35 and sharpness >= 0.9 on each (one round, 12 x 12, stride 4, with
  /// jitter 0.5) gains only 0.015 of nn_rel (0.298 vs 0.313) for more
  /// copying (0.31 vs 0.28) and a picture no better (brick's mortar as
  /// broken, more short bricks); more rounds, larger patches or stride 2
  /// copy more (docs/solid.md has the sweep).
  int refine_passes = 0;
  int refine_patch = 12;
  int refine_stride = 4;
  int refine_random = 1;
  /// The vote: the medoid of the proposals (true) or the proposal nearest
  /// their mean colour (false: less copying, lower nn_rel, but it favours
  /// mid-tones: lower sharpness; docs/solid.md).
  bool refine_medoid = true;
  /// Seam cuts after the finest level and the refinement (cut_passes
  /// sweeps, 0 = none; image/seam_cut.hpp): graph-cut expansion moves on
  /// cut_window^2 windows move the seams between coherent regions to where
  /// the two sources agree (Kwatra et al. 2003's seam cost), alpha over the
  /// cut_labels commonest sources of each window; cut_leave is the cost (in
  /// colour distance, the exemplar's units) a pixel pays for leaving the
  /// synthesis's coordinate, which holds the regions' growth (copying) back.
  int cut_passes = 0;
  int cut_window = 32;
  int cut_labels = 16;
  double cut_leave = 0.0;
  /// A move by source alpha reaches only pixels within cut_reach (Chebyshev)
  /// of alpha's pixels (0 = the whole window).
  int cut_reach = 4;
  /// The seam cost compares the two sources over (2 cut_radius + 1)^2
  /// pixels around each of the pair (the mean; 0 = the pair only, Kwatra's).
  int cut_radius = 0;
  /// Also try as alpha, in each window, the sources of the nearest exemplar
  /// patches (PatchMatch of the refinement: refine_patch, refine_stride,
  /// refine_random) of the output patches whose corners lie in the window.
  bool cut_matches = false;
};

struct ImageSynthesisOptions : TextureOptimizationOptions {
  int width = 128;
  int height = 128;
  ImageMethod method = ImageMethod::Coordinates;
  CoordinateSynthesisOptions coordinates;
  ImageSynthesisOptions() { tileable = false; }
};

/// The image method names (in enum order: "coordinates", "optimization"),
/// the default's, and the parse (InvalidInput naming them otherwise).
const std::vector<std::string>& image_method_names();
const char* default_image_method_name();
ImageMethod image_method_from_name(const std::string& name);

/// 2D synthesis: exemplar -> a width x height image, by `opt.method`.
Image synthesize_image(const Image& exemplar, const ImageSynthesisOptions& opt = {}, ExecContext* ctx = nullptr,
                       std::vector<double>* energy = nullptr);

}  // namespace exsynth
