#include <Eigen/Geometry>

#include "points/patch_solver.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/rng.hpp"
#include "points/pairing.hpp"
#include "points/tps.hpp"

namespace exsynth::points {
namespace {

using Clock = std::chrono::steady_clock;

void check_options(const PointTextureOptions& o) {
  auto bad = [](const std::string& what) { throw InvalidInput("point texture option " + what); };
  if (!(o.patch_size > 0) || !std::isfinite(o.patch_size)) bad("patch_size must be a positive length (exemplar units)");
  if (!(o.extra > 0.05 && o.extra <= 0.5)) bad("extra (the overlap as a fraction of the patch) must be in (0.05, 0.5]");
  if (!(o.epsilon >= 0)) bad("epsilon must be >= 0");
  if (o.grid_resolution < 4 || o.grid_resolution > 64) bad("grid_resolution must be in [4, 64]");
  if (o.pairing_iterations < 1 || o.pairing_iterations > 20) bad("pairing_iterations must be in [1, 20]");
  if (o.max_pairs < 4 || o.max_pairs > 2000) bad("max_pairs must be in [4, 2000]");
  if (o.blend_iterations < 1 || o.blend_iterations > 20) bad("blend_iterations must be in [1, 20]");
  if (o.relax_iterations < 0 || o.relax_iterations > 20) bad("relax_iterations must be in [0, 20]");
  if (!(o.bandwidth >= 0.5 && o.bandwidth <= 10)) bad("bandwidth must be in [0.5, 10] point spacings");
  for (double w : {o.w_sdf, o.w_gradient, o.w_p, o.w_n, o.w_v, o.w_l, o.w_d})
    if (!(w >= 0) || !std::isfinite(w)) bad("weights (w_sdf, w_gradient, w_p, w_n, w_v, w_l, w_d) must be >= 0");
}

}  // namespace

void PatchSolver::sample_field(const PointSurface& surface, const std::vector<Eigen::Vector3f>& cells, float band,
                               std::vector<float>& f, std::vector<Eigen::Vector3f>& n,
                               const StageProgress* progress) {
  f.assign(cells.size(), band);
  n.assign(cells.size(), Eigen::Vector3f::Zero());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 256), [&](const auto& r) {
    if (progress) progress->check();
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const SurfaceSample s = surface.evaluate(cells[i]);
      if (!s.valid) continue;
      f[i] = std::clamp(s.f, -band, band);
      n[i] = s.normal;
    }
  });
}

