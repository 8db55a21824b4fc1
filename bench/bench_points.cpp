// Point-set geometry texture synthesis at the seed paper's sizes: a 71 k
// point chainmail exemplar grown to ~197 k points (paper: 38 s) and to
// ~2.9 M points (paper: 711 s), with the paper's Table 1 split of the time.
#include <benchmark/benchmark.h>

#include <cmath>

#include <time.h>

#include "../tests/cpp/support/load_obj.hpp"
#include "cancel_latency.hpp"
#include "exsynth/field.hpp"
#include "exsynth/points.hpp"

namespace {

using namespace exsynth;

// CPU seconds of all the process's threads: on a shared machine the wall
// time follows the load, this does not (ideal 2-core wall = cpu_s / 2).
double process_cpu_s() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The built-in chainmail at the density that gives ~71 k exemplar points
// (box 1 x 1 plus 0.35 padding), made once.
const PointExemplar& exemplar_71k() {
  static const PointExemplar ex = [] {
    const PointExemplar probe = make_point_exemplar("chainmail", 1000.0);
    return make_point_exemplar("chainmail", 1000.0 * 71000.0 / double(probe.points.size()));
  }();
  return ex;
}

// The side of the square that holds `target` output points at the
// exemplar's box density (points per unit area).
double side_for(const PointExemplar& ex, double target) {
  std::size_t inside = 0;
  for (const auto& p : ex.points.positions) inside += p.x() >= 0 && p.x() <= 1 && p.y() >= 0 && p.y() <= 1;
  return std::sqrt(target / double(inside));
}

void BM_PointsChainmail(benchmark::State& state) {
  const PointExemplar& ex = exemplar_71k();
  const double side = side_for(ex, double(state.range(0)));
  const PointTextureOptions opt = point_texture_preset("chainmail");
  PointTextureResult r;
  double cpu = 0;
  for (auto _ : state) {
    const double c0 = process_cpu_s();
    r = synthesize_points(ex, side, side, opt);
    cpu += process_cpu_s() - c0;
    benchmark::DoNotOptimize(r.points.positions.data());
  }
  state.counters["cpu_s"] = cpu / double(state.iterations());
  state.counters["in_points"] = double(ex.points.size());
  state.counters["out_points"] = double(r.points.size());
  state.counters["patches"] = double(r.patches);
  state.counters["search_s"] = r.times.search;
  state.counters["warp_s"] = r.times.warp;
  state.counters["blend_s"] = r.times.blend;
  state.counters["other_s"] = r.times.other;
}
BENCHMARK(BM_PointsChainmail)->Arg(197000)->Arg(2900000)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// Cancel latency per stage (cancel_latency.hpp) of the 197 k case.
void BM_CancelLatencyPoints(benchmark::State& state) {
  const PointExemplar& ex = exemplar_71k();
  const double side = side_for(ex, 197000.0);
  const PointTextureOptions opt = point_texture_preset("chainmail");
  exsynth_bench::report(state, "points", [&](ExecContext* ctx) { synthesize_points(ex, side, side, opt, ctx); });
}
BENCHMARK(BM_CancelLatencyPoints)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// Cancel latency per stage of a curved target: the bundled bunny scaled to 2
// units, chainmail at 1500 points per unit area, 0.5 target units per
// exemplar unit, the field around the bunny's vertical (Y) axis.
void BM_CancelLatencyPointsOnMesh(benchmark::State& state) {
  static const PointExemplar ex = make_point_exemplar("chainmail", 1500.0);
  TriangleMesh bunny = exsynth::testing::load_obj(exsynth::testing::asset("meshes/bunny.obj"));
  Eigen::Vector3f lo = bunny.vertices[0], hi = lo;
  for (const auto& v : bunny.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  for (auto& v : bunny.vertices) v *= 2.0f / (hi - lo).maxCoeff();
  const std::vector<Eigen::Vector3f> field = preset_direction_field(bunny, FieldPreset::AroundAxis, Eigen::Vector3f::UnitY());
  const PointTextureOptions opt = point_texture_preset("chainmail");
  exsynth_bench::report(state, "points on a mesh", [&](ExecContext* ctx) {
    synthesize_points_on_mesh(ex, bunny, field, 0.5, opt, ctx);
  });
}
BENCHMARK(BM_CancelLatencyPointsOnMesh)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
