#include "solid/crossbar_candidates.hpp"

#include <algorithm>
#include <limits>
#include <memory>
#include <utility>

#include "exsynth/parallel.hpp"
#include "search/kd_tree.hpp"

namespace exsynth::solid {
namespace {

struct Match {
  std::int32_t j;
  float d2;
};

/// Every valid centre's line along `axis`, one row each.
RowMatrixXf line_matrix(const ExemplarIndex& index, int view, int axis, int half) {
  const int dims = (2 * half + 1) * index.image().channels();
  RowMatrixXf m(index.count(), dims);
  for (int j = 0; j < index.count(); ++j) crossbar_line(index, view, j, axis, half, m.row(j).data());
  return m;
}

/// The lines of one view along one axis and how to find the closest ones:
/// in the space of their leading kLineDims principal components (exact
/// k-NN in 21 dimensions took half of a 48^3 solid's time), then ranked by
/// the full line distance.
constexpr int kLineDims = 8;

class LineSet {
 public:
  LineSet(const RowMatrixXf& lines, CrossbarCandidates::Search search)
      : lines_(lines), pca_(search::fit_pca(lines, 1.0, kLineDims)), coeffs_(pca_.project(lines)) {
    if (search == CrossbarCandidates::Search::KdTree) tree_ = std::make_unique<search::KdTree>(coeffs_);
  }
  const RowMatrixXf& lines() const { return lines_; }

  /// The k closest rows to q in PCA space, ranked by full distance.
  std::vector<Match> closest(const float* q, int k) const {
    const int count = int(lines_.rows());
    k = std::min(k, count);
    const Eigen::Map<const Eigen::RowVectorXf> query(q, lines_.cols());
    const Eigen::RowVectorXf c = (query - pca_.mean) * pca_.basis;
    std::vector<Match> out;
    if (tree_) {
      std::vector<Eigen::Index> idx(static_cast<std::size_t>(k));
      std::vector<float> d2(static_cast<std::size_t>(k));
      const std::size_t found = tree_->knn(c.data(), std::size_t(k), idx.data(), d2.data());
      for (std::size_t i = 0; i < found; ++i) out.push_back({std::int32_t(idx[i]), 0.0f});
    } else {
      std::vector<Match> all(static_cast<std::size_t>(count));
      for (int r = 0; r < count; ++r) all[std::size_t(r)] = {r, (coeffs_.row(r) - c).squaredNorm()};
      std::partial_sort(all.begin(), all.begin() + k, all.end(),
                        [](const Match& a, const Match& b) { return a.d2 < b.d2 || (a.d2 == b.d2 && a.j < b.j); });
      out.assign(all.begin(), all.begin() + k);
    }
    for (Match& m : out) m.d2 = (lines_.row(m.j) - query).squaredNorm();
    std::sort(out.begin(), out.end(), [](const Match& a, const Match& b) { return a.d2 < b.d2 || (a.d2 == b.d2 && a.j < b.j); });
    return out;
  }

 private:
  const RowMatrixXf& lines_;
  search::Pca pca_;
  RowMatrixXf coeffs_;
  std::unique_ptr<search::KdTree> tree_;
};

}  // namespace

void crossbar_line(const ExemplarIndex& index, int view, int j, int axis, int half, float* out) {
  const Image& img = index.image();
  const int c = img.channels(), u = index.centre_u(j), v = index.centre_v(j);
  const bool along_columns = axis == col_axis(view);
  for (int t = -half; t <= half; ++t) {
    const int x = along_columns ? std::clamp(u + t, 0, img.width() - 1) : u;
    const int y = along_columns ? v : std::clamp(v + t, 0, img.height() - 1);
    const float* p = img.data() + img.offset(x, y);
    std::copy(p, p + c, out + std::size_t(t + half) * c);
  }
}

CrossbarCandidates::CrossbarCandidates(const std::array<const ExemplarIndex*, 3>& views, int half_length, int per_texel,
                                       int line_k, ExecContext* ctx, const std::string& stage, double lo, double hi,
                                       Search search)
    : views_(views), per_texel_(std::max(per_texel, 1)) {
  std::size_t units = 0;
  for (const ExemplarIndex* v : views) units += v ? std::size_t(v->count()) : 0;
  StageProgress progress(ctx, stage, lo, hi, 2 * units);

  // lines[view][axis]: that view's lines along a 3D axis of its slice.
  std::array<std::array<std::unique_ptr<LineSet>, 3>, 3> lines;
  for (int i = 0; i < 3; ++i) {
    if (!views[i]) continue;
    for (int axis : {col_axis(i), row_axis(i)}) {
      lines_[i][axis] = line_matrix(*views[i], i, axis, half_length);
      lines[i][axis] = std::make_unique<LineSet>(lines_[i][axis], search);
    }
    progress.advance(std::size_t(views[i]->count()));
    progress.check();
  }
  const int dims = (2 * half_length + 1) * (views[0] ? views[0] : views[1])->image().channels();
  line_dims_ = dims;

  for (int i = 0; i < 3; ++i) {
    if (!views[i]) continue;
    std::array<int, 2> other{-1, -1};
    int n_other = 0;
    for (int k = 0; k < 3; ++k)
      if (k != i && views[k]) other[n_other++] = k;
    table_[i].assign(std::size_t(views[i]->count()) * per_texel_, Triple{-1, -1, -1});
    cost_[i].assign(std::size_t(views[i]->count()) * per_texel_, 0.0f);
    parallel_chunks(std::size_t(views[i]->count()), 256, progress, [&](std::size_t j0, std::size_t j1) {
      std::vector<float> query(static_cast<std::size_t>(dims));
      std::array<std::vector<Match>, 2> matches;
      struct Scored {
        Triple t;
        float cost;
      };
      std::vector<Scored> scored;
      for (std::size_t j = j0; j < j1; ++j) {
        for (int o = 0; o < n_other; ++o) {
          const int axis = shared_axis(i, other[o]);
          crossbar_line(*views[i], i, int(j), axis, half_length, query.data());
          matches[o] = lines[other[o]][axis]->closest(query.data(), line_k);
        }
        scored.clear();
        if (n_other == 1) {
          for (const Match& a : matches[0]) {
            Triple t{-1, -1, -1};
            t[i] = std::int32_t(j);
            t[other[0]] = a.j;
            scored.push_back({t, a.d2});
          }
        } else {
          const int k1 = other[0], k2 = other[1], axis = shared_axis(k1, k2);
          for (const Match& a : matches[0])
            for (const Match& b : matches[1]) {
              Triple t{-1, -1, -1};
              t[i] = std::int32_t(j);
              t[k1] = a.j;
              t[k2] = b.j;
              const float cross = (lines[k1][axis]->lines().row(a.j) - lines[k2][axis]->lines().row(b.j)).squaredNorm();
              scored.push_back({t, a.d2 + b.d2 + cross});
            }
        }
        // Best first; ties by the triple, so both searches agree.
        std::sort(scored.begin(), scored.end(),
                  [](const Scored& a, const Scored& b) { return a.cost < b.cost || (a.cost == b.cost && a.t < b.t); });
        for (int s = 0; s < per_texel_; ++s) {
          const Scored& pick = scored[std::min<std::size_t>(std::size_t(s), scored.size() - 1)];
          table_[i][j * per_texel_ + s] = pick.t;
          cost_[i][j * per_texel_ + s] = pick.cost;
        }
      }
    });
  }
}

}  // namespace exsynth::solid