PatchSolver::PatchSolver(const PointExemplar& exemplar, const PointTextureOptions& opt, ExecContext* ctx)
    : opt_(opt), ctx_(ctx), ex_(exemplar) {
  validate_exemplar(exemplar);
  check_options(opt);
  StageProgress progress(ctx, "exemplar field", 0.0, 0.05, 3);
  const auto& pos = exemplar.points.positions;
  const search::PointIndex index(pos);
  spacing_ = mean_spacing(pos, index, &progress);
  if (!(spacing_ > 0)) throw InvalidInput("the exemplar's points all coincide; give a point set with some extent");
  sigma_ = surface_variation(pos, index, 12, &progress);
  progress.advance();
  patch_ = opt.patch_size;
  extra_ = opt.extra * patch_;
  res_ = opt.grid_resolution;
  cell_ = patch_ / res_;
  margin_ = std::max(2.0 * cell_, 0.5 * extra_);
  band_ = 2.0 * cell_;
  h_ = opt.bandwidth * spacing_;

  if (patch_ < 2 * spacing_) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "the patch size %.3g is less than two of the exemplar's point spacings (%.3g), "
                  "so a patch would hold almost no points; give a patch size of at least %.3g", patch_, spacing_,
                  2 * spacing_);
    throw InvalidInput(buf);
  }
  Eigen::Vector3f lo = pos[0], hi = pos[0];
  for (const auto& p : pos) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  origin_ = Eigen::Vector2d(lo.x(), lo.y());
  const double cells_x = std::floor((hi.x() - lo.x()) / cell_), cells_y = std::floor((hi.y() - lo.y()) / cell_);
  const double cells_z = std::max(1.0, std::ceil((hi.z() - lo.z() + 4 * cell_) / cell_));
  if (cells_z * cells_x * cells_y * 16.0 > double(opt.memory_budget ? opt.memory_budget : kDefaultMemoryBudget))
    throw OverBudget("the exemplar's field grid (" + format_count(cells_x) + " x " + format_count(cells_y) + " x " +
                     format_count(cells_z) + " cells of the patch size / grid_resolution) would be over the memory "
                     "budget; raise the patch size or lower grid_resolution");
  gx_ = int(cells_x);
  gy_ = int(cells_y);
  z0_ = float(lo.z() - 2 * cell_);
  nz_ = int(cells_z);
  const int mc = int(std::ceil(margin_ / cell_));
  for (int j = mc; j + res_ + mc <= gy_; ++j)
    for (int i = mc; i + res_ + mc <= gx_; ++i) candidates_.push_back({i, j});
  if (candidates_.empty()) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "the patch (%.3g plus a margin of %.3g on each side) is larger than the exemplar's points "
                  "(%.3g x %.3g); lower the patch size or give a larger exemplar",
                  patch_, margin_, double(hi.x() - lo.x()), double(hi.y() - lo.y()));
    throw InvalidInput(buf);
  }

  // The exemplar's field on the whole grid, once.
  std::vector<Eigen::Vector3f> cells(std::size_t(gx_) * gy_ * nz_);
  for (int j = 0; j < gy_; ++j)
    for (int i = 0; i < gx_; ++i)
      for (int k = 0; k < nz_; ++k)
        cells[(std::size_t(j) * gx_ + i) * nz_ + k] =
            Eigen::Vector3f(float(origin_.x() + (i + 0.5) * cell_), float(origin_.y() + (j + 0.5) * cell_),
                            float(z0_ + (k + 0.5) * cell_));
  const PointSurface surface(pos, exemplar.points.normals, float(h_));
  progress.check();
  sample_field(surface, cells, float(band_), ex_f_, ex_n_, &progress);
  progress.advance();
  columns_.resize(std::size_t(gx_) * gy_);
  for (std::size_t p = 0; p < pos.size(); ++p) {
    const int i = std::clamp(int(std::floor((pos[p].x() - origin_.x()) / cell_)), 0, gx_ - 1);
    const int j = std::clamp(int(std::floor((pos[p].y() - origin_.y()) / cell_)), 0, gy_ - 1);
    columns_[std::size_t(j) * gx_ + i].push_back(std::uint32_t(p));
  }
  progress.advance();
  stats_.spacing = spacing_;
}

float PatchSolver::gather_radius() const {
  const double half = 0.5 * patch_ + margin_ + cell_;
  const double hz = std::max(std::abs(z0_), std::abs(z_max()));
  return float(std::sqrt(2 * half * half + hz * hz));
}

int PatchSolver::column(const Eigen::Vector3f& p) const {
  const int i = int(std::floor((p.x() + 0.5 * patch_) / cell_)), j = int(std::floor((p.y() + 0.5 * patch_) / cell_));
  if (i < 0 || j < 0 || i >= res_ || j >= res_) return -1;
  return j * res_ + i;
}

float PatchSolver::ramp(const Eigen::Vector3f& p) const {
  const double d = std::min(0.5 * patch_ - std::abs(p.x()), 0.5 * patch_ - std::abs(p.y()));
  return float(std::clamp(d / extra_, 0.0, 1.0));
}

