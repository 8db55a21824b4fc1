// Geometric texture by analogy (issue 4's target): the bundled bunny at
// about 158x200x197 voxels (200 on its longest axis) with grooves and with
// spikes following a field of circles around its vertical axis, the pair at
// half the bunny's size (100^3). Timed: frames + synthesis (the voxelizer
// has its own benchmark). Target <= 60 s on 2 cores.
#include <benchmark/benchmark.h>

#include <cmath>

#include "../tests/cpp/support/load_obj.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/field.hpp"
#include "exsynth/frames.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/voxelize.hpp"

namespace {

void BM_AnalogyBunny(benchmark::State& state) {
  const auto preset = exsynth::PairPreset(state.range(0));
  const int res = int(state.range(1));
  exsynth::PairOptions po;
  po.resolution = res / 2;
  const exsynth::ExemplarPair pair = exsynth::make_exemplar_pair(preset, po);
  const double h = pair.a.transform().voxel_size;
  // Scale the bunny so that `res` voxels of the pair's size span it: A and B share a voxel size.
  exsynth::TriangleMesh bunny = exsynth::testing::load_obj(exsynth::testing::asset("meshes/bunny.obj"));
  Eigen::Vector3f lo = bunny.vertices[0], hi = lo;
  for (const auto& v : bunny.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const float scale = float(res * h / (hi - lo).maxCoeff());
  for (auto& v : bunny.vertices) v *= scale;
  exsynth::VoxelizeOptions vo;
  vo.resolution = res;
  // Room for the spikes (height 0.3 in pair units) to grow into.
  vo.padding = preset == exsynth::PairPreset::Spikes ? int(std::ceil(0.3 / h)) + 4 : 4;
  const exsynth::Volume b = exsynth::voxelize(bunny, vo).sdf;
  // OBJ is y up: circles around y.
  const auto field = exsynth::preset_direction_field(bunny, exsynth::FieldPreset::AroundAxis, Eigen::Vector3f::UnitY());
  exsynth::AnalogyResult r;
  for (auto _ : state) {
    const exsynth::VolumeFrames frames = exsynth::volume_frames(b, bunny.vertices, field);
    r = exsynth::synthesize_analogy(pair.a, pair.a_prime, pair.field_a, b, frames.t);
  }
  state.counters["nx"] = b.nx();
  state.counters["ny"] = b.ny();
  state.counters["nz"] = b.nz();
  state.counters["searched"] = double(r.searched);
  state.counters["culled_pct"] = 100.0 * double(r.culled) / double(r.culled + r.searched);
  state.counters["coherent_pct"] = 100.0 * double(r.coherent) / double(r.searched);
  state.counters["ann_skipped_pct"] = 100.0 * double(r.ann_skipped) / double(r.searched);
}
BENCHMARK(BM_AnalogyBunny)
    ->Args({int(exsynth::PairPreset::Grooves), 200})
    ->Args({int(exsynth::PairPreset::Spikes), 200})
    ->ArgNames({"preset", "res"})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
