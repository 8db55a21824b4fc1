// Voxelizer benchmarks on a real mesh (the 52k-triangle Armadillo).
#include <benchmark/benchmark.h>

#include "../tests/cpp/support/load_obj.hpp"
#include "exsynth/voxelize.hpp"

namespace {

const exsynth::TriangleMesh& armadillo() {
  static const exsynth::TriangleMesh m = exsynth::testing::load_obj(exsynth::testing::asset("meshes/armadillo.obj"));
  return m;
}

// Density + full signed distance (the figure: 256 voxels on the longest axis).
void BM_VoxelizeArmadillo(benchmark::State& state) {
  exsynth::VoxelizeOptions opt;
  opt.resolution = int(state.range(0));
  opt.compute_sdf = state.range(1) != 0;
  const exsynth::TriangleMesh& mesh = armadillo();  // loaded before timing starts
  std::size_t voxels = 0;
  for (auto _ : state) {
    auto r = exsynth::voxelize(mesh, opt);
    voxels = r.density.voxel_count();
    benchmark::DoNotOptimize(r.density.data());
  }
  state.counters["voxels"] = double(voxels);
  state.counters["triangles"] = double(armadillo().faces.size());
  state.counters["Mvoxel/s"] =
      benchmark::Counter(double(voxels) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_VoxelizeArmadillo)
    ->ArgsProduct({{128, 256}, {0, 1}})
    ->ArgNames({"res", "sdf"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
