#include "exsynth/analogy.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <nanoflann.hpp>

#include "exsynth/errors.hpp"
#include "exsynth/parallel.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/sample.hpp"
#include "search/pca.hpp"

namespace exsynth {
namespace {

using search::RowMatrixXf;
using Offset = std::array<int, 3>;

// Neighbourhood offsets. The causal part holds the fine cube's voxels that
// come before the centre in scanline order (z slowest, then y, then x):
// those are already synthesized when the centre is visited.
struct Neighbourhoods {
  std::vector<Offset> causal, fine, coarse;
  int dims(bool with_coarse) const { return int(causal.size() + fine.size() + (with_coarse ? 2 * coarse.size() : 0)); }
};

Neighbourhoods make_neighbourhoods(int fine, int coarse) {
  Neighbourhoods n;
  const int r = fine / 2, rc = coarse / 2;
  for (int dz = -r; dz <= r; ++dz)
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        n.fine.push_back({dx, dy, dz});
        if (dz < 0 || (dz == 0 && (dy < 0 || (dy == 0 && dx < 0)))) n.causal.push_back({dx, dy, dz});
      }
  for (int dz = -rc; dz <= rc; ++dz)
    for (int dy = -rc; dy <= rc; ++dy)
      for (int dx = -rc; dx <= rc; ++dx) n.coarse.push_back({dx, dy, dz});
  return n;
}

float clamped(const Volume& v, int x, int y, int z) {
  return v.at(std::clamp(x, 0, v.nx() - 1), std::clamp(y, 0, v.ny() - 1), std::clamp(z, 0, v.nz() - 1));
}

// One level's view of a side of the analogy: the "before" volume (A or B),
// the "after" volume (A' or B', being written for B'), and their next-coarser
// levels (empty at the coarsest).
struct Side {
  const Volume* before;
  const Volume* after;
  const Volume* before_coarse;
  const Volume* after_coarse;
};

void feature_vector(const Side& s, const Neighbourhoods& n, int x, int y, int z, float* f) {
  for (const Offset& o : n.causal) *f++ = clamped(*s.after, x + o[0], y + o[1], z + o[2]);
  for (const Offset& o : n.fine) *f++ = clamped(*s.before, x + o[0], y + o[1], z + o[2]);
  if (s.before_coarse) {
    const int cx = x / 2, cy = y / 2, cz = z / 2;  // pyramid levels keep voxel 0's centre
    for (const Offset& o : n.coarse) *f++ = clamped(*s.after_coarse, cx + o[0], cy + o[1], cz + o[2]);
    for (const Offset& o : n.coarse) *f++ = clamped(*s.before_coarse, cx + o[0], cy + o[1], cz + o[2]);
  }
}

class KdIndex {
 public:
  using Tree = nanoflann::KDTreeEigenMatrixAdaptor<RowMatrixXf, -1, nanoflann::metric_L2_Simple>;
  explicit KdIndex(const RowMatrixXf& points) : tree_(int(points.cols()), std::cref(points), 16) {
    tree_.index->buildIndex();
  }
  Eigen::Index nearest(const float* q, float eps) const {
    Eigen::Index idx = 0;
    float d2 = 0;
    nanoflann::KNNResultSet<float, Eigen::Index> result(1);
    result.init(&idx, &d2);
    tree_.index->findNeighbors(result, q, nanoflann::SearchParams(32, eps));
    return idx;
  }

 private:
  Tree tree_;
};

void check_volume(const Volume& v, const char* name) {
  if (v.empty()) throw InvalidInput(std::string(name) + " is empty; give a volume with at least one voxel");
  if (v.channels() != 1)
    throw InvalidInput(std::string(name) + " must have 1 channel (a signed distance or density), got " +
                       std::to_string(v.channels()));
  for (float x : v.values())
    if (!std::isfinite(x)) throw InvalidInput(std::string(name) + " has a non-finite value; fix the volume first");
}

}  // namespace

