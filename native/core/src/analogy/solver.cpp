#include "analogy/solver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "analogy/band.hpp"
#include "analogy/debris.hpp"
#include "analogy/local_frames.hpp"
#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/pyramid.hpp"

namespace exsynth::analogy {
namespace {

using search::RowMatrixXf;

// Progress: the pyramids, then the levels by their voxel counts, then the debris.
constexpr double kPyramidsEnd = 0.03, kLevelsEnd = 0.97;

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

}  // namespace

struct AnalogySolver::Level {
  int l = 0, k = 0, scale = 1;  // level (0 = coarsest), pyramid index, voxel scale to the finest
  bool has_coarser = false;     // a coarser level was synthesized before this one
  const Volume *al = nullptr, *apl = nullptr, *bl = nullptr;
  double p0 = 0, p1 = 0;  // this level's share of the progress bar
  std::string stage;
  double cull = 0, cull_out = 0, cull_in = 0;
  Side a_side;
  double share(double f) const { return p0 + f * (p1 - p0); }  // a fraction of this level's progress
};

struct AnalogySolver::Database {
  std::vector<std::uint32_t> a_voxels;
  std::vector<Frame> a_frames;
  int C = 0, D = 0;  // causal and all feature dimensions
  search::Pca pca;
  RowMatrixXf coeffs;
  std::unique_ptr<AnnIndex> index;  // over coeffs
  std::vector<std::int32_t> row_of;  // A voxel -> database row, -1: none
};

struct AnalogySolver::Band {
  Volume bp;
  Side b_side;
  std::vector<std::uint32_t> voxels, order;  // band voxels (by index); visit order (positions in voxels)
  std::vector<Frame> frames;
  RowMatrixXf fixed;                    // static part of every band voxel's PCA coefficients
  Eigen::MatrixXf basis_causal;
  std::vector<std::int32_t> band_of;    // B voxel -> band position, -1: none
  std::vector<std::int32_t> source;     // per band voxel: the database row it copied ...
  std::vector<Vec3> source_at;          // ... and the continuous position in A
};

AnalogySolver::AnalogySolver(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b,
                             const Volume* field_b, const AnalogyOptions& opt, ExecContext* ctx)
    : a_(a), a_prime_(a_prime), field_a_(field_a), b_(b), field_b_(field_b), opt_(opt), ctx_(ctx),
      aligned_(field_a != nullptr), hood_(make_neighbourhoods(opt.fine_size, opt.coarse_size, !aligned_)) {
  PyramidOptions popt;
  popt.levels = opt.levels;
  pa_ = gaussian_pyramid(a, popt, ctx, 0.0, 0.01);
  pap_ = gaussian_pyramid(a_prime, popt, ctx, 0.01, 0.02);
  pb_ = gaussian_pyramid(b, popt, ctx, 0.02, kPyramidsEnd);
  reach_ = pair_reach(a, a_prime);
  for (const Volume& v : pb_) work_total_ += double(v.voxel_count());
}

AnalogyResult AnalogySolver::run() {
  const int L = opt_.levels;
  for (int l = 0; l < L; ++l) {
    const Level lv = level(l);
    const std::unique_ptr<Database> db = learn(lv);
    const std::unique_ptr<Band> band = prepare(lv, *db);
    synthesize(lv, *db, *band);
    if (l + 1 < L) {
      coarse_source_at_.assign(lv.bl->voxel_count(), Vec3::Constant(std::numeric_limits<float>::quiet_NaN()));
      for (std::size_t i = 0; i < band->voxels.size(); ++i)
        if (band->source[i] >= 0) coarse_source_at_[band->voxels[i]] = band->source_at[i];
    }
    bp_coarse_ = std::move(band->bp);
  }
  result_.b_prime = std::move(bp_coarse_);
  result_.b_prime.set_transform(b_.transform());
  if (opt_.remove_debris) {
    StageProgress debris(ctx_, "analogy: debris", kLevelsEnd, 1.0, 2);
    result_.debris = analogy::remove_debris(result_.b_prime, b_, debris);
  }
  if (ctx_) ctx_->set_progress(1.0);
  return std::move(result_);
}

AnalogySolver::Level AnalogySolver::level(int l) {
  Level lv;
  lv.l = l;
  lv.k = opt_.levels - 1 - l;
  lv.scale = 1 << lv.k;
  lv.has_coarser = l > 0;
  const std::size_t k = std::size_t(lv.k);
  lv.al = &pa_[k];
  lv.apl = &pap_[k];
  lv.bl = &pb_[k];
  lv.p0 = kPyramidsEnd + (kLevelsEnd - kPyramidsEnd) * work_done_ / work_total_;
  work_done_ += double(lv.bl->voxel_count());
  lv.p1 = kPyramidsEnd + (kLevelsEnd - kPyramidsEnd) * work_done_ / work_total_;
  lv.stage = "analogy: level " + std::to_string(l + 1) + "/" + std::to_string(opt_.levels);
  // Band searched: within the fine half-width of B''s surface plus, at the
  // coarsest level, as far as the pair moves A's surface on each side (a
  // spike's height out, a pit's depth in), so that level can grow the
  // whole feature; finer levels refine the surface the coarser one made,
  // within one coarser voxel more.
  const double h = lv.bl->transform().voxel_size;
  const double half_width = (opt_.fine_size / 2) * h;
  const double grow_out = lv.has_coarser ? 2.0 * h : reach_.outward;
  const double grow_in = lv.has_coarser ? 2.0 * h : reach_.inward;
  const bool automatic = opt_.cull_distance < 0;
  lv.cull = automatic ? half_width + std::max(grow_out, grow_in) : opt_.cull_distance;
  lv.cull_out = automatic ? half_width + grow_out : opt_.cull_distance;
  lv.cull_in = automatic ? half_width + grow_in : opt_.cull_distance;
  lv.a_side = Side{lv.al, lv.apl, lv.has_coarser ? &pa_[k + 1] : nullptr, lv.has_coarser ? &pap_[k + 1] : nullptr};
  return lv;
}

// A's database: the voxels of A that show the change. Parts of A that A'
// leaves alone (the underside of a slab with spikes on top) would teach "no
// change" and, seen in their own frames, look exactly like the parts that
// do change. Kept: voxels within the fine half-width (+1) of a voxel where
// A' differs from A, and, when culling, near either surface. Tolerance: a
// tenth of a voxel for distances, 1 % of A's range for densities (whichever
// is smaller).
std::unique_ptr<AnalogySolver::Database> AnalogySolver::learn(const Level& lv) const {
  const Volume &al = *lv.al, &apl = *lv.apl;
  auto db = std::make_unique<Database>();
  const auto [lo, hi] = std::minmax_element(al.values().begin(), al.values().end());
  const float tol = std::min(0.1f * float(al.transform().voxel_size), 0.01f * (*hi - *lo));
  StageProgress change(ctx_, lv.stage + " exemplar change", lv.share(0.0), lv.share(0.02), 1);
  const std::vector<unsigned char> changed = change_mask(al, apl, tol, opt_.fine_size / 2 + 1, change);
  for (std::uint32_t i = 0; i < std::uint32_t(al.voxel_count()); ++i) {
    change.check_every(i);
    if (!changed[i] || (lv.cull > 0 && std::abs(al.data()[i]) > 2.0 * lv.cull && std::abs(apl.data()[i]) > 2.0 * lv.cull))
      continue;
    if (!opt_.a_region.empty()) {
      const Vec3 g = float(lv.scale) * voxel_position(al, i);
      if (trilinear(opt_.a_region, g.x(), g.y(), g.z()) <= 0.5f) continue;
    }
    db->a_voxels.push_back(i);
  }
  if (db->a_voxels.empty())
    throw InvalidInput("A' does not differ from A near A's surface" +
                       std::string(opt_.a_region.empty() ? "" : " inside a_region") + " at level " +
                       std::to_string(lv.l + 1) +
                       "; give a pair whose A' changes A there (and A as a signed distance field, or set "
                       "cull_distance=0)");
  const Volume no_field;
  StageProgress a_frame_progress(ctx_, lv.stage + " exemplar frames", lv.share(0.02), lv.share(0.04), db->a_voxels.size());
  db->a_frames = analogy::frames_at(al, aligned_ ? *field_a_ : no_field, lv.scale, db->a_voxels, nullptr, a_frame_progress);
  db->C = int(hood_.causal.size());
  db->D = hood_.dims(lv.has_coarser);
  RowMatrixXf features(Eigen::Index(db->a_voxels.size()), db->D);
  {
    StageProgress build(ctx_, lv.stage + " exemplar features", lv.share(0.04), lv.share(0.09), db->a_voxels.size());
    parallel_chunks(db->a_voxels.size(), 1024, build, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const Vec3 g = voxel_position(al, db->a_voxels[i]);
        float* row = features.row(Eigen::Index(i)).data();
        causal_features(lv.a_side, hood_, g, db->a_frames[i], row);
        static_features(lv.a_side, hood_, g, db->a_frames[i], row + db->C);
      }
    });
  }
  // PCA, projection and the k-d tree are single library calls: checked
  // between them (each well under 0.2 s at the sizes the budget allows).
  StageProgress indexing(ctx_, lv.stage + " exemplar index", lv.share(0.09), lv.share(0.1), 3);
  db->pca = search::fit_pca(features, opt_.pca_variance, opt_.max_pca_dims);
  indexing.check();
  indexing.advance(1);
  db->coeffs = db->pca.project(features);
  RowMatrixXf().swap(features);
  indexing.check();
  indexing.advance(1);
  db->index = std::make_unique<AnnIndex>(db->coeffs);
  indexing.check();
  indexing.advance(1);
  db->row_of.assign(al.voxel_count(), -1);
  for (std::size_t i = 0; i < db->a_voxels.size(); ++i) db->row_of[db->a_voxels[i]] = std::int32_t(i);
  return db;
}

