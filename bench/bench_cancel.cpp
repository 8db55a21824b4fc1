// Cancel latency per stage of the voxelizer, the analogy, the solid and 2D
// synthesis (the method: cancel_latency.hpp).
#include <benchmark/benchmark.h>

#include <cmath>

#include "../tests/cpp/support/load_obj.hpp"
#include "../tests/cpp/support/textures.hpp"
#include "cancel_latency.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/field.hpp"
#include "exsynth/frames.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/pyramid.hpp"
#include "exsynth/solid.hpp"
#include "exsynth/voxelize.hpp"

namespace {

using exsynth_bench::report;

exsynth::TriangleMesh bunny_scaled(float longest) {
  exsynth::TriangleMesh bunny = exsynth::testing::load_obj(exsynth::testing::asset("meshes/bunny.obj"));
  Eigen::Vector3f lo = bunny.vertices[0], hi = lo;
  for (const auto& v : bunny.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const float scale = longest / (hi - lo).maxCoeff();
  for (auto& v : bunny.vertices) v *= scale;
  return bunny;
}

// The analogy benchmark's job (bunny with spikes around its vertical axis)
// at `res` voxels: frames, then the field-aligned analogy.
void BM_CancelLatencyAnalogy(benchmark::State& state) {
  const int res = int(state.range(0));
  exsynth::PairOptions po;
  po.resolution = res / 2;
  const exsynth::ExemplarPair pair = exsynth::make_exemplar_pair(exsynth::PairPreset::Spikes, po);
  const double h = pair.a.transform().voxel_size;
  const exsynth::TriangleMesh bunny = bunny_scaled(float(res * h));
  exsynth::VoxelizeOptions vo;
  vo.resolution = res;
  vo.padding = int(std::ceil(0.3 / h)) + 4;
  const exsynth::Volume b = exsynth::voxelize(bunny, vo).sdf;
  const auto field = exsynth::preset_direction_field(bunny, exsynth::FieldPreset::AroundAxis, Eigen::Vector3f::UnitY());
  report(state, "analogy", [&](exsynth::ExecContext* ctx) {
    const exsynth::VolumeFrames frames = exsynth::volume_frames(b, bunny.vertices, field, {}, ctx);
    exsynth::synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, frames.t, {}, ctx);
  });
}
BENCHMARK(BM_CancelLatencyAnalogy)->Arg(160)->ArgName("res")->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_CancelLatencyVoxelizePyramid(benchmark::State& state) {
  const int res = int(state.range(0));
  const exsynth::TriangleMesh bunny = bunny_scaled(1.0f);
  exsynth::VoxelizeOptions vo;
  vo.resolution = res;
  report(state, "voxelize + pyramid", [&](exsynth::ExecContext* ctx) {
    const exsynth::VoxelizeResult r = exsynth::voxelize(bunny, vo, ctx);
    exsynth::gaussian_pyramid(r.sdf, {4}, ctx);
  });
}
BENCHMARK(BM_CancelLatencyVoxelizePyramid)->Arg(384)->ArgName("res")->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

namespace {

// Solid texture synthesis, 64^3 RGB from a 128^2 exemplar, default options
// (exemplar analysis, levels, the exemplar-values pass).
// Arg 1 is the method: 0 the optimiser, 1 exemplar coordinates.
void BM_CancelLatencySolid(benchmark::State& state) {
  exsynth::SolidExemplars ex;
  ex.views[0] = exsynth::testing::disc_texture(128, 128, 3, 7, 60, 6.0f);
  exsynth::SolidOptions opt;
  opt.size = int(state.range(0));
  opt.method = state.range(1) ? exsynth::SolidMethod::Coordinates : exsynth::SolidMethod::Optimization;
  report(state, "solid", [&](exsynth::ExecContext* ctx) { exsynth::synthesize_solid(ex, opt, ctx); });
}
BENCHMARK(BM_CancelLatencySolid)->Args({64, 0})->Args({64, 1})->ArgNames({"size", "coordinates"})
    ->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// 2D synthesis from a 1024^2 exemplar (a photo's size): the working
// resolution's pyramid, the exemplar analysis, the levels.
// Arg 1 is the method: 0 the optimiser, 1 exemplar coordinates (the default).
void BM_CancelLatencyImage(benchmark::State& state) {
  const exsynth::Image ex = exsynth::testing::disc_texture(int(state.range(0)), int(state.range(0)), 3, 5, 900, 24.0f);
  exsynth::ImageSynthesisOptions opt;
  opt.method = state.range(1) ? exsynth::ImageMethod::Coordinates : exsynth::ImageMethod::Optimization;
  opt.width = opt.height = 256;
  report(state, "image", [&](exsynth::ExecContext* ctx) { exsynth::synthesize_image(ex, opt, ctx); });
}
BENCHMARK(BM_CancelLatencyImage)->Args({1024, 0})->Args({1024, 1})->ArgNames({"exemplar", "coordinates"})
    ->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
