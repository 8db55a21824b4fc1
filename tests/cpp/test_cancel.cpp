// Every stage of every long job can be cancelled from inside its work and
// reports progress: each job is run once to list its stages, then once per
// stage with a cancel made inside it (support/cancel.hpp), which must come
// out of that very stage as Cancelled. How soon (milliseconds) is measured
// by the benchmark (bench/bench_cancel.cpp), not here.
#include <gtest/gtest.h>

#include "exsynth/analogy.hpp"
#include "exsynth/frames.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/voxelize.hpp"
#include "support/cancel.hpp"
#include "support/shapes.hpp"
#include "support/volumes.hpp"

using namespace exsynth;
using namespace exsynth::testing;

TEST(CancelInEveryStage, Pyramid) {
  const Volume v = sphere_volume(24, 0.1, 0.7);
  expect_every_stage_cancels([&](ExecContext* ctx) { gaussian_pyramid(v, {3}, ctx); }, 1);
}

TEST(CancelInEveryStage, VolumeFrames) {
  const Volume sdf = sphere_volume(24, 2.0 / 24, 0.6);
  const TriangleMesh m = icosphere(0.6f, 2);
  std::vector<Eigen::Vector3f> vectors;
  for (const auto& p : m.vertices) vectors.push_back(Eigen::Vector3f::UnitZ().cross(p));
  expect_every_stage_cancels([&](ExecContext* ctx) { volume_frames(sdf, m.vertices, vectors, {}, ctx); }, 5);
}

TEST(CancelInEveryStage, Voxelize) {
  const TriangleMesh m = icosphere(1.0f, 2);
  VoxelizeOptions opt;
  opt.resolution = 24;
  expect_every_stage_cancels([&](ExecContext* ctx) { voxelize(m, opt, ctx); }, 2);
}

TEST(CancelInEveryStage, ExemplarPair) {
  PairOptions po;
  po.resolution = 16;
  expect_every_stage_cancels([&](ExecContext* ctx) { make_exemplar_pair(PairPreset::Spikes, po, ctx); }, 1);
}

TEST(CancelInEveryStage, IsotropicAnalogy) {
  PairOptions po;
  po.resolution = 16;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Dilate, po);
  const Volume b = sphere_volume(20, pair.a.transform().voxel_size, 0.4);
  AnalogyOptions opt;
  opt.levels = 2;
  opt.sweeps = 1;
  // pyramids, per level: change, frames, features, index, band, target frames and features,
  // visit order, synthesis; debris
  expect_every_stage_cancels([&](ExecContext* ctx) { synthesize_analogy(pair.a, pair.a_prime, b, opt, ctx); },
                             2 + 2 * 9);
}

TEST(CancelInEveryStage, FieldAlignedAnalogy) {
  PairOptions po;
  po.resolution = 24;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const Volume b = sphere_volume(28, h, 10 * h);
  const Volume field = around_z_field(b);
  AnalogyOptions opt;
  opt.levels = 2;
  opt.sweeps = 1;
  // ... and the sweep distance on each level
  expect_every_stage_cancels(
      [&](ExecContext* ctx) { synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field, opt, ctx); },
      2 + 2 * 10);
}
