// Comparator throughput on a 1920x1080 pair that exercises every class: a reference-like
// frame against a copy with driver-like noise everywhere (depth +-2 steps, colour +-0.01
// units: the p99 and max that llvmpipe and softpipe show on the catalog, see
// docs/tolerances.md), blocks of missing, extra and wrong-primitive pixels, and depth and
// colour outliers. A second pair has noise of +-0.4 units, over the shading warn level at
// every pixel: the worst case, where every pixel takes the allowance path.
#include <random>

#include <benchmark/benchmark.h>

#include "compare/compare.h"
#include "synthetic_frames.h"

namespace {

struct Pair {
  rc::Frame ref;
  rc::Frame gl;
};

Pair makePair(float colour_noise_units) {
  Pair p;
  constexpr int kW = 1920, kH = 1080;
  p.ref = rc::testing::renderRects(kW, kH, rc::testing::defaultRects(kW, kH));
  p.gl = p.ref;
  p.gl.clearUncertainty();
  p.gl.meta["backend"] = "gl:bench";
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> dz(-2, 2);
  std::uniform_real_distribution<float> dc(-colour_noise_units / 255.0f,
                                           colour_noise_units / 255.0f);
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
}

const Pair& pair1080p() {
  static const Pair pair = makePair(0.01f);
  return pair;
}

const Pair& noisyPair1080p() {
  static const Pair pair = makePair(0.4f);
  return pair;
}

// Pixels per second of CPU time: the target is per core, and this machine is shared.
void countPixels(benchmark::State& state, const Pair& p) {
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(p.ref.pixelCount()));
  state.counters["Mpx/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(p.ref.pixelCount()) * 1e-6,
      benchmark::Counter::kIsRate);
}

void BM_Compare1080p(benchmark::State& state) {
  const Pair& p = pair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  for (auto _ : state) {
    rc::PairResult r = rc::compareFrames(p.ref, p.gl, p.ref, tol);
    benchmark::DoNotOptimize(r);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Compare1080p)->Unit(benchmark::kMillisecond);

void BM_Compare1080pWithMaps(benchmark::State& state) {
  const Pair& p = pair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  rc::ClassMaps maps;
  maps.want_flip = false;  // BM_Flip1080p measures it
  for (auto _ : state) {
    rc::PairResult r = rc::compareFrames(p.ref, p.gl, p.ref, tol, &maps);
    benchmark::DoNotOptimize(r);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Compare1080pWithMaps)->Unit(benchmark::kMillisecond);

void BM_Compare1080pNoisy(benchmark::State& state) {
  const Pair& p = noisyPair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  for (auto _ : state) {
    rc::PairResult r = rc::compareFrames(p.ref, p.gl, p.ref, tol);
    benchmark::DoNotOptimize(r);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Compare1080pNoisy)->Unit(benchmark::kMillisecond);

// LDR-FLIP (compare/flip.h) alone, on the colour of the pair above: the cost `run` and
// `compare` add per pair with --flip.
void BM_Flip1080p(benchmark::State& state) {
  const Pair& p = pair1080p();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  std::vector<float> map;
  for (auto _ : state) {
    rc::FlipStats s = rc::flipFrames(p.ref, p.gl, tol, &map);
    benchmark::DoNotOptimize(s);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Flip1080p)->Unit(benchmark::kMillisecond);

// CIEDE2000 (compare/ciede2000.h) alone, which every comparison includes: on the pair
// above (only the blocks and the noisy pixels whose 8-bit colour changes are computed) and
// on its worst case: random 8-bit colours at every pixel against a copy one step off in R,
// G and B, so that no pixel repeats its neighbour's pair of colours.
void BM_Ciede2000_1080p(benchmark::State& state) {
  const Pair& p = pair1080p();
  for (auto _ : state) {
    rc::DeltaE2000Stats s = rc::deltaE2000Frames(p.ref, p.gl);
    benchmark::DoNotOptimize(s);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Ciede2000_1080p)->Unit(benchmark::kMillisecond);

void BM_Ciede2000_1080pEveryPixel(benchmark::State& state) {
  static const Pair p = [] {
    Pair q;
    q.ref = rc::testing::renderRects(1920, 1080, rc::testing::defaultRects(1920, 1080));
    q.gl = q.ref;
    std::mt19937 rng(2);
    std::uniform_int_distribution<int> byte(0, 254);
    for (std::size_t i = 0; i < q.gl.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) {
        const int v = byte(rng);
        q.ref.color[4 * i + c] = static_cast<float>(v) / 255.0f;
        q.gl.color[4 * i + c] = static_cast<float>(v + 1) / 255.0f;
      }
    return q;
  }();
  for (auto _ : state) {
    rc::DeltaE2000Stats s = rc::deltaE2000Frames(p.ref, p.gl);
    benchmark::DoNotOptimize(s);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Ciede2000_1080pEveryPixel)->Unit(benchmark::kMillisecond);

// The catalog's usual size.
void BM_Flip256(benchmark::State& state) {
  static const Pair p = [] {
    Pair q;
    q.ref = rc::testing::renderRects(256, 256, rc::testing::defaultRects(256, 256));
    q.gl = q.ref;
    for (std::size_t i = 0; i < q.gl.pixelCount(); i += 7) q.gl.color[4 * i] += 0.02f;
    return q;
  }();
  const rc::Tolerances tol = rc::tolerancesForFrames(p.ref, p.gl);
  std::vector<float> map;
  for (auto _ : state) {
    rc::FlipStats s = rc::flipFrames(p.ref, p.gl, tol, &map);
    benchmark::DoNotOptimize(s);
  }
  countPixels(state, p);
}
BENCHMARK(BM_Flip256)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
