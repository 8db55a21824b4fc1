#pragma once
// 3D candidates of solid synthesis by coordinates (Dong, Lefebvre, Tong &
// Drettakis 2008, "Lazy Solid Texture Synthesis", §4): a candidate is a
// triple of exemplar texels, one per view, whose crossbars agree. The three
// slices through a voxel meet pairwise in the three axis lines through it;
// each line appears in two views (the x-slice's rows run along z, its
// columns along y, and so on), so a triple is consistent when, for every
// pair of active views, the two views' lines along their shared axis hold
// the same colours. For each texel of each view the table keeps the best
// triples that contain it.
#include <array>
#include <cstdint>
#include <vector>

#include "exsynth/exec_context.hpp"
#include "solid/exemplar_index.hpp"

namespace exsynth::solid {

/// One valid-centre index per view (ExemplarIndex numbering); -1 = inactive view.
using Triple = std::array<std::int32_t, 3>;

/// Slice axes of view i: exemplar columns run along axis col_axis(i), rows
/// along row_axis(i) (x-slices: (y, z), y-slices: (x, z), z-slices: (x, y)).
inline int col_axis(int view) { return view == 0 ? 1 : 0; }
inline int row_axis(int view) { return view == 2 ? 1 : 2; }

class CrossbarCandidates {
 public:
  /// How each view's best line matches in another view are found: exact
  /// k-NN with nanoflann (default) or all pairs (the tests' reference).
  enum class Search { KdTree, BruteForce };

  /// Lines are 2 * half_length + 1 texels (clamped at the exemplar's
  /// border); `per_texel` triples are kept per texel of each view, the best
  /// of `line_k` x `line_k` combinations of line matches in the two other
  /// views. Progress over [lo, hi] of `ctx`, cancellable per chunk.
  CrossbarCandidates(const std::array<const ExemplarIndex*, 3>& views, int half_length, int per_texel, int line_k,
                     ExecContext* ctx, const std::string& stage, double lo, double hi, Search search = Search::KdTree);

  int per_texel() const { return per_texel_; }
  /// The per_texel() triples whose component `view` is valid centre j, best first.
  const Triple* of(int view, int j) const { return table_[view].data() + std::size_t(j) * per_texel_; }
  /// Crossbar disagreement of each stored triple (sum over view pairs of the
  /// squared line differences), parallel to of().
  const float* cost(int view, int j) const { return cost_[view].data() + std::size_t(j) * per_texel_; }
  /// Line through valid centre j of `view` along 3D `axis` (one of its slice
  /// axes), line_dims() values: what the crossbar costs compare.
  const float* line(int view, int axis, std::int32_t j) const {
    return lines_[view][axis].data() + std::size_t(j) * std::size_t(lines_[view][axis].cols());
  }
  int line_dims() const { return line_dims_; }

 private:
  std::array<const ExemplarIndex*, 3> views_;
  int per_texel_;
  int line_dims_ = 0;
  std::array<std::array<RowMatrixXf, 3>, 3> lines_;  // [view][axis], valid centres x line_dims
  std::array<std::vector<Triple>, 3> table_;
  std::array<std::vector<float>, 3> cost_;
};

/// Axis shared by the slices of views a and b (a != b): the third one.
inline int shared_axis(int a, int b) { return 3 - a - b; }

/// The colours along the line through valid centre j of `index`'s exemplar
/// in the direction of 3D axis `axis` (which must be one of the view's slice
/// axes), 2 * half + 1 texels, clamped at the border, into `out`.
void crossbar_line(const ExemplarIndex& index, int view, int j, int axis, int half, float* out);

}  // namespace exsynth::solid