// B' starts as B at the coarsest level, as the coarser B' upsampled above.
std::unique_ptr<AnalogySolver::Band> AnalogySolver::prepare(const Level& lv, const Database& db) {
  const Volume& bl = *lv.bl;
  auto band = std::make_unique<Band>();
  StageProgress band_progress(ctx_, lv.stage + " band", lv.share(0.1), lv.share(0.12), std::size_t(bl.nz()) + 1);
  band->bp = lv.has_coarser ? upsample(bp_coarse_, bl, band_progress) : bl;
  band->bp.set_transform(bl.transform());
  band->b_side = Side{&bl, &band->bp, lv.has_coarser ? &pb_[std::size_t(lv.k + 1)] : nullptr,
                      lv.has_coarser ? &bp_coarse_ : nullptr};
  // Culling looks at B' as it stands, so a surface a coarser level moved
  // (a dilation, a spike) keeps its new place: far voxels stay EMPTY or
  // OPAQUE by their sign.
  std::vector<std::uint32_t>& voxels = band->voxels;
  for (std::uint32_t i = 0; i < std::uint32_t(bl.voxel_count()); ++i) {
    band_progress.check_every(i);
    if (lv.cull <= 0 || (band->bp.data()[i] <= lv.cull_out && band->bp.data()[i] >= -lv.cull_in)) voxels.push_back(i);
  }
  const Volume no_field;
  StageProgress b_frame_progress(ctx_, lv.stage + " target frames", lv.share(0.12), lv.share(0.14), voxels.size());
  band->frames = analogy::frames_at(bl, aligned_ ? *field_b_ : no_field, lv.scale, voxels, nullptr, b_frame_progress);

  // Visit order: scanline (the band is sorted by index) or sweep distance.
  band->order.resize(voxels.size());
  std::iota(band->order.begin(), band->order.end(), 0u);
  if (aligned_) {
    const int iterations = lv.has_coarser ? 40 : 400;
    StageProgress start(ctx_, lv.stage + " sweep distance", lv.share(0.14), lv.share(0.14), voxels.size());
    std::vector<float> phi_start = upsample_phi(phi_coarse_, has_phi_coarse_, bl, voxels, start);
    StageProgress sweep(ctx_, lv.stage + " sweep distance", lv.share(0.14), lv.share(0.17), std::size_t(iterations) + 1);
    const std::vector<float> phi =
        analogy::sweep_distance(bl.nx(), bl.ny(), bl.nz(), voxels, band->frames, phi_start, iterations, sweep);
    band->order = analogy::sorted_by(phi, sweep);
    phi_coarse_ = Volume(bl.nx(), bl.ny(), bl.nz(), 1);
    has_phi_coarse_ = Volume(bl.nx(), bl.ny(), bl.nz(), 1);
    for (std::size_t i = 0; i < voxels.size(); ++i) {
      phi_coarse_.data()[voxels[i]] = phi[i];
      has_phi_coarse_.data()[voxels[i]] = 1.0f;
    }
  }

  // The static part of every band voxel's PCA coefficients: B and the
  // coarse level do not change while this level is synthesized, so
  // (f - mean) * basis = f_causal * basis_causal + [f_static * basis_static - mean * basis].
  const int C = db.C, D = db.D;
  band->basis_causal = db.pca.basis.topRows(C);
  const Eigen::MatrixXf basis_static = db.pca.basis.bottomRows(D - C);
  const Eigen::RowVectorXf mean_proj = db.pca.mean * db.pca.basis;
  band->fixed.resize(Eigen::Index(voxels.size()), db.pca.dims());
  {
    StageProgress prep(ctx_, lv.stage + " target features", lv.share(0.17), lv.share(0.2), voxels.size());
    parallel_chunks(voxels.size(), 1024, prep, [&](std::size_t begin, std::size_t end) {
      Eigen::RowVectorXf f(D - C);
      for (std::size_t i = begin; i < end; ++i) {
        static_features(band->b_side, hood_, voxel_position(bl, voxels[i]), band->frames[i], f.data());
        band->fixed.row(Eigen::Index(i)) = f * basis_static - mean_proj;
      }
    });
  }
  band->band_of.assign(bl.voxel_count(), -1);
  for (std::size_t i = 0; i < voxels.size(); ++i) band->band_of[voxels[i]] = std::int32_t(i);
  band->source.assign(voxels.size(), -1);
  band->source_at.resize(voxels.size());
  return band;
}