std::size_t PatchSolver::choose(const std::vector<Cell>& overlap, std::uint64_t patch_id) {
  if (overlap.empty()) return std::size_t(IndexRng(opt_.seed, patch_id, 1).below(candidates_.size()));
  std::vector<double> dist(candidates_.size());
  const float wf = float(opt_.w_sdf), wg = float(opt_.w_gradient);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates_.size(), 16), [&](const auto& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) {
      const std::size_t base = (std::size_t(candidates_[c].second) * gx_ + candidates_[c].first) * nz_;
      float d = 0;
      for (const Cell& cell : overlap) {
        const float df = cell.f - ex_f_[base + cell.rel];
        d += wf * df * df + wg * (cell.n - ex_n_[base + cell.rel]).squaredNorm() * float(band_ * band_);
      }
      dist[c] = double(d) / double(overlap.size());
    }
  });
  const double best = *std::min_element(dist.begin(), dist.end());
  const double limit = best * (1.0 + opt_.epsilon) + 1e-12;
  std::vector<std::size_t> eligible;
  for (std::size_t c = 0; c < dist.size(); ++c)
    if (dist[c] <= limit) eligible.push_back(c);
  return eligible[IndexRng(opt_.seed, patch_id, 2).below(eligible.size())];
}

std::vector<LocalPoint> PatchSolver::source_points(std::size_t candidate, std::vector<float>& sigma) const {
  const auto [ci, cj] = candidates_[candidate];
  const double cx = origin_.x() + (ci + 0.5 * res_) * cell_, cy = origin_.y() + (cj + 0.5 * res_) * cell_;
  const double reach = 0.5 * patch_ + margin_;
  const int mc = int(std::ceil(margin_ / cell_));
  std::vector<LocalPoint> out;
  sigma.clear();
  for (int j = std::max(0, cj - mc); j < std::min(gy_, cj + res_ + mc); ++j)
    for (int i = std::max(0, ci - mc); i < std::min(gx_, ci + res_ + mc); ++i)
      for (std::uint32_t p : columns_[std::size_t(j) * gx_ + i]) {
        const Eigen::Vector3f& q = ex_.points.positions[p];
        const Eigen::Vector3f l(float(q.x() - cx), float(q.y() - cy), q.z());
        if (std::abs(l.x()) > reach || std::abs(l.y()) > reach) continue;
        out.push_back({l, ex_.points.normals[p]});
        sigma.push_back(sigma_[p]);
      }
  return out;
}

