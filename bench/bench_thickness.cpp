// Model thickness (Geometric Texture's fitted pattern size) on the Armadillo.
#include <benchmark/benchmark.h>

#include "../tests/cpp/support/load_obj.hpp"
#include "exsynth/thickness.hpp"

namespace {

void BM_ThicknessArmadillo(benchmark::State& state) {
  static const exsynth::TriangleMesh mesh =
      exsynth::testing::load_obj(exsynth::testing::asset("meshes/armadillo.obj"));
  exsynth::ThicknessOptions opt;
  opt.resolution = int(state.range(0));
  exsynth::ThicknessResult r;
  for (auto _ : state) {
    r = exsynth::model_thickness(mesh, opt);
    benchmark::DoNotOptimize(r.thickness);
  }
  state.counters["samples"] = double(r.samples);
}
BENCHMARK(BM_ThicknessArmadillo)->Arg(96)->Arg(192)->ArgName("res")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
