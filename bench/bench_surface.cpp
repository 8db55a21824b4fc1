// Surface synthesis at the paper's sizes (Ying et al. 2001, table): the
// bundled cow (5804 triangles = 17412 ptex faces) at ~370k texels with a 96²
// exemplar (coherent; paper: 3 min), ~400k texels with a 64² exemplar
// (multiscale; paper: 10 min) and with a 192² exemplar (paper: 290 min).
// Exemplars are the test suite's structured disc textures (no image I/O in
// the core). Texel density is searched once, before timing, to hit the count.
#include <benchmark/benchmark.h>

#include <cmath>

#include "../tests/cpp/support/load_obj.hpp"
#include "../tests/cpp/support/textures.hpp"
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

void run(benchmark::State& state, double texels, int exemplar, exsynth::SurfaceMethod method) {
  const exsynth::SurfaceSynthesisOptions o = options_for(texels, method);
  const exsynth::Image ex = exsynth::testing::disc_texture(exemplar, exemplar, 3, 7, exemplar * exemplar / 60,
                                                           float(exemplar) / 24);
  std::size_t count = 0;
  for (auto _ : state) {
    const exsynth::SurfaceTexture t = exsynth::synthesize_surface(cow(), ex, o);
    count = t.texel_count();
    benchmark::DoNotOptimize(t.texels.data());
  }
  state.counters["texels"] = double(count);
  state.counters["exemplar"] = exemplar;
  state.counters["texels_per_unit"] = o.texels_per_unit;
}

void BM_SurfaceCoherent(benchmark::State& state) { run(state, 370e3, 96, exsynth::SurfaceMethod::Coherent); }
void BM_SurfaceMultiscale64(benchmark::State& state) { run(state, 400e3, 64, exsynth::SurfaceMethod::Multiscale); }
void BM_SurfaceMultiscale192(benchmark::State& state) { run(state, 400e3, 192, exsynth::SurfaceMethod::Multiscale); }

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

}  // namespace

BENCHMARK(BM_SurfaceCoherent)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceMultiscale64)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceMultiscale192)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SurfaceAtlasAndMesh)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
