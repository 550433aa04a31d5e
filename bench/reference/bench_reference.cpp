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

// 100k right triangles with 2-pixel legs (2 px^2: about two fragments each) at random
// positions, flat shaded, one material.
Scene smallTriangles() {
  Scene s = test::windowScene(kSize, kSize);
  s.state.shading = Shading::Flat;
  Object o;
  std::uint32_t seed = 1;
  auto rnd = [&]() {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / static_cast<float>(1 << 24) * (kSize - 4) + 1.0f;
  };
  for (std::uint32_t i = 0; i < 100000; ++i) {
    const float x = rnd(), y = rnd(), z = 0.25f + 0.5f * (i % 97) / 97.0f;
    o.mesh.positions.insert(o.mesh.positions.end(), {{x, y, z}, {x + 2, y, z}, {x, y + 2, z}});
    o.mesh.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  o.mesh.normals.assign(o.mesh.positions.size(), {0.0f, 0.0f, 1.0f});
  s.objects.push_back(o);
  return s;
}

// 8 full-screen rectangles drawn back to front (every fragment passes the depth test and
// is shaded and written), lit by one point light, Blinn-Phong, shininess 32.
Scene layers(Shading shading) {
  Scene s = test::windowScene(kSize, kSize);
  s.state.shading = shading;
  s.ambient_light = glm::dvec3(0.1);
  s.lights.push_back(Light{LightType::Point, {300.0, 700.0, 400.0}, {}, {1.0, 1.0, 1.0}, 1.0});
  s.materials[0].diffuse = {0.6, 0.5, 0.4};
  s.materials[0].specular = glm::dvec3(0.5);
  s.materials[0].shininess = 32.0;
  for (int layer = 0; layer < 8; ++layer)
    test::addRect(s, -1.0f, -1.0f, kSize + 1.0f, kSize + 1.0f, 0.1f + 0.1f * layer);
  return s;
}

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
  static const Scene scene = smallTriangles();
  run(state, scene, state.range(0) != 0, 100000.0, 200000.0);
}
BENCHMARK(BM_SmallTriangles)->ArgName("uncertainty")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Layers(benchmark::State& state) {
  const auto shading = static_cast<Shading>(state.range(0));
  static const Scene scenes[3] = {layers(Shading::Flat), layers(Shading::Gouraud),
                                  layers(Shading::Phong)};
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
