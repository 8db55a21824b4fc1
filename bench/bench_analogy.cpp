// Volume analogy (isotropic variant): the dilation pair applied to the
// voxelized bunny at the "bunny-sized" resolution (~200 voxels on
// the longest axis).
#include <benchmark/benchmark.h>

#include "../tests/cpp/support/load_obj.hpp"
#include "exsynth/analogy.hpp"
#include "exsynth/pairs.hpp"
#include "exsynth/voxelize.hpp"

namespace {

void BM_AnalogyDilateBunny(benchmark::State& state) {
  const int res = int(state.range(0));
  exsynth::PairOptions po;
  po.resolution = 32;
  const exsynth::ExemplarPair pair = exsynth::make_exemplar_pair(exsynth::PairPreset::Dilate, po);
  const double h = pair.a.transform().voxel_size;
  // Scale the bunny so that `res` voxels of the pair's size span it: A and B share a voxel size.
  exsynth::TriangleMesh bunny = exsynth::testing::load_obj(exsynth::testing::asset("meshes/bunny.obj"));
  Eigen::Vector3f lo = bunny.vertices[0], hi = lo;
  for (const auto& v : bunny.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const float scale = float(res * h / (hi - lo).maxCoeff());
  for (auto& v : bunny.vertices) v *= scale;
  exsynth::VoxelizeOptions vo;
  vo.resolution = res;
  const exsynth::Volume b = exsynth::voxelize(bunny, vo).sdf;
  std::size_t searched = 0, culled = 0;
  for (auto _ : state) {
    const auto r = exsynth::synthesize_analogy(pair.a, pair.a_prime, b);
    searched = r.searched;
    culled = r.culled;
  }
  state.counters["voxels"] = double(b.voxel_count());
  state.counters["searched"] = double(searched);
  state.counters["culled"] = double(culled);
}
BENCHMARK(BM_AnalogyDilateBunny)->Arg(64)->Arg(200)->ArgName("res")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
