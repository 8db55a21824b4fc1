#pragma once
// The one seam between nanoflann 1.4 (Debian 12) and 1.5 and later (Debian
// 13: 1.7): the search parameters' type, the Eigen adaptor's index member,
// whether constructing a tree builds it, and the radius search's result type.
// Everything else the k-d trees use is the same in both.
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include <nanoflann.hpp>

namespace exsynth::search::nf {

#if NANOFLANN_VERSION >= 0x150
using SearchParams = nanoflann::SearchParameters;
/// Search parameters: (1 + eps)-approximate, results sorted or in tree order.
inline SearchParams params(float eps = 0.0f, bool sorted = true) { return SearchParams(eps, sorted); }
/// The index of a KDTreeEigenMatrixAdaptor.
template <class Adaptor>
auto& index(Adaptor& tree) { return *tree.index_; }
/// Builds a tree if its constructor did not (1.5 and later build there).
template <class Tree>
void ensure_built(Tree&) {}
#else
using SearchParams = nanoflann::SearchParams;
inline SearchParams params(float eps = 0.0f, bool sorted = true) { return SearchParams(32, eps, sorted); }
template <class Adaptor>
auto& index(Adaptor& tree) { return *tree.index; }
template <class Tree>
void ensure_built(Tree& tree) { tree.buildIndex(); }
#endif

/// A radius search's result set: every (index, squared distance) closer than
/// `radius2`, in the tree's order (never sorted), into a vector of pairs
/// whatever nanoflann's own result item type is.
template <class Index, class Distance>
class RadiusCollector {
 public:
  using DistanceType = Distance;
  using IndexType = Index;
  RadiusCollector(Distance radius2, std::vector<std::pair<Index, Distance>>& out) : radius2_(radius2), out_(out) {
    out_.clear();
  }
  void init() { out_.clear(); }
  std::size_t size() const { return out_.size(); }
  bool empty() const { return out_.empty(); }
  bool full() const { return true; }
  bool addPoint(Distance d2, Index i) {
    if (d2 < radius2_) out_.emplace_back(i, d2);
    return true;
  }
  Distance worstDist() const { return radius2_; }
  void sort() {}

 private:
  Distance radius2_;
  std::vector<std::pair<Index, Distance>>& out_;
};

/// The k nearest closer than `bound`, closest first. nanoflann 1.4's
/// KNNResultSet read such a bound from its last distance slot; 1.5 and later
/// do not, so the bounded search has its own result set (same order, same
/// ties: a new point goes after those at the same distance).
template <class Index, class Distance>
class BoundedKnn {
 public:
  using DistanceType = Distance;
  using IndexType = Index;
  BoundedKnn(std::size_t k, Index* idx, Distance* d2, Distance bound = std::numeric_limits<Distance>::max())
      : k_(k), idx_(idx), d2_(d2), bound_(bound) {}
  void init() { count_ = 0; }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  bool full() const { return count_ == k_; }
  bool addPoint(Distance d2, Index i) {
    std::size_t j = count_;
    for (; j > 0 && d2_[j - 1] > d2; --j) {
      if (j < k_) {
        d2_[j] = d2_[j - 1];
        idx_[j] = idx_[j - 1];
      }
    }
    if (j < k_) {
      d2_[j] = d2;
      idx_[j] = i;
    }
    if (count_ < k_) ++count_;
    return true;
  }
  Distance worstDist() const { return count_ < k_ ? bound_ : d2_[k_ - 1]; }
  void sort() {}

 private:
  std::size_t k_;
  Index* idx_;
  Distance* d2_;
  Distance bound_;
  std::size_t count_ = 0;
};

}  // namespace exsynth::search::nf
