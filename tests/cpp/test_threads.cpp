// Determinism with more threads than cores: every long job gives the same
// output on 1 and on 8 TBB threads (the machine has 2 cores), so no result
// depends on how the work was split or scheduled. The 1-vs-2 thread tests
// live beside each algorithm's own tests.
#include <gtest/gtest.h>

#include "exsynth/analogy.hpp"
#include "exsynth/bake.hpp"
#include "exsynth/field.hpp"
#include "exsynth/frames.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/rng.hpp"
#include "exsynth/solid.hpp"
#include "exsynth/voxelize.hpp"
#include "support/load_obj.hpp"
#include "support/shapes.hpp"
#include "support/textures.hpp"
#include "support/threads.hpp"
#include "support/volumes.hpp"

using namespace exsynth;
using namespace exsynth::testing;

namespace {

constexpr int kMany = 8;

template <class F>
void expect_same_on_1_and_8_threads(F&& job) {
  const auto one = on_threads(1, job);
  const auto many = on_threads(kMany, job);
  EXPECT_TRUE(one == many);
}

}  // namespace

TEST(EightThreads, TheArenaReallyRunsEightThreads) {
  EXPECT_EQ(on_threads(kMany, [] { return tbb::this_task_arena::max_concurrency(); }), kMany);
}

TEST(EightThreads, Voxelize) {
  const TriangleMesh m = load_obj(asset("meshes/cow.obj"));
  VoxelizeOptions opt;
  opt.resolution = 40;
  expect_same_on_1_and_8_threads([&] {
    const VoxelizeResult r = voxelize(m, opt);
    return std::make_pair(r.density.values(), r.sdf.values());
  });
}

TEST(EightThreads, SolidAndImage) {
  SolidExemplars ex;
  ex.views[0] = disc_texture(32, 32, 3, 10);
  SolidOptions opt;
  opt.size = 24;
  opt.levels = 2;
  opt.seed = 5;
  expect_same_on_1_and_8_threads([&] { return synthesize_solid(ex, opt).texture.values(); });
  ImageSynthesisOptions io;
  io.method = ImageMethod::Optimization;  // these tests are the optimiser's
  io.width = io.height = 40;
  io.levels = 2;
  io.seed = 3;
  expect_same_on_1_and_8_threads([&] { return synthesize_image(ex.views[0], io).values(); });
  ImageSynthesisOptions co;  // the coordinate method (the default)
  co.width = co.height = 40;
  co.seed = 3;
  expect_same_on_1_and_8_threads([&] { return synthesize_image(ex.views[0], co).values(); });
}

TEST(EightThreads, DiffusedField) {
  // 26k vertices: the multigrid path, whose matrix products run in parallel.
  const TriangleMesh m = load_obj(asset("meshes/armadillo.obj"));
  std::vector<Eigen::Vector3f> given(m.vertices.size(), Eigen::Vector3f::Zero());
  for (int k = 0; k < 20; ++k) {
    IndexRng r(4, std::uint64_t(k));
    given[std::size_t(r.uniform() * double(m.vertices.size()))] =
        Eigen::Vector3f(float(r.uniform() - 0.5), float(r.uniform() - 0.5), float(r.uniform() - 0.5));
  }
  expect_same_on_1_and_8_threads([&] { return diffuse_direction_field(m, given); });
}

TEST(EightThreads, VolumeFramesAndPyramid) {
  const Volume sdf = sphere_volume(24, 2.0 / 24, 0.6);
  const TriangleMesh m = icosphere(0.6f, 3);
  std::vector<Eigen::Vector3f> vectors;
  for (const auto& p : m.vertices) vectors.push_back(Eigen::Vector3f::UnitZ().cross(p));
  expect_same_on_1_and_8_threads([&] {
    const VolumeFrames f = volume_frames(sdf, m.vertices, vectors);
    return std::make_pair(f.t.values(), f.b.values());
  });
  expect_same_on_1_and_8_threads([&] {
    std::vector<std::vector<float>> levels;
    for (const Volume& v : gaussian_pyramid(sdf, {4, Boundary::Wrap})) levels.push_back(v.values());
    return levels;
  });
}

TEST(EightThreads, PairAndFieldAlignedAnalogy) {
  PairOptions po;
  po.resolution = 32;
  po.jitter = 0.2;
  po.seed = 9;
  expect_same_on_1_and_8_threads([&] { return make_exemplar_pair(PairPreset::Spikes, po).a_prime.values(); });
  po.jitter = 0;
  const ExemplarPair pair = make_exemplar_pair(PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const Volume b = sphere_volume(40, h, 14 * h);
  const Volume field = around_z_field(b);
  expect_same_on_1_and_8_threads([&] {
    const AnalogyResult r = synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, field);
    return std::make_tuple(r.b_prime.values(), r.searched, r.coherent, r.debris);
  });
}

TEST(EightThreads, Bake) {
  const Volume vol = sphere_volume(16, 0.1, 0.5);
  std::vector<std::array<Eigen::Vector3f, 3>> pos;
  std::vector<std::array<Eigen::Vector2f, 3>> uv;
  const TriangleMesh m = icosphere(0.7f, 2);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    std::array<Eigen::Vector3f, 3> p;
    std::array<Eigen::Vector2f, 3> t;
    for (int k = 0; k < 3; ++k) {
      p[k] = m.vertices[std::size_t(m.faces[f][k])];
      t[k] = Eigen::Vector2f(0.5f + 0.45f * p[k].x(), 0.5f + 0.45f * p[k].y());
    }
    pos.push_back(p);
    uv.push_back(t);
  }
  BakeOptions opt;
  opt.width = opt.height = 64;
  expect_same_on_1_and_8_threads([&] {
    const BakeResult r = bake_volume_to_uv(vol, pos, uv, opt);
    return std::make_pair(r.image.values(), r.mask);
  });
}
