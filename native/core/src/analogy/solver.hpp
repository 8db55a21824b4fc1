#pragma once
// The volume analogy (Bhat et al. 2004) in stages: built once from validated
// inputs (the pyramids), then run coarse to fine. Per level: learn A's
// database (the voxels that show the change, their frames, PCA and k-d
// tree), prepare B's band (B' upsampled, frames, visit order, the static
// part of every feature), synthesize it; at the end remove debris.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "analogy/ann_index.hpp"
#include "analogy/exemplar_change.hpp"
#include "analogy/features.hpp"
#include "exsynth/analogy.hpp"
#include "search/pca.hpp"

namespace exsynth::analogy {

class AnalogySolver {
 public:
  /// Inputs already validated; they must outlive the solver.
  AnalogySolver(const Volume& a, const Volume& a_prime, const Volume* field_a, const Volume& b,
                const Volume* field_b, const AnalogyOptions& opt, ExecContext* ctx);
  AnalogyResult run();

 private:
  struct Level;     // one pyramid level's grids, band limits and progress share
  struct Database;  // what the level learns from A
  struct Band;      // the part of B' the level synthesizes
  class Visit;      // one voxel's choice of source

  Level level(int l);
  std::unique_ptr<Database> learn(const Level& lv) const;
  std::unique_ptr<Band> prepare(const Level& lv, const Database& db);
  void synthesize(const Level& lv, const Database& db, Band& band);

  const Volume &a_, &a_prime_, *field_a_, &b_, *field_b_;
  const AnalogyOptions& opt_;
  ExecContext* ctx_;
  const bool aligned_;
  const Neighbourhoods hood_;
  std::vector<Volume> pa_, pap_, pb_;  // pyramids, finest first
  Reach reach_;
  AnalogyResult result_;
  // Carried from one level to the next finer one.
  Volume bp_coarse_, phi_coarse_, has_phi_coarse_;
  // The coarser level's sources (positions in its A, per voxel of its grid;
  // NaN where it had none): the finer level starts from them, so its first
  // sweep continues the coarse copy instead of starting copies of its own.
  std::vector<Vec3> coarse_source_at_;
  double work_total_ = 0, work_done_ = 0;
};

}  // namespace exsynth::analogy
