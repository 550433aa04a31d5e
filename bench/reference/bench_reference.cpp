// Reference renderer throughput, single-threaded, at 1024 x 1024: many tiny triangles
// (setup cost) and full-screen layers per shading mode (per-fragment cost), each with
// and without the uncertainty channels. Numbers: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr int kSize = 1024;

void run(benchmark::State& state, const Scene& scene, bool uncertainty, double triangles,
         double fragments) {
  ReferenceOptions options;
  options.uncertainty = uncertainty;
  for (auto _ : state) {
    Frame f = renderReference(scene, options);
    benchmark::DoNotOptimize(f.color.data());
  }
  if (triangles > 0)
    state.counters["tris_per_s"] =
        benchmark::Counter(triangles, benchmark::Counter::kIsIterationInvariantRate);
  if (fragments > 0)
    state.counters["frags_per_s"] =
        benchmark::Counter(fragments, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_SmallTriangles(benchmark::State& state) {
  static const Scene scene = test::smallTrianglesScene(kSize, 100000);
  run(state, scene, state.range(0) != 0, 100000.0, 200000.0);
}
BENCHMARK(BM_SmallTriangles)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Layers(benchmark::State& state) {
  const auto shading = static_cast<Shading>(state.range(0));
  static const Scene scenes[3] = {test::layersScene(Shading::Flat, kSize, 8),
                                  test::layersScene(Shading::Gouraud, kSize, 8),
                                  test::layersScene(Shading::Phong, kSize, 8)};
  state.SetLabel(toString(shading));
  run(state, scenes[state.range(0)], state.range(1) != 0, 16.0, 8.0 * kSize * kSize);
}
BENCHMARK(BM_Layers)
    ->ArgNames({"shading", "uncertainty"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// The fixed cost of a 1024 x 1024 frame with nothing in it (allocation, clear, output).
void BM_EmptyFrame(benchmark::State& state) {
  static const Scene scene = test::windowScene(kSize, kSize);
  run(state, scene, state.range(0) != 0, 0.0, 0.0);
}
BENCHMARK(BM_EmptyFrame)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rc

BENCHMARK_MAIN();