void PatchSolver::warp(std::vector<LocalPoint>& src, const std::vector<float>& src_sigma,
                       const std::vector<LocalPoint>& old, const std::vector<float>& old_sigma,
                       const std::vector<char>& covered) {
  std::vector<PairPoint> sources, targets;
  std::vector<std::size_t> in_overlap;
  for (std::size_t i = 0; i < src.size(); ++i) {
    const int c = column(src[i].p);
    if (c >= 0 && covered[std::size_t(c)]) in_overlap.push_back(i);
  }
  // At most one pair per metric cell survives, max_pairs in all: pairing
  // every overlap point would cost 8x more for the same warp. Keep an even
  // subset (every k-th, index order) of 4 max_pairs sources.
  const std::size_t stride = std::max<std::size_t>(1, in_overlap.size() / (4 * std::size_t(opt_.max_pairs)));
  for (std::size_t k = 0; k < in_overlap.size(); k += stride) {
    const std::size_t i = in_overlap[k];
    sources.push_back({src[i].p, src[i].n, src_sigma[i]});
  }
  for (std::size_t i = 0; i < old.size(); ++i)
    if (column(old[i].p) >= 0) targets.push_back({old[i].p, old[i].n, old_sigma[i]});
  PairingOptions po;
  po.spacing = spacing_;
  po.w_p = opt_.w_p;
  po.w_n = opt_.w_n;
  po.w_v = opt_.w_v;
  po.max_distance = opt_.max_pair_distance;
  po.min_normal_dot = opt_.min_pair_normal_dot;
  po.max_variation = opt_.max_pair_variation;
  po.w_l = opt_.w_l;
  po.w_d = opt_.w_d;
  po.iterations = opt_.pairing_iterations;
  const std::vector<PointPair> pairs = greedy_pairs(sources, targets, po);
  // One pair per metric cell (the cheapest), then the cheapest max_pairs.
  std::map<std::int64_t, PointPair> per_cell;
  for (const PointPair& pr : pairs) {
    const Eigen::Vector3f& p = sources[pr.source].p;
    const std::int64_t key = (std::int64_t(std::floor(p.z() / cell_)) * 4096 + std::int64_t(std::floor(p.y() / cell_)) + 2048) * 4096 +
                             std::int64_t(std::floor(p.x() / cell_)) + 2048;
    auto it = per_cell.find(key);
    if (it == per_cell.end() || pr.cost < it->second.cost) per_cell[key] = pr;
  }
  std::vector<PointPair> kept;
  for (const auto& [k, pr] : per_cell) kept.push_back(pr);
  std::stable_sort(kept.begin(), kept.end(), [](const PointPair& a, const PointPair& b) { return a.cost < b.cost; });
  if (kept.size() > std::size_t(opt_.max_pairs)) kept.resize(std::size_t(opt_.max_pairs));
  if (kept.size() < 4) return;
  std::vector<Eigen::Vector3d> from, to;
  for (const PointPair& pr : kept) {
    from.push_back(sources[pr.source].p.cast<double>());
    to.push_back(targets[pr.target].p.cast<double>());
  }
  // Fixed corner pairs: the spline stays the identity far from the overlap.
  const double r = 0.5 * patch_ + margin_;
  for (double z : {double(z0_), double(z_max())})
    for (double y : {-r, r})
      for (double x : {-r, r}) {
        from.emplace_back(x, y, z);
        to.emplace_back(x, y, z);
      }
  ThinPlateSpline tps;
  try {
    tps = ThinPlateSpline(from, to, opt_.tps_regularization);
  } catch (const InvalidInput&) {
    return;  // degenerate pairs: place the patch unwarped
  }
  std::vector<LocalPoint> warped(src.size());
  std::atomic<bool> wild{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, src.size(), 512), [&](const auto& rg) {
    for (std::size_t i = rg.begin(); i < rg.end(); ++i) {
      const Eigen::Vector3d x = src[i].p.cast<double>();
      Eigen::Vector3d n;
      const Eigen::Vector3d y = tps.apply(x, src[i].n.cast<double>(), n);
      if ((y - x).norm() > 0.5 * patch_) wild = true;
      warped[i] = {y.cast<float>(), n.cast<float>()};
    }
  });
  if (wild) return;  // contradictory pairs fold the spline: keep the patch as it is
  src = std::move(warped);
  stats_.pairs += kept.size();
}

namespace {

// Where the line p + s n meets `surface` nearest to p, within +-reach (the
// two rays +n and -n; used where the projection does not settle, e.g. in
// valleys between two sheets). False when neither ray crosses it.
bool two_ray_hit(const PointSurface& surface, const Eigen::Vector3f& p, const Eigen::Vector3f& n, float reach,
                 float step, Eigen::Vector3f& hit, Eigen::Vector3f& hit_n) {
  const SurfaceSample s0 = surface.evaluate(p);
  if (!s0.valid) return false;
  float prev_f[2] = {s0.f, s0.f};
  bool alive[2] = {true, true};
  for (float s = step; s <= reach; s += step)
    for (int d = 0; d < 2; ++d) {
      if (!alive[d]) continue;
      const float dir = d == 0 ? 1.0f : -1.0f;
      const SurfaceSample b = surface.evaluate(p + dir * s * n);
      if (!b.valid) {
        alive[d] = false;
        continue;
      }
      if ((prev_f[d] > 0) == (b.f > 0)) {
        prev_f[d] = b.f;
        continue;
      }
      // Linear interpolation of f between the two samples, then one more evaluation for the normal.
      const float t = prev_f[d] / (prev_f[d] - b.f);
      hit = p + dir * (s - step + t * step) * n;
      const SurfaceSample e = surface.evaluate(hit);
      hit_n = e.valid ? e.normal : n;
      return true;
    }
  return false;
}

}  // namespace

