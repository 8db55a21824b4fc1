// Surface synthesis at the paper's sizes (Ying et al. 2001, table): the
// bundled cow (5804 triangles = 17412 ptex faces) at ~370k texels with a 96²
// exemplar (coherent; paper: 3 min), ~400k texels with a 64² exemplar
// (multiscale; paper: 10 min) and with a 192² exemplar (paper: 290 min).
// Exemplars are the test suite's structured disc textures (no image I/O in
// the core). Texel density is searched once, before timing, to hit the count.
#include <benchmark/benchmark.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "../tests/cpp/support/load_obj.hpp"
#include "../tests/cpp/support/textures.hpp"
#include "cancel_latency.hpp"
#include "exsynth/surface.hpp"

namespace {

const exsynth::SubdivSurface& cow() {
  static const exsynth::SubdivSurface s = [] {
    const exsynth::TriangleMesh t = exsynth::testing::load_obj(exsynth::testing::asset("meshes/cow.obj"));
    exsynth::PolygonMesh m;
    m.vertices = t.vertices;
    for (const auto& f : t.faces) {
      m.face_sizes.push_back(3);
      m.face_vertices.insert(m.face_vertices.end(), {f[0], f[1], f[2]});
    }
    return exsynth::SubdivSurface(m);
  }();
  return s;
}

/// Options whose texel count is closest to `texels` (bisection on the density).
exsynth::SurfaceSynthesisOptions options_for(double texels, exsynth::SurfaceMethod method) {
  exsynth::SurfaceSynthesisOptions o;
  o.method = method;
  o.min_face_resolution = 1;
  double lo = 1, hi = 1e5;
  for (int it = 0; it < 60; ++it) {
    o.texels_per_unit = std::sqrt(lo * hi);
    double n = 0;
    for (int r : exsynth::surface_face_resolutions(cow(), o)) n += double(r) * r;
    (n < texels ? lo : hi) = o.texels_per_unit;
  }
  o.seed = 1;
  return o;
}

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Wall and process CPU time per stage (ExecContext stage names), printed
/// to stderr after each run: where the time goes.
class StageTimer {
 public:
  explicit StageTimer(exsynth::ExecContext& ctx) : ctx_(ctx) {
    ctx.on_stage([this] { switch_to(ctx_.stage()); });
  }
  void finish(const char* title) {
    switch_to("");
    std::fprintf(stderr, "%s: stage wall / process CPU (s)\n", title);
    for (const auto& [name, t] : totals_) std::fprintf(stderr, "  %-44s %7.2f %7.2f\n", name.c_str(), t[0], t[1]);
  }

 private:
  void switch_to(const std::string& stage) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    const double cpu = process_cpu_seconds();
    if (!current_.empty()) {
      totals_[current_][0] += wall - wall_;
      totals_[current_][1] += cpu - cpu_;
    }
    current_ = stage;
    wall_ = wall;
    cpu_ = cpu;
  }
  exsynth::ExecContext& ctx_;
  std::string current_;
  double wall_ = 0, cpu_ = 0;
  std::map<std::string, std::array<double, 2>> totals_;
};

void run(benchmark::State& state, const char* name, double texels, int exemplar, exsynth::SurfaceMethod method,
         bool charts = true) {
  exsynth::SurfaceSynthesisOptions o = options_for(texels, method);
  o.vertex_charts = charts;
  const exsynth::Image ex = exsynth::testing::disc_texture(exemplar, exemplar, 3, 7, exemplar * exemplar / 60,
                                                           float(exemplar) / 24);
  std::size_t count = 0;
  for (auto _ : state) {
    exsynth::ExecContext ctx;
    StageTimer timer(ctx);
    const double cpu0 = process_cpu_seconds();
    const exsynth::SurfaceTexture t = exsynth::synthesize_surface(cow(), ex, o, &ctx);
    state.counters["process_cpu_s"] = process_cpu_seconds() - cpu0;
    timer.finish(name);
    count = t.texel_count();
    state.counters["walked_pct"] = 100.0 * double(t.walked_samples) / double(std::max<std::uint64_t>(1, t.chart_samples + t.walked_samples));
    benchmark::DoNotOptimize(t.texels.data());
  }
  state.counters["texels"] = double(count);
  state.counters["exemplar"] = exemplar;
  state.counters["texels_per_unit"] = o.texels_per_unit;
}

void BM_SurfaceCoherent(benchmark::State& state) { run(state, "coherent 96", 370e3, 96, exsynth::SurfaceMethod::Coherent); }
// The same with every neighbourhood sample walked on the limit surface (no vertex charts).
void BM_SurfaceCoherentWalks(benchmark::State& state) { run(state, "coherent 96, walks", 370e3, 96, exsynth::SurfaceMethod::Coherent, false); }
void BM_SurfaceMultiscale64(benchmark::State& state) { run(state, "multiscale 64", 400e3, 64, exsynth::SurfaceMethod::Multiscale); }
void BM_SurfaceMultiscale192(benchmark::State& state) { run(state, "multiscale 192", 400e3, 192, exsynth::SurfaceMethod::Multiscale); }

/// Atlas + limit mesh for the coherent result (the rest of the job).
void BM_SurfaceAtlasAndMesh(benchmark::State& state) {
  const exsynth::SurfaceSynthesisOptions o = options_for(370e3, exsynth::SurfaceMethod::Coherent);
  const exsynth::SurfaceTexture t =
      exsynth::synthesize_surface(cow(), exsynth::testing::disc_texture(96, 96, 3, 7), o);
  for (auto _ : state) {
    const exsynth::SurfaceAtlas a = exsynth::build_surface_atlas(cow(), t, 2);
    const exsynth::LimitMesh m = exsynth::surface_limit_mesh(cow(), t, a, 2);
    benchmark::DoNotOptimize(m.vertices.data());
  }
}

// Cancel latency per stage (cancel_latency.hpp): coherent synthesis on the cow
// at ~100 k texels, 64^2 exemplar.
void BM_CancelLatencySurface(benchmark::State& state) {
  const exsynth::SurfaceSynthesisOptions o = options_for(double(state.range(0)), exsynth::SurfaceMethod::Coherent);
  const exsynth::Image ex = exsynth::testing::disc_texture(64, 64, 3, 7, 64 * 64 / 60, 64.0f / 24);
  exsynth_bench::report(state, "surface", [&](exsynth::ExecContext* ctx) { exsynth::synthesize_surface(cow(), ex, o, ctx); });
}

}  // namespace

BENCHMARK(BM_CancelLatencySurface)->Arg(100000)->ArgName("texels")->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceCoherent)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceCoherentWalks)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceMultiscale64)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceMultiscale192)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceAtlasAndMesh)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
