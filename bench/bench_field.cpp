// Direction-field benchmarks at the size: ~100k vertices, ~20
// painted vertices (the target: well under a second on 2 cores).
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <utility>

#include "../tests/cpp/support/load_obj.hpp"
#include "../tests/cpp/support/shapes.hpp"
#include "exsynth/field.hpp"
#include "exsynth/rng.hpp"

namespace {

using exsynth::TriangleMesh;

// One 1-to-4 midpoint subdivision: the 26k-vertex Armadillo becomes 104k
// vertices with the same (real, irregular) shape.
TriangleMesh subdivide(const TriangleMesh& m) {
  TriangleMesh out{m.vertices, {}};
  std::map<std::pair<int, int>, int> mid;
  auto midpoint = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    out.vertices.push_back(0.5f * (m.vertices[a] + m.vertices[b]));
    return mid[key] = int(out.vertices.size()) - 1;
  };
  for (const auto& f : m.faces) {
    const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
    out.faces.insert(out.faces.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
  }
  return out;
}

const TriangleMesh& mesh(int which) {
  static const TriangleMesh armadillo =
      subdivide(exsynth::testing::load_obj(exsynth::testing::asset("meshes/armadillo.obj")));
  static const TriangleMesh sphere = exsynth::testing::icosphere(1.0f, 7);
  return which == 0 ? armadillo : sphere;
}

// `count` painted vertices with random directions (projected by the engine).
std::vector<Eigen::Vector3f> strokes(std::size_t vertices, int count) {
  std::vector<Eigen::Vector3f> g(vertices, Eigen::Vector3f::Zero());
  for (int k = 0; k < count; ++k) {
    exsynth::IndexRng r(1, std::uint64_t(k));
    g[std::size_t(r.uniform() * double(vertices))] =
        Eigen::Vector3f(float(r.uniform() - 0.5), float(r.uniform() - 0.5), float(r.uniform() - 0.5));
  }
  return g;
}

// mesh: 0 = Armadillo subdivided once (104k vertices), 1 = icosphere level 7 (164k).
void BM_DiffuseDirectionField(benchmark::State& state) {
  const TriangleMesh& m = mesh(int(state.range(0)));  // built before timing starts
  const auto given = strokes(m.vertices.size(), 20);
  exsynth::DirectionFieldOptions opt;
  opt.weights = state.range(1) ? exsynth::FieldWeights::Uniform : exsynth::FieldWeights::Cotangent;
  for (auto _ : state) {
    auto f = exsynth::diffuse_direction_field(m, given, opt);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["vertices"] = double(m.vertices.size());
  state.counters["painted"] = 20;
}
BENCHMARK(BM_DiffuseDirectionField)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"mesh", "uniform"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A preset over the same 104k vertices; along_curve with a 200-point curve
// is the brute-force nearest-segment case.
void BM_PresetDirectionField(benchmark::State& state) {
  const TriangleMesh& m = mesh(0);
  const auto preset = exsynth::FieldPreset(state.range(0));
  std::vector<Eigen::Vector3f> curve;
  for (int k = 0; k < 200; ++k) curve.emplace_back(std::cos(k * 0.05f), std::sin(k * 0.05f), k * 0.01f);
  for (auto _ : state) {
    auto f = exsynth::preset_direction_field(m, preset, Eigen::Vector3f(0, 1, 0), curve);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["vertices"] = double(m.vertices.size());
}
BENCHMARK(BM_PresetDirectionField)->DenseRange(0, 2)->ArgName("preset")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
