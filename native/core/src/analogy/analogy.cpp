#include "exsynth/analogy.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "analogy/ann_index.hpp"
#include "analogy/band.hpp"
#include "analogy/debris.hpp"
#include "analogy/exemplar_change.hpp"
#include "analogy/features.hpp"
#include "analogy/local_frames.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/pyramid.hpp"
#include "search/pca.hpp"

namespace exsynth {
namespace {

using namespace analogy;
using search::RowMatrixXf;

void check_volume(const Volume& v, const char* name) {
  if (v.empty()) throw InvalidInput(std::string(name) + " is empty; give a volume with at least one voxel");
  if (v.channels() != 1)
    throw InvalidInput(std::string(name) + " must have 1 channel (a signed distance or density), got " +
                       std::to_string(v.channels()));
  for (float x : v.values())
    if (!std::isfinite(x)) throw InvalidInput(std::string(name) + " has a non-finite value; fix the volume first");
}

std::string size_of(const Volume& v) {
  return std::to_string(v.nx()) + "x" + std::to_string(v.ny()) + "x" + std::to_string(v.nz());
}

// A field must match its volume's grid and be a usable direction wherever
// the pattern will be synthesized: near the surface.
void check_field(const Volume& field, const Volume& sdf, const char* name, const char* volume_name) {
  if (field.channels() != 3 || field.nx() != sdf.nx() || field.ny() != sdf.ny() || field.nz() != sdf.nz())
    throw InvalidInput(std::string(name) + " must have 3 channels on " + volume_name + "'s grid (" + size_of(sdf) +
                       "), got " + size_of(field) + " with " + std::to_string(field.channels()) + " channels");
  const float near = float(2.0 * sdf.transform().voxel_size);
  std::size_t bad = 0, surface = 0;
  for (std::size_t i = 0; i < sdf.voxel_count(); ++i) {
    if (std::abs(sdf.data()[i]) > near) continue;
    ++surface;
    const float* t = field.data() + 3 * i;
    if (!std::isfinite(t[0]) || !std::isfinite(t[1]) || !std::isfinite(t[2]) ||
        t[0] * t[0] + t[1] * t[1] + t[2] * t[2] < 1e-12f)
      ++bad;
  }
  if (bad)
    throw InvalidInput(std::string(name) + " is zero or not finite at " + std::to_string(bad) + " of the " +
                       std::to_string(surface) + " voxels near " + volume_name +
                       "'s surface; give a direction at every surface point (or use a field preset)");
}

// The database row of the A voxel nearest position c (A's level grid), or
// -1 when c is off the grid or that voxel is not in the database.
std::int32_t row_near(const Volume& al, const std::vector<std::int32_t>& row_of, const Vec3& c) {
  const int x = int(std::lround(c.x())), y = int(std::lround(c.y())), z = int(std::lround(c.z()));
  if (x < 0 || y < 0 || z < 0 || x >= al.nx() || y >= al.ny() || z >= al.nz()) return -1;
  return row_of[al.voxel_index(x, y, z)];
}

// Per-thread working storage of the visits, and their counts.
struct Scratch {
  Scratch(int causal_dims, int pca_dims) : fc(causal_dims), y(pca_dims) {}
  Eigen::RowVectorXf fc, y;
  std::vector<Vec3> sums;             // per proposed position: sum of the proposals ...
  std::vector<int> votes;             // ... how many neighbours proposed it ...
  std::vector<std::int32_t> rows;     // ... its database row (-1: none) ...
  std::vector<float> dists;           // ... and its feature distance
  std::size_t searched = 0, coherent = 0, ann_skipped = 0;
  void add(const Scratch& o) {
    searched += o.searched, coherent += o.coherent, ann_skipped += o.ann_skipped;
  }
};

// Edge of the sweep tiles in voxels: more than twice the farthest a visit
// reads (the 5^3 causal cube turned in its frame, trilinear: < 5 voxels).
constexpr int kTile = 16;

using Tiles = std::vector<std::vector<std::uint32_t>>;

// The band split into tiles of edge^3 voxels, each tile's positions in
// `order`, grouped by the tile's colour (the parity of its x, y and z tile
// index: 8 colours); tiles of a colour by increasing index.
std::array<Tiles, 8> tiles_by_colour(const Volume& grid, const std::vector<std::uint32_t>& band,
                                     const std::vector<std::uint32_t>& order, int edge, const StageProgress& progress) {
  const int tx = (grid.nx() + edge - 1) / edge, ty = (grid.ny() + edge - 1) / edge;
  std::map<std::size_t, std::vector<std::uint32_t>> by_tile;
  std::size_t n = 0;
  for (const std::uint32_t i : order) {
    progress.check_every(n++);
    const Vec3 g = voxel_position(grid, band[i]);
    const std::size_t key = (std::size_t(int(g.z()) / edge) * std::size_t(ty) + std::size_t(int(g.y()) / edge)) *
                                std::size_t(tx) + std::size_t(int(g.x()) / edge);
    by_tile[key].push_back(i);
  }
  std::array<Tiles, 8> tiles;
  for (auto& [key, positions] : by_tile) {
    const std::size_t x = key % std::size_t(tx), y = key / std::size_t(tx) % std::size_t(ty),
                      z = key / (std::size_t(tx) * std::size_t(ty));
    tiles[(x & 1) | (y & 1) << 1 | (z & 1) << 2].push_back(std::move(positions));
  }
  return tiles;
}

// Each voxel of this level's band starts from its coarse parent's source
// (the parent is its index / 2): the parent copied from c in the coarse A,
// so this voxel's offset from the parent's centre, carried into A's frame,
// lands at 2 c + that offset in this level's A. Voxels whose parent had no
// source, or whose position falls off A's database, keep none.
void carry_coarse_sources(const Volume& coarse_grid, const std::vector<Vec3>& coarse_source_at, const Volume& bl,
                          const std::vector<std::uint32_t>& band, const std::vector<Frame>& b_frames, const Volume& al,
                          const std::vector<Frame>& a_frames, const std::vector<std::int32_t>& row_of,
                          std::vector<std::int32_t>& source, std::vector<Vec3>& source_at,
                          const StageProgress& progress) {
  for (std::size_t i = 0; i < band.size(); ++i) {
    progress.check_every(i);
    const Vec3 g = voxel_position(bl, band[i]);
    const int px = std::min(int(g.x()) / 2, coarse_grid.nx() - 1), py = std::min(int(g.y()) / 2, coarse_grid.ny() - 1),
              pz = std::min(int(g.z()) / 2, coarse_grid.nz() - 1);
    const Vec3 parent = coarse_source_at[coarse_grid.voxel_index(px, py, pz)];
    if (!parent.allFinite()) continue;
    const Vec3 centre = 2.0f * parent;
    const std::int32_t r0 = row_near(al, row_of, centre);
    if (r0 < 0) continue;
    const Vec3 c = centre + a_frames[std::size_t(r0)] *
                                (b_frames[i].transpose() * (g - 2.0f * Vec3(float(px), float(py), float(pz))));
    const std::int32_t r = row_near(al, row_of, c);
    if (r < 0) continue;
    source[i] = r;
    source_at[i] = c;
  }
}

// Every bad input named with its fix, before any work.
void validate(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b, const Volume* field_b,
              const AnalogyOptions& opt) {
  check_volume(a, "A");
  check_volume(a_prime, "A'");
  check_volume(b, "B");
  if (a.nx() != a_prime.nx() || a.ny() != a_prime.ny() || a.nz() != a_prime.nz())
    throw InvalidInput("A and A' must have the same size, got " + size_of(a) + " and " + size_of(a_prime) +
                       "; voxelize both on the same grid");
  using Lim = AnalogyLimits;
  auto range = [](const char* name, int v, int lo, int hi, bool odd) {
    if (v < lo || v > hi || (odd && v % 2 == 0))
      throw InvalidInput(std::string(name) + " must be " + (odd ? "odd, " : "") + "between " + std::to_string(lo) +
                         " and " + std::to_string(hi) + ", got " + std::to_string(v));
  };
  range("levels", opt.levels, 1, Lim::max_levels, false);
  range("fine_size", opt.fine_size, Lim::min_fine_size, Lim::max_fine_size, true);
  range("coarse_size", opt.coarse_size, Lim::min_coarse_size, Lim::max_coarse_size, true);
  range("sweeps", opt.sweeps, 1, Lim::max_sweeps, false);
  range("max_pca_dims", opt.max_pca_dims, 1, Lim::max_pca_dims, false);
  if (!(opt.pca_variance > 0 && opt.pca_variance <= 1))
    throw InvalidInput("pca_variance must be in (0, 1], got " + std::to_string(opt.pca_variance));
  if (!(opt.ann_eps >= 0) || !std::isfinite(opt.ann_eps))
    throw InvalidInput("ann_eps must be a finite number >= 0, got " + std::to_string(opt.ann_eps));
  if (!(opt.coherence >= 0) || !(opt.coherence_slack >= 0) || !std::isfinite(opt.coherence) ||
      !std::isfinite(opt.coherence_slack))
    throw InvalidInput("coherence and coherence_slack must be finite numbers >= 0");
  if (!std::isfinite(opt.cull_distance)) throw InvalidInput("cull_distance must be finite (< 0 = automatic, 0 = off)");
  if (b.voxel_count() >= std::size_t(std::numeric_limits<std::uint32_t>::max()) ||
      a.voxel_count() >= std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw InvalidInput("A or B has too many voxels (limit 2^31); use a lower resolution");
  if (!opt.a_region.empty() && (opt.a_region.channels() != 1 || opt.a_region.nx() != a.nx() ||
                                 opt.a_region.ny() != a.ny() || opt.a_region.nz() != a.nz()))
    throw InvalidInput("a_region must have 1 channel on A's grid (" + size_of(a) + "), got " + size_of(opt.a_region) +
                       " with " + std::to_string(opt.a_region.channels()) + " channels");
  if (field_a) {
    check_field(*field_a, a, "field_a", "A");
    check_field(*field_b, b, "field_b", "B");
  }
}

AnalogyResult run(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b,
                  const Volume* field_b, const AnalogyOptions& opt, ExecContext* ctx) {
  validate(a, a_prime, field_a, b, field_b, opt);
  const bool aligned = field_a != nullptr;

  const Neighbourhoods hood = make_neighbourhoods(opt.fine_size, opt.coarse_size, !aligned);
  const int L = opt.levels;
  // Peak: A's database (features, coefficients, frames), the pyramids, and
  // per-B-voxel bookkeeping (B', sources, static projections of the band).
  check_memory_budget(double(a.voxel_count()) * (hood.dims(L > 1) + 2.0 * opt.max_pca_dims + 9) * 4.0 * 1.2 +
                          double(a.voxel_count() * 2 + b.voxel_count() * 4) * 4.0 * 8.0 / 7.0 +
                          double(b.voxel_count()) * 4.0 * 3.0,
                      opt.memory_budget, "the analogy of a " + size_of(a) + " exemplar onto a " + size_of(b) + " volume",
                      "use a lower resolution or raise the memory budget");

  // Progress: the pyramids, then the levels by their voxel counts, then the debris.
  constexpr double kPyramidsEnd = 0.03, kLevelsEnd = 0.97;
  PyramidOptions popt;
  popt.levels = L;
  const std::vector<Volume> pa = gaussian_pyramid(a, popt, ctx, 0.0, 0.01),
                            pap = gaussian_pyramid(a_prime, popt, ctx, 0.01, 0.02),
                            pb = gaussian_pyramid(b, popt, ctx, 0.02, kPyramidsEnd);
  const Volume no_field;

  const Reach reach = pair_reach(a, a_prime);
  AnalogyResult result;
  Volume bp_coarse, phi_coarse, has_phi_coarse;
  // The coarser level's sources (positions in its A, per voxel of its grid;
  // NaN where it had none): the finer level starts from them, so its first
  // sweep continues the coarse copy instead of starting copies of its own.
  std::vector<Vec3> coarse_source_at;
  double work_total = 0, work_done = 0;
  for (const Volume& v : pb) work_total += double(v.voxel_count());
  for (int l = 0; l < L; ++l) {
    const int k = L - 1 - l;  // pyramid index
    const int scale = 1 << k;
    const bool has_coarser = l > 0;  // a coarser level was synthesized before this one
    const Volume& al = pa[std::size_t(k)];
    const Volume& apl = pap[std::size_t(k)];
    const Volume& bl = pb[std::size_t(k)];
    const double p0 = kPyramidsEnd + (kLevelsEnd - kPyramidsEnd) * work_done / work_total;
    work_done += double(bl.voxel_count());
    const double p1 = kPyramidsEnd + (kLevelsEnd - kPyramidsEnd) * work_done / work_total;
    auto share = [&](double f) { return p0 + f * (p1 - p0); };  // a fraction of this level's progress
    const std::string stage = "analogy: level " + std::to_string(l + 1) + "/" + std::to_string(L);
    // Band searched: within the fine half-width of B''s surface plus, at the
    // coarsest level, as far as the pair moves A's surface on each side (a
    // spike's height out, a pit's depth in), so that level can grow the
    // whole feature; finer levels refine the surface the coarser one made,
    // within one coarser voxel more.
    const double half_width = (opt.fine_size / 2) * bl.transform().voxel_size;
    const double grow_out = has_coarser ? 2.0 * bl.transform().voxel_size : reach.outward;
    const double grow_in = has_coarser ? 2.0 * bl.transform().voxel_size : reach.inward;
    const double cull = opt.cull_distance < 0 ? half_width + std::max(grow_out, grow_in) : opt.cull_distance;
    const double cull_out = opt.cull_distance < 0 ? half_width + grow_out : opt.cull_distance;
    const double cull_in = opt.cull_distance < 0 ? half_width + grow_in : opt.cull_distance;
    const Side a_side{&al, &apl, has_coarser ? &pa[std::size_t(k + 1)] : nullptr, has_coarser ? &pap[std::size_t(k + 1)] : nullptr};

    // ---- A's database: the voxels of A that show the change. Parts of A
    // that A' leaves alone (the underside of a slab with spikes on top) would
    // teach "no change" and, seen in their own frames, look exactly like the
    // parts that do change. Kept: voxels within the fine half-width (+1) of a
    // voxel where A' differs from A, and, when culling, near either surface.
    // Tolerance: a tenth of a voxel for distances, 1 % of A's range for
    // densities (whichever is smaller).
    const auto [lo, hi] = std::minmax_element(al.values().begin(), al.values().end());
    const float tol = std::min(0.1f * float(al.transform().voxel_size), 0.01f * (*hi - *lo));
    StageProgress change(ctx, stage + " exemplar change", share(0.0), share(0.02), 1);
    const std::vector<unsigned char> changed = change_mask(al, apl, tol, opt.fine_size / 2 + 1, change);
    std::vector<std::uint32_t> a_voxels;
    for (std::uint32_t i = 0; i < std::uint32_t(al.voxel_count()); ++i) {
      change.check_every(i);
      if (!changed[i] || (cull > 0 && std::abs(al.data()[i]) > 2.0 * cull && std::abs(apl.data()[i]) > 2.0 * cull))
        continue;
      if (!opt.a_region.empty()) {
        const Vec3 g = float(scale) * voxel_position(al, i);
        if (trilinear(opt.a_region, g.x(), g.y(), g.z()) <= 0.5f) continue;
      }
      a_voxels.push_back(i);
    }
    if (a_voxels.empty())
      throw InvalidInput("A' does not differ from A near A's surface" +
                         std::string(opt.a_region.empty() ? "" : " inside a_region") + " at level " +
                         std::to_string(l + 1) +
                         "; give a pair whose A' changes A there (and A as a signed distance field, or set "
                         "cull_distance=0)");
    StageProgress a_frame_progress(ctx, stage + " exemplar frames", share(0.02), share(0.04), a_voxels.size());
    const std::vector<Frame> a_frames =
        analogy::frames_at(al, aligned ? *field_a : no_field, scale, a_voxels, nullptr, a_frame_progress);
    const int C = int(hood.causal.size()), D = hood.dims(has_coarser);
    RowMatrixXf db(Eigen::Index(a_voxels.size()), D);
    {
      StageProgress build(ctx, stage + " exemplar features", share(0.04), share(0.09), a_voxels.size());
      parallel_chunks(a_voxels.size(), 1024, build, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const Vec3 g = voxel_position(al, a_voxels[i]);
          float* row = db.row(Eigen::Index(i)).data();
          causal_features(a_side, hood, g, a_frames[i], row);
          static_features(a_side, hood, g, a_frames[i], row + C);
        }
      });
    }
    // PCA, projection and the k-d tree are single library calls: checked
    // between them (each well under 0.2 s at the sizes the budget allows).
    StageProgress indexing(ctx, stage + " exemplar index", share(0.09), share(0.1), 3);
    const search::Pca pca = search::fit_pca(db, opt.pca_variance, opt.max_pca_dims);
    indexing.check();
    indexing.advance(1);
    const RowMatrixXf coeffs = pca.project(db);
    RowMatrixXf().swap(db);
    indexing.check();
    indexing.advance(1);
    const analogy::AnnIndex index(coeffs);
    indexing.check();
    indexing.advance(1);
    std::vector<std::int32_t> row_of(al.voxel_count(), -1);
    for (std::size_t i = 0; i < a_voxels.size(); ++i) row_of[a_voxels[i]] = std::int32_t(i);

    // ---- B' starts as B at the coarsest level, as the coarser B' upsampled above.
    StageProgress band_progress(ctx, stage + " band", share(0.1), share(0.12), std::size_t(bl.nz()) + 1);
    Volume bp = has_coarser ? upsample(bp_coarse, bl, band_progress) : bl;
    bp.set_transform(bl.transform());
    const Side b_side{&bl, &bp, has_coarser ? &pb[std::size_t(k + 1)] : nullptr, has_coarser ? &bp_coarse : nullptr};
    // Culling looks at B' as it stands, so a surface a coarser level moved
    // (a dilation, a spike) keeps its new place: far voxels stay EMPTY or
    // OPAQUE by their sign.
    std::vector<std::uint32_t> band;
    for (std::uint32_t i = 0; i < std::uint32_t(bl.voxel_count()); ++i) {
      band_progress.check_every(i);
      if (cull <= 0 || (bp.data()[i] <= cull_out && bp.data()[i] >= -cull_in)) band.push_back(i);
    }
    StageProgress b_frame_progress(ctx, stage + " target frames", share(0.12), share(0.14), band.size());
    const std::vector<Frame> b_frames =
        analogy::frames_at(bl, aligned ? *field_b : no_field, scale, band, nullptr, b_frame_progress);

    // Visit order: scanline (the band is sorted by index) or sweep distance.
    std::vector<std::uint32_t> order(band.size());
    std::iota(order.begin(), order.end(), 0u);
    if (aligned) {
      const int iterations = has_coarser ? 40 : 400;
      StageProgress start(ctx, stage + " sweep distance", share(0.14), share(0.14), band.size());
      std::vector<float> phi_start = upsample_phi(phi_coarse, has_phi_coarse, bl, band, start);
      StageProgress sweep(ctx, stage + " sweep distance", share(0.14), share(0.17), std::size_t(iterations) + 1);
      const std::vector<float> phi =
          analogy::sweep_distance(bl.nx(), bl.ny(), bl.nz(), band, b_frames, std::move(phi_start), iterations, sweep);
      order = analogy::sorted_by(phi, sweep);
      phi_coarse = Volume(bl.nx(), bl.ny(), bl.nz(), 1);
      has_phi_coarse = Volume(bl.nx(), bl.ny(), bl.nz(), 1);
      for (std::size_t i = 0; i < band.size(); ++i) {
        phi_coarse.data()[band[i]] = phi[i];
        has_phi_coarse.data()[band[i]] = 1.0f;
      }
    }

    // ---- The static part of every band voxel's PCA coefficients: B and the
    // coarse level do not change while this level is synthesized, so
    // (f - mean) * basis = f_causal * basis_causal + [f_static * basis_static - mean * basis].
    const int d = pca.dims();
    const Eigen::MatrixXf basis_causal = pca.basis.topRows(C);
    const Eigen::MatrixXf basis_static = pca.basis.bottomRows(D - C);
    const Eigen::RowVectorXf mean_proj = pca.mean * pca.basis;
    RowMatrixXf fixed(Eigen::Index(band.size()), d);
    {
      StageProgress prep(ctx, stage + " target features", share(0.17), share(0.2), band.size());
      parallel_chunks(band.size(), 1024, prep, [&](std::size_t begin, std::size_t end) {
        Eigen::RowVectorXf f(D - C);
        for (std::size_t i = begin; i < end; ++i) {
          static_features(b_side, hood, voxel_position(bl, band[i]), b_frames[i], f.data());
          fixed.row(Eigen::Index(i)) = f * basis_static - mean_proj;
        }
      });
    }

    // ---- The growing pass and the sweeps.
    // Where each band voxel copied from: a continuous position in A (a
    // coherent continuation is not rounded, so a patch wrapped over a curved
    // B does not jitter) and the database row nearest to it.
    std::vector<std::int32_t> band_of(bl.voxel_count(), -1);
    for (std::size_t i = 0; i < band.size(); ++i) band_of[band[i]] = std::int32_t(i);
    std::vector<std::int32_t> source(band.size(), -1);
    std::vector<Vec3> source_at(band.size());
    const int nx = bl.nx(), ny = bl.ny(), nz = bl.nz();
    StageProgress ordering(ctx, stage + " visit order", share(0.2), share(0.2), 1);
    if (has_coarser && opt.coherence > 0)
      carry_coarse_sources(pb[std::size_t(k + 1)], coarse_source_at, bl, band, b_frames, al, a_frames, row_of, source,
                           source_at, ordering);
    const float kappa = float((1.0 + opt.coherence) * (1.0 + opt.coherence));
    const float slack = float(opt.coherence_slack * coeffs.squaredNorm() / double(coeffs.rows()));
    // At the coarsest level a growing pass comes first: B' = B
    // would make every causal neighbourhood pattern-free, so the first
    // choices would all be pattern-free places of A' and, along the field,
    // stay so. Instead each voxel takes the position its visited neighbours
    // agree on, whatever it looks like (the nearest neighbour only where
    // there is none): one coherent copy of A', pattern and all, that the
    // sweeps then correct where it does not fit B.
    const bool grow = !has_coarser && opt.coherence > 0;
    // The growing pass floods the band breadth-first from the first voxel
    // in sweep order (then from the first not yet reached, for each further
    // piece): every voxel but a piece's first has a visited neighbour. (The
    // sweep order itself has a local minimum wherever the field circles, and
    // every minimum would start a copy of its own.)
    std::vector<std::uint32_t> grow_order;
    if (grow) grow_order = breadth_first(bl, band, band_of, order, ordering);
    const std::array<Tiles, 8> tiles = tiles_by_colour(bl, band, order, kTile, ordering);
    const std::size_t passes = std::size_t(opt.sweeps + (grow ? 1 : 0));
    result.culled += passes * (bl.voxel_count() - band.size());
    StageProgress synth(ctx, stage + " synthesis", share(0.2), p1, passes * band.size());
    // One visit: the voxel at band position i takes its best candidate.
    // Reads B' and the sources within a few voxels, writes only its own.
    const auto visit = [&](std::uint32_t i, bool growing, Scratch& sc) {
      const std::uint32_t v = band[i];
      const Vec3 g = voxel_position(bl, v);
      const Frame& f = b_frames[i];
      causal_features(b_side, hood, g, f, sc.fc.data());
      Eigen::RowVectorXf& y = sc.y;
      y.noalias() = fixed.row(Eigen::Index(i)) + sc.fc * basis_causal;

      // Coherent candidates: each visited neighbour's source, moved back
      // by the neighbour's offset expressed in the source's frame. Among
      // those close enough to the nearest neighbour's distance, the one
      // most neighbours agree on wins (then the closer): a patch of B'
      // keeps copying one piece of A' rigidly, pattern and all, instead of
      // drifting to whichever candidate happens to be pattern-free.
      sc.votes.clear();
      sc.sums.clear();
      const int x0 = int(g.x()), y0 = int(g.y()), z0 = int(g.z());
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x0 + dx, qy = y0 + dy, qz = z0 + dz;
            if ((dx | dy | dz) == 0 || qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz) continue;
            const std::int32_t q = band_of[bl.voxel_index(qx, qy, qz)];
            if (q < 0 || source[std::size_t(q)] < 0) continue;
            const std::int32_t s = source[std::size_t(q)];
            // The offset in the neighbour's own frame: a source that is A rotated onto
            // B stays exactly so (with the centre's frame it would drift).
            const Vec3 local = b_frames[std::size_t(q)].transpose() * Vec3(float(-dx), float(-dy), float(-dz));
            const Vec3 c = source_at[std::size_t(q)] + a_frames[std::size_t(s)] * local;
            // Neighbours of one patch propose (nearly) the same position:
            // they vote together even when rounding would split them.
            std::size_t k = 0;
            while (k < sc.sums.size() && (sc.sums[k] / float(sc.votes[k]) - c).squaredNorm() > 0.5f) ++k;
            if (k < sc.sums.size()) {
              ++sc.votes[k];
              sc.sums[k] += c;
            } else {
              sc.votes.push_back(1);
              sc.sums.push_back(c);
            }
          }
      // Each proposal's database row: the A voxel nearest its mean position.
      sc.rows.resize(sc.sums.size());
      for (std::size_t k = 0; k < sc.sums.size(); ++k) sc.rows[k] = row_near(al, row_of, sc.sums[k] / float(sc.votes[k]));
      // The candidate most neighbours agree on (then the closest). If it is
      // within the slack, the rule below would take it whatever the
      // nearest neighbour's distance (>= 0): skip the k-d tree query.
      std::vector<float>& dists = sc.dists;
      dists.resize(sc.rows.size());
      std::size_t top = sc.rows.size();
      for (std::size_t c = 0; c < sc.rows.size(); ++c) {
        if (sc.rows[c] < 0) {  // off A's database: no candidate
          dists[c] = std::numeric_limits<float>::infinity();
          continue;
        }
        dists[c] = (coeffs.row(sc.rows[c]) - y).squaredNorm();
        if (top == sc.rows.size() || sc.votes[c] > sc.votes[top] || (sc.votes[c] == sc.votes[top] && dists[c] < dists[top])) top = c;
      }
      std::int32_t best;
      Vec3 at;
      int best_votes = 0;
      if (top < sc.rows.size() && (growing || dists[top] <= slack)) {
        best = sc.rows[top], best_votes = sc.votes[top], at = sc.sums[top] / float(sc.votes[top]);
        ++sc.ann_skipped;
      } else {
        const std::int32_t nearest = std::int32_t(index.nearest(y.data(), float(opt.ann_eps)));
        const float accept = (coeffs.row(nearest) - y).squaredNorm() * kappa + slack;
        best = nearest;
        at = voxel_position(al, a_voxels[std::size_t(nearest)]);
        float best_d = std::numeric_limits<float>::infinity();
        for (std::size_t c = 0; c < sc.rows.size(); ++c) {
          if (dists[c] > accept || sc.votes[c] < best_votes || (sc.votes[c] == best_votes && dists[c] >= best_d)) continue;
          best = sc.rows[c], best_votes = sc.votes[c], best_d = dists[c];
          at = sc.sums[c] / float(sc.votes[c]);
        }
      }
      if (best_votes) ++sc.coherent;
      bp.data()[v] = trilinear(apl, at.x(), at.y(), at.z());
      source[i] = best;
      source_at[i] = at;
      ++sc.searched;
    };
    Scratch serial(C, d);
    if (grow) {
      for (std::size_t n = 0; n < grow_order.size(); ++n) {
        if ((n & 1023) == 0) {
          synth.check();
          if (n) synth.advance(1024);
        }
        visit(grow_order[n], true, serial);
      }
    }
    // The sweeps run tile by tile, in sweep order inside a tile. Tiles of
    // one colour (the parity of their x, y, z tile index) are a tile apart,
    // farther than any visit reads, so they run in parallel and the result
    // does not depend on the number of threads; the colours run in turn.
    tbb::enumerable_thread_specific<Scratch> scratch([&] { return Scratch(C, d); });
    for (int sweep = 0; sweep < opt.sweeps; ++sweep)
      for (const Tiles& colour : tiles) {
        synth.check();
        tbb::parallel_for(std::size_t(0), colour.size(), [&](std::size_t t) {
          synth.check();
          Scratch& sc = scratch.local();
          for (const std::uint32_t i : colour[t]) visit(i, false, sc);
          synth.advance(colour[t].size());
        });
      }
    for (const Scratch& sc : scratch) serial.add(sc);
    result.searched += serial.searched;
    result.coherent += serial.coherent;
    result.ann_skipped += serial.ann_skipped;
    if (l + 1 < L) {
      coarse_source_at.assign(bl.voxel_count(), Vec3::Constant(std::numeric_limits<float>::quiet_NaN()));
      for (std::size_t i = 0; i < band.size(); ++i)
        if (source[i] >= 0) coarse_source_at[band[i]] = source_at[i];
    }
    bp_coarse = std::move(bp);
  }
  result.b_prime = std::move(bp_coarse);
  result.b_prime.set_transform(b.transform());
  if (opt.remove_debris) {
    StageProgress debris(ctx, "analogy: debris", kLevelsEnd, 1.0, 2);
    result.debris = analogy::remove_debris(result.b_prime, b, debris);
  }
  if (ctx) ctx->set_progress(1.0);
  return result;
}

}  // namespace

AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& b, const AnalogyOptions& opt,
                                 ExecContext* ctx) {
  return run(a, a_prime, nullptr, b, nullptr, opt, ctx);
}

AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& field_a, const Volume& b,
                                 const Volume& field_b, const AnalogyOptions& opt, ExecContext* ctx) {
  return run(a, a_prime, &field_a, b, &field_b, opt, ctx);
}

}  // namespace exsynth