void PatchSolver::blend(std::vector<LocalPoint>& fresh, std::vector<char>& keep_new, std::vector<LocalPoint>& old,
                        std::vector<char>& old_moved, std::vector<char>& old_dead, const std::vector<char>& covered,
                        const PointSurface& old_surface) {
  std::vector<Eigen::Vector3f> fp(fresh.size()), fn(fresh.size());
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    fp[i] = fresh[i].p;
    fn[i] = fresh[i].n;
  }
  const PointSurface new_surface(fp, fn, float(h_));
  const float max_move = float(std::max(0.5 * extra_, 2.0 * h_));
  // The rays look for the other sheet only nearby: a point whose projection
  // ran off has, most often, no counterpart at all (measured: 37 % of the
  // blended chainmail points tried the rays; reaching max_move cost 10 evaluations each).
  const float ray_reach = std::min(max_move, float(3.0 * h_));
  const int iters = opt_.blend_iterations;
  std::atomic<std::size_t> fallbacks{0};
  // Moves p a total fraction w of the way to its projection on `surface`,
  // in `iters` steps (each re-projects from where the point now is). Where
  // the projection does not settle, the two rays' hit is the target of the
  // remaining steps too: the point moves along its normal toward it, so the
  // rays from there would find the same crossing (they did for ~half of the
  // 235 k pulls of the 197 k chainmail, at up to 8 evaluations a step).
  auto pull = [&](LocalPoint& pt, float w, const PointSurface& surface) {
    if (w <= 0) return;
    if (!surface.any_within(pt.p, max_move)) return;  // nothing to meet
    const float alpha = 1.0f - std::pow(1.0f - std::min(w, 0.999f), 1.0f / float(iters));
    const Eigen::Vector3f start = pt.p;
    thread_local PointSurface::Cursor cursor;  // one neighbour query for all the steps, mostly
    cursor.centre = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
    bool ray_target = false;
    Projection pr;
    for (int k = 0; k < iters; ++k) {
      if (!ray_target) pr = surface.project(pt.p, 3, float(1e-2 * h_), &cursor);
      if (!ray_target && (!pr.converged || (pr.point - start).norm() > max_move)) {
        Eigen::Vector3f hit, hit_n;
        if (!two_ray_hit(surface, pt.p, pt.n, ray_reach, float(h_), hit, hit_n)) return;
        if (k == 0) fallbacks.fetch_add(1, std::memory_order_relaxed);
        pr.point = hit;
        pr.normal = hit_n;
        ray_target = true;
      }
      if (pr.normal.dot(pt.n) < 0) return;  // the other side of a sheet: leave it
      pt.p += alpha * (pr.point - pt.p);
      pt.n = ((1 - alpha) * pt.n + alpha * pr.normal).normalized();
    }
  };
  keep_new.assign(fresh.size(), 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, fresh.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const int c = column(fresh[i].p);
      if (c < 0) {
        keep_new[i] = 0;
        continue;
      }
      if (!covered[std::size_t(c)]) continue;
      const float t = ramp(fresh[i].p);
      if (t < 0.5f) {
        keep_new[i] = 0;
        continue;
      }
      pull(fresh[i], 1.0f - t, old_surface);
    }
  });
  old_moved.assign(old.size(), 0);
  old_dead.assign(old.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, old.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      if (column(old[i].p) < 0) continue;
      const float t = ramp(old[i].p);
      if (t >= 0.5f) {
        old_dead[i] = 1;
        continue;
      }
      if (t > 0) {
        pull(old[i], t, new_surface);
        old_moved[i] = 1;
      }
    }
  });
  stats_.fallbacks += fallbacks.load();
}

