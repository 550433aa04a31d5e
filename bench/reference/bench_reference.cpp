// Reference renderer throughput, single-threaded, at 1024 x 1024: many tiny triangles, as a
// soup and as one mesh (setup cost) and full-screen layers per shading mode (per-fragment cost),
// each with the uncertainty channels off and on (the CLI default). Counters: tris_per_s (the
// scene's triangles) and frags_per_s (covered pixel centres, depth-tested or not, as the renderer
// counts them in frame.meta). The scenes come from rc_scene_builders
// (tests/reference/test_scenes.h), which bench_gl renders too. Commands: docs/reference.md.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "fixtures/big_buffer.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr int kSize = 1024;

double sceneTriangles(const Scene& scene) {
  double n = 0.0;
  for (const Object& o : scene.objects) n += static_cast<double>(o.mesh.triangles.size());
  return n;
}

void run(benchmark::State& state, const Scene& scene, bool uncertainty) {
  ReferenceOptions options;
  options.uncertainty = uncertainty;
  double fragments = 0.0;  // the same on every render
  for (auto _ : state) {
    Frame f = renderReference(scene, options);
    benchmark::DoNotOptimize(f.color.data());
    fragments = static_cast<double>(f.meta.at("fragments").get<std::uint64_t>());
  }
  const double triangles = sceneTriangles(scene);
  if (triangles > 0)
    state.counters["tris_per_s"] =
        benchmark::Counter(triangles, benchmark::Counter::kIsIterationInvariantRate);
  if (fragments > 0)
    state.counters["frags_per_s"] =
        benchmark::Counter(fragments, benchmark::Counter::kIsIterationInvariantRate);
}

// 100k right triangles with 2-pixel legs (about two fragments each), flat shaded.
void BM_SmallTriangles(benchmark::State& state) {
  static const Scene scene = test::smallTrianglesScene(kSize, 100000);
  run(state, scene, state.range(0) != 0);
}
BENCHMARK(BM_SmallTriangles)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The same 100k triangles of 2 px^2 as one grid mesh (shared vertices, drawn in row order):
// how a tessellated model arrives, next to the soup above.
void BM_SmallTriangleMesh(benchmark::State& state) {
  static const Scene scene = test::smallTriangleMeshScene(kSize, 100000);
  run(state, scene, state.range(0) != 0);
}
BENCHMARK(BM_SmallTriangleMesh)
    ->ArgName("uncertainty")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);

// 8 full-screen layers drawn back to front (8 * 1024^2 fragments, all passing), one point
// light, Blinn-Phong, shininess 32.
void BM_Layers(benchmark::State& state) {
  const auto shading = static_cast<Shading>(state.range(0));
  static const Scene scenes[3] = {test::layersScene(Shading::Flat, kSize, 8),
                                  test::layersScene(Shading::Gouraud, kSize, 8),
                                  test::layersScene(Shading::Phong, kSize, 8)};
  state.SetLabel(toString(shading));
  run(state, scenes[state.range(0)], state.range(1) != 0);
}
BENCHMARK(BM_Layers)
    ->ArgNames({"shading", "uncertainty"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// 20k segments (a third 3 px wide) and 20k points of size 3, Gouraud: the line and point
// path (line_loop.cpp), whose channels also sample each fragment's colour slack.
void BM_Lines(benchmark::State& state) {
  static const Scene scene = test::linesScene(kSize, 20000);
  run(state, scene, state.range(0) != 0);
}
BENCHMARK(BM_Lines)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A teapot on a floor through a 1024 x 1024 shadow map: two passes (the map, then the frame
// at 1024 x 768 with its lookups, the floor's percentage-closer filtered).
void BM_ShadowMap(benchmark::State& state) {
  static const Scene scene = test::shadowScene(kSize);
  run(state, scene, state.range(0) != 0);
}
BENCHMARK(BM_ShadowMap)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The fixed cost of a 1024 x 1024 frame with nothing in it (allocation, clear, output).
void BM_EmptyFrame(benchmark::State& state) {
  static const Scene scene = test::windowScene(kSize, kSize);
  run(state, scene, state.range(0) != 0);
}
BENCHMARK(BM_EmptyFrame)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rc

// The renderer as `run`'s workers use it: freed frames kept for the next render
// (keepFreedMemory(), fixtures/big_buffer.h), so that a benchmark measures rendering and
// not the kernel handing the same pages back every iteration.
int main(int argc, char** argv) {
  rc::keepFreedMemory();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