// One visit: the voxel at band position i takes its best candidate. Reads
// B' and the sources within a few voxels, writes only its own.
class AnalogySolver::Visit {
 public:
  Visit(const Level& lv, const Database& db, Band& band, const Neighbourhoods& hood, const AnalogyOptions& opt)
      : lv_(lv), db_(db), band_(band), hood_(hood), eps_(float(opt.ann_eps)),
        kappa_(float((1.0 + opt.coherence) * (1.0 + opt.coherence))),
        slack_(float(opt.coherence_slack * db.coeffs.squaredNorm() / double(db.coeffs.rows()))) {}

  void operator()(std::uint32_t i, bool growing, Scratch& sc) const {
    const Volume& bl = *lv_.bl;
    const std::uint32_t v = band_.voxels[i];
    const Vec3 g = voxel_position(bl, v);
    const Frame& f = band_.frames[i];
    causal_features(band_.b_side, hood_, g, f, sc.fc.data());
    Eigen::RowVectorXf& y = sc.y;
    y.noalias() = band_.fixed.row(Eigen::Index(i)) + sc.fc * band_.basis_causal;
    propose(g, sc);
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
      dists[c] = (db_.coeffs.row(sc.rows[c]) - y).squaredNorm();
      if (top == sc.rows.size() || sc.votes[c] > sc.votes[top] || (sc.votes[c] == sc.votes[top] && dists[c] < dists[top])) top = c;
    }
    std::int32_t best;
    Vec3 at;
    int best_votes = 0;
    if (top < sc.rows.size() && (growing || dists[top] <= slack_)) {
      best = sc.rows[top], best_votes = sc.votes[top], at = sc.sums[top] / float(sc.votes[top]);
      ++sc.ann_skipped;
    } else {
      const std::int32_t nearest = std::int32_t(db_.index->nearest(y.data(), eps_));
      const float accept = (db_.coeffs.row(nearest) - y).squaredNorm() * kappa_ + slack_;
      best = nearest;
      at = voxel_position(*lv_.al, db_.a_voxels[std::size_t(nearest)]);
      float best_d = std::numeric_limits<float>::infinity();
      for (std::size_t c = 0; c < sc.rows.size(); ++c) {
        if (dists[c] > accept || sc.votes[c] < best_votes || (sc.votes[c] == best_votes && dists[c] >= best_d)) continue;
        best = sc.rows[c], best_votes = sc.votes[c], best_d = dists[c];
        at = sc.sums[c] / float(sc.votes[c]);
      }
    }
    if (best_votes) ++sc.coherent;
    band_.bp.data()[v] = trilinear(*lv_.apl, at.x(), at.y(), at.z());
    band_.source[i] = best;
    band_.source_at[i] = at;
    ++sc.searched;
  }

 private:
  // Coherent candidates: each visited neighbour's source, moved back by the
  // neighbour's offset expressed in the source's frame, grouped by position
  // (sc.sums, sc.votes) with each group's database row (sc.rows). Among
  // those close enough to the nearest neighbour's distance, the one most
  // neighbours agree on wins (then the closer): a patch of B' keeps copying
  // one piece of A' rigidly, pattern and all, instead of drifting to
  // whichever candidate happens to be pattern-free.
  void propose(const Vec3& g, Scratch& sc) const {
    const Volume& bl = *lv_.bl;
    const int nx = bl.nx(), ny = bl.ny(), nz = bl.nz();
    sc.votes.clear();
    sc.sums.clear();
    const int x0 = int(g.x()), y0 = int(g.y()), z0 = int(g.z());
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x0 + dx, qy = y0 + dy, qz = z0 + dz;
          if ((dx | dy | dz) == 0 || qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz) continue;
          const std::int32_t q = band_.band_of[bl.voxel_index(qx, qy, qz)];
          if (q < 0 || band_.source[std::size_t(q)] < 0) continue;
          const std::int32_t s = band_.source[std::size_t(q)];
          // The offset in the neighbour's own frame: a source that is A rotated onto
          // B stays exactly so (with the centre's frame it would drift).
          const Vec3 local = band_.frames[std::size_t(q)].transpose() * Vec3(float(-dx), float(-dy), float(-dz));
          const Vec3 c = band_.source_at[std::size_t(q)] + db_.a_frames[std::size_t(s)] * local;
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
    for (std::size_t k = 0; k < sc.sums.size(); ++k) sc.rows[k] = row_near(*lv_.al, db_.row_of, sc.sums[k] / float(sc.votes[k]));
  }

  const Level& lv_;
  const Database& db_;
  Band& band_;
  const Neighbourhoods& hood_;
  const float eps_, kappa_, slack_;
};

