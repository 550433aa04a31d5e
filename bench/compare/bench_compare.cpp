// Comparator throughput on a 1920x1080 pair that exercises every class: a reference-like
// frame against a copy with GL-like noise (depth +-2 steps, colour +-0.4 units everywhere),
// blocks of missing, extra and wrong-primitive pixels, and depth and colour outliers.
#include <random>

#include <benchmark/benchmark.h>

#include "compare/compare.h"
#include "synthetic_frames.h"

namespace {

struct Pair {
  rc::Frame ref;
  rc::Frame gl;
};

const Pair& pair1080p() {
  static const Pair pair = [] {
    Pair p;
    constexpr int kW = 1920, kH = 1080;
    p.ref = rc::testing::renderRects(kW, kH, rc::testing::defaultRects(kW, kH));
    p.gl = p.ref;
    p.gl.edge_dist.clear();
    p.gl.depth_gap.clear();
    p.gl.meta["backend"] = "gl:bench";
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> dz(-2, 2);
    std::uniform_real_distribution<float> dc(-0.4f / 255.0f, 0.4f / 255.0f);
    for (std::size_t i = 0; i < p.gl.pixelCount(); ++i) {
      if (p.gl.id[i] == 0) continue;
      p.gl.depth[i] =
          static_cast<float>((std::nearbyint(p.gl.depth[i] * 16777215.0) + dz(rng)) / 16777215.0);
      for (int c = 0; c < 3; ++c) p.gl.color[i * 4 + c] += dc(rng);
    }
    auto block = [&](int x0, int y0, auto f) {
      for (int y = y0; y < y0 + 40; ++y)
        for (int x = x0; x < x0 + 40; ++x) f(p.gl.index(x, y));
    };
    block(400, 200, [&](std::size_t i) { p.gl.id[i] = 0; });                       // missing
    block(20, 1040, [&](std::size_t i) { p.gl.id[i] = 9; });                       // extra
    block(500, 300, [&](std::size_t i) { p.gl.id[i] = 4; });                       // wrong
    block(300, 400, [&](std::size_t i) { p.gl.depth[i] += 1e-4f; });               // depth
    block(200, 500, [&](std::size_t i) { p.gl.color[i * 4] += 10.0f / 255.0f; });  // shading
    return p;
  }();
  return pair;
}

void BM_Compare1080p(benchmark::State& state) {
  const Pair& p = pair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  for (auto _ : state) {
    rc::PairResult r = rc::compareFrames(p.ref, p.gl, p.ref, tol);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(p.ref.pixelCount()));
  state.counters["Mpx/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(p.ref.pixelCount()) * 1e-6,
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Compare1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Compare1080pWithMaps(benchmark::State& state) {
  const Pair& p = pair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  rc::ClassMaps maps;
  for (auto _ : state) {
    rc::PairResult r = rc::compareFrames(p.ref, p.gl, p.ref, tol, &maps);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(p.ref.pixelCount()));
  state.counters["Mpx/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(p.ref.pixelCount()) * 1e-6,
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Compare1080pWithMaps)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