AnalogyResult synthesize_analogy(const Volume& a, const Volume& a_prime, const Volume& b, const AnalogyOptions& opt,
                                 ExecContext* ctx) {
  check_volume(a, "A");
  check_volume(a_prime, "A'");
  check_volume(b, "B");
  if (a.nx() != a_prime.nx() || a.ny() != a_prime.ny() || a.nz() != a_prime.nz())
    throw InvalidInput("A and A' must have the same size, got " + std::to_string(a.nx()) + "x" + std::to_string(a.ny()) +
                       "x" + std::to_string(a.nz()) + " and " + std::to_string(a_prime.nx()) + "x" +
                       std::to_string(a_prime.ny()) + "x" + std::to_string(a_prime.nz()) +
                       "; voxelize both on the same grid");
  if (opt.levels < 1 || opt.levels > 6) throw InvalidInput("levels must be between 1 and 6, got " + std::to_string(opt.levels));
  if (opt.fine_size < 3 || opt.fine_size > 9 || opt.fine_size % 2 == 0)
    throw InvalidInput("fine_size must be odd, between 3 and 9, got " + std::to_string(opt.fine_size));
  if (opt.coarse_size < 1 || opt.coarse_size > 7 || opt.coarse_size % 2 == 0)
    throw InvalidInput("coarse_size must be odd, between 1 and 7, got " + std::to_string(opt.coarse_size));
  if (opt.sweeps < 1 || opt.sweeps > 8) throw InvalidInput("sweeps must be between 1 and 8, got " + std::to_string(opt.sweeps));

  const Neighbourhoods hood = make_neighbourhoods(opt.fine_size, opt.coarse_size);
  const int L = opt.levels;
  // Peak: A's database (features + PCA coefficients) and the pyramids.
  check_memory_budget(double(a.voxel_count()) * (hood.dims(L > 1) + opt.max_pca_dims) * 4.0 * 1.2 +
                          double(a.voxel_count() * 2 + b.voxel_count() * 2) * 4.0 * 8.0 / 7.0,
                      opt.memory_budget, "the analogy on a " + std::to_string(a.nx()) + "x" + std::to_string(a.ny()) +
                                             "x" + std::to_string(a.nz()) + " exemplar",
                      "use a smaller exemplar resolution or raise the memory budget");

  PyramidOptions popt;
  popt.levels = L;
  const std::vector<Volume> pa = gaussian_pyramid(a, popt), pap = gaussian_pyramid(a_prime, popt),
                            pb = gaussian_pyramid(b, popt);

  AnalogyResult result;
  Volume bp_coarse;
  double work_total = 0, work_done = 0;
  for (const Volume& v : pb) work_total += double(v.voxel_count());
  for (int l = 0; l < L; ++l) {
    const int k = L - 1 - l;  // pyramid index
    const bool coarse = l > 0;
    const Volume& al = pa[k];
    const Volume& apl = pap[k];
    const Volume& bl = pb[k];
    const double p0 = work_done / work_total;
    work_done += double(bl.voxel_count());
    const double p1 = work_done / work_total;
    const std::string stage = "analogy: level " + std::to_string(l + 1) + "/" + std::to_string(L);

    const double cull = opt.cull_distance < 0 ? (opt.fine_size / 2) * bl.transform().voxel_size : opt.cull_distance;
    const Side a_side{&al, &apl, coarse ? &pa[k + 1] : nullptr, coarse ? &pap[k + 1] : nullptr};

    // A's database: voxels near A's surface when culling (B's searched
    // voxels are near B's surface; far voxels of A would never match).
    std::vector<std::array<int, 3>> samples;
    for (int z = 0; z < al.nz(); ++z)
      for (int y = 0; y < al.ny(); ++y)
        for (int x = 0; x < al.nx(); ++x)
          if (cull <= 0 || std::abs(al.at(x, y, z)) <= 2.0 * cull || std::abs(apl.at(x, y, z)) <= 2.0 * cull)
            samples.push_back({x, y, z});
    if (samples.empty()) throw InvalidInput("A has no voxels near its surface at level " + std::to_string(l + 1) +
                                            "; check that A is a signed distance field (or set cull_distance=0)");
    const int D = hood.dims(coarse);
    RowMatrixXf db(Eigen::Index(samples.size()), D);
    {
      StageProgress build(ctx, stage + " exemplar features", p0, p0 + 0.2 * (p1 - p0), samples.size());
      parallel_chunks(samples.size(), 1024, build, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          feature_vector(a_side, hood, samples[i][0], samples[i][1], samples[i][2], db.row(Eigen::Index(i)).data());
      });
    }
    const search::Pca pca = search::fit_pca(db, opt.pca_variance, opt.max_pca_dims);
    const RowMatrixXf coeffs = pca.project(db);
    RowMatrixXf().swap(db);
    const KdIndex index(coeffs);

    // B' starts as B at the coarsest level, as the coarser B' upsampled above.
    Volume bp = coarse ? resize_trilinear(bp_coarse, bl.nx(), bl.ny(), bl.nz()) : bl;
    bp.set_transform(bl.transform());
    const Side b_side{&bl, &bp, coarse ? &pb[k + 1] : nullptr, coarse ? &bp_coarse : nullptr};

    StageProgress synth(ctx, stage + " synthesis", p0 + 0.2 * (p1 - p0), p1,
                        std::size_t(opt.sweeps) * bl.voxel_count());
    std::vector<float> f(D);
    Eigen::RowVectorXf y(pca.dims());
    for (int sweep = 0; sweep < opt.sweeps; ++sweep)
      for (int z = 0; z < bl.nz(); ++z)
        for (int yy = 0; yy < bl.ny(); ++yy) {
          // Scanline order is causal: one row after another, no parallelism.
          synth.check();
          for (int x = 0; x < bl.nx(); ++x) {
            // Culling looks at B' as it stands (B at the coarsest level, the
            // upsampled coarser result above), so a surface a coarser level
            // moved (a dilation) keeps its new place: far voxels stay EMPTY
            // or OPAQUE by their sign.
            if (cull > 0 && std::abs(bp.at(x, yy, z)) > cull) {
              ++result.culled;
              continue;
            }
            feature_vector(b_side, hood, x, yy, z, f.data());
            y = (Eigen::Map<const Eigen::RowVectorXf>(f.data(), D) - pca.mean) * pca.basis;
            const auto& s = samples[std::size_t(index.nearest(y.data(), float(opt.ann_eps)))];
            bp.at(x, yy, z) = apl.at(s[0], s[1], s[2]);
            ++result.searched;
          }
          synth.advance(std::size_t(bl.nx()));
        }
    bp_coarse = std::move(bp);
  }
  if (ctx) ctx->set_progress(1.0);
  result.b_prime = std::move(bp_coarse);
  result.b_prime.set_transform(b.transform());
  return result;
}

}  // namespace exsynth