// The growing pass and the sweeps. Where each band voxel copied from: a
// continuous position in A (a coherent continuation is not rounded, so a
// patch wrapped over a curved B does not jitter) and the database row
// nearest to it.
void AnalogySolver::synthesize(const Level& lv, const Database& db, Band& band) {
  const Volume& bl = *lv.bl;
  StageProgress ordering(ctx_, lv.stage + " visit order", lv.share(0.2), lv.share(0.2), 1);
  if (lv.has_coarser && opt_.coherence > 0)
    carry_coarse_sources(pb_[std::size_t(lv.k + 1)], coarse_source_at_, bl, band.voxels, band.frames, *lv.al,
                         db.a_frames, db.row_of, band.source, band.source_at, ordering);
  // At the coarsest level a growing pass comes first: B' = B would make
  // every causal neighbourhood pattern-free, so the first choices would all
  // be pattern-free places of A' and, along the field, stay so. Instead
  // each voxel takes the position its visited neighbours agree on, whatever
  // it looks like (the nearest neighbour only where there is none): one
  // coherent copy of A', pattern and all, that the sweeps then correct
  // where it does not fit B.
  const bool grow = !lv.has_coarser && opt_.coherence > 0;
  // The growing pass floods the band breadth-first from the first voxel in
  // sweep order (then from the first not yet reached, for each further
  // piece): every voxel but a piece's first has a visited neighbour. (The
  // sweep order itself has a local minimum wherever the field circles, and
  // every minimum would start a copy of its own.)
  std::vector<std::uint32_t> grow_order;
  if (grow) grow_order = breadth_first(bl, band.voxels, band.band_of, band.order, ordering);
  const std::array<Tiles, 8> tiles = tiles_by_colour(bl, band.voxels, band.order, kTile, ordering);
  const std::size_t passes = std::size_t(opt_.sweeps + (grow ? 1 : 0));
  result_.culled += passes * (bl.voxel_count() - band.voxels.size());
  StageProgress synth(ctx_, lv.stage + " synthesis", lv.share(0.2), lv.p1, passes * band.voxels.size());
  const Visit visit(lv, db, band, hood_, opt_);
  const int d = db.pca.dims();
  Scratch serial(db.C, d);
  if (grow) {
    for (std::size_t n = 0; n < grow_order.size(); ++n) {
      if ((n & 1023) == 0) {
        synth.check();
        if (n) synth.advance(1024);
      }
      visit(grow_order[n], true, serial);
    }
  }
  // The sweeps run tile by tile, in sweep order inside a tile. Tiles of one
  // colour (the parity of their x, y, z tile index) are a tile apart,
  // farther than any visit reads, so they run in parallel and the result
  // does not depend on the number of threads; the colours run in turn.
  tbb::enumerable_thread_specific<Scratch> scratch([&] { return Scratch(db.C, d); });
  for (int sweep = 0; sweep < opt_.sweeps; ++sweep)
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
  result_.searched += serial.searched;
  result_.coherent += serial.coherent;
  result_.ann_skipped += serial.ann_skipped;
}

}  // namespace exsynth::analogy