void PatchSolver::place(const Chart& chart, std::uint64_t patch_id, OutputStore& out) {
  auto t0 = Clock::now();
  std::vector<std::uint32_t> ids;
  out.gather(chart.centre(), chart.scale() * gather_radius(), ids);
  std::vector<LocalPoint> old;
  std::vector<std::uint32_t> old_ids;
  const float reach = float(0.5 * patch_ + margin_ + cell_);
  for (std::uint32_t id : ids) {
    LocalPoint l;
    if (!chart.to_local(out.positions[id], out.normals[id], l)) continue;
    if (std::abs(l.p.x()) > reach || std::abs(l.p.y()) > reach) continue;
    old.push_back(l);
    old_ids.push_back(id);
  }
  std::vector<char> covered(std::size_t(res_) * res_, 0);
  for (const LocalPoint& l : old) {
    const int c = column(l.p);
    if (c >= 0) covered[std::size_t(c)] = 1;
  }
  std::vector<Eigen::Vector3f> op(old.size()), on(old.size());
  for (std::size_t i = 0; i < old.size(); ++i) {
    op[i] = old[i].p;
    on[i] = old[i].n;
  }
  const PointSurface old_surface(op, on, float(h_));
  // The output's field in the overlap, beside each cell's place in the exemplar grid.
  std::vector<Eigen::Vector3f> cells;
  std::vector<std::uint32_t> rel;
  for (int j = 0; j < res_; ++j)
    for (int i = 0; i < res_; ++i) {
      if (!covered[std::size_t(j) * res_ + i]) continue;
      for (int k = 0; k < nz_; ++k) {
        cells.emplace_back(float(-0.5 * patch_ + (i + 0.5) * cell_), float(-0.5 * patch_ + (j + 0.5) * cell_),
                           float(z0_ + (k + 0.5) * cell_));
        rel.push_back(std::uint32_t((std::size_t(j) * gx_ + i) * nz_ + k));
      }
    }
  std::vector<float> f;
  std::vector<Eigen::Vector3f> n;
  sample_field(old_surface, cells, float(band_), f, n);
  std::vector<Cell> overlap(cells.size());
  for (std::size_t c = 0; c < cells.size(); ++c) overlap[c] = {rel[c], f[c], n[c]};
  const std::size_t pick = choose(overlap, patch_id);
  t0 = lap(t0, stats_.times.search);
  if (ctx_) ctx_->check();  // a curved target's patch took up to 0.24 s (cancel latency bench)

  std::vector<float> src_sigma;
  std::vector<LocalPoint> fresh = source_points(pick, src_sigma);
  if (!old.empty()) {
    std::vector<float> old_sigma(old.size());
    for (std::size_t i = 0; i < old.size(); ++i) old_sigma[i] = out.sigma[old_ids[i]];
    warp(fresh, src_sigma, old, old_sigma, covered);
  }
  t0 = lap(t0, stats_.times.warp);
  if (ctx_) ctx_->check();

  std::vector<char> keep_new, old_moved, old_dead;
  blend(fresh, keep_new, old, old_moved, old_dead, covered, old_surface);
  for (std::size_t i = 0; i < old.size(); ++i) {
    const std::uint32_t id = old_ids[i];
    if (old_dead[i]) {
      out.alive[id] = 0;
    } else if (old_moved[i]) {
      const LocalPoint w = chart.to_world(old[i]);
      out.positions[id] = w.p;
      out.normals[id] = w.n;
    }
  }
  // Charts on curved targets project every point: map in parallel, add in order.
  std::vector<LocalPoint> world(fresh.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, fresh.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      if (keep_new[i]) world[i] = chart.to_world(fresh[i]);
  });
  for (std::size_t i = 0; i < fresh.size(); ++i)
    if (keep_new[i]) out.add(world[i].p, world[i].n, src_sigma[i]);
  ++stats_.patches;
  lap(t0, stats_.times.blend);
}

}  // namespace exsynth::points
