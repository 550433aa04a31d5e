// GL backend benchmarks, one driver per process (GALLIUM_DRIVER is read once):
//   ./bench_gl --gl_spec=gl:egl:softpipe     (or RASTERCHECK_GL_SPEC=...)
// At 1920x1080: context creation, shader compilation, upload, draw and readback as
// separate counters (each timed inside renderGl, frame.meta timing_ms), and the harness's
// own overhead per frame (upload + readback with conversion + writing the frame files).
// Plus the reference benchmark's scenes, for bench/run.sh's reference/GL ratios.
// Everything is wall time (UseRealTime): the drivers draw on their own threads.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "bench/gl/bench_scenes.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/scene.h"
#include "gl_backend/context.h"
#include "gl_backend/gl_backend.h"
#include "gl_backend/gl_functions.h"

namespace {

std::string g_spec = "gl:egl:llvmpipe";

double metaMs(const rc::Frame& f, const char* key) {
  return f.meta.at("timing_ms").at(key).get<double>();
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Sums of the backend's stage timings over the iterations, reported as per-frame means.
struct Stages {
  double context = 0, compile = 0, upload = 0, draw = 0, readback = 0;
  std::string renderer;

  void add(const rc::Frame& f) {
    context += metaMs(f, "context");
    compile += metaMs(f, "compile");
    upload += metaMs(f, "upload");
    draw += metaMs(f, "draw");
    readback += metaMs(f, "readback");
    renderer = f.meta.at("gl_renderer").get<std::string>();
  }
  void report(benchmark::State& state) const {
    const auto n = static_cast<double>(state.iterations());
    state.counters["context_ms"] = context / n;
    state.counters["compile_ms"] = compile / n;
    state.counters["upload_ms"] = upload / n;
    state.counters["draw_ms"] = draw / n;
    state.counters["readback_ms"] = readback / n;
  }
};

// A context from nothing (display, context, function table) after the process's first:
// Mesa keeps the loaded driver, so this is what a second context costs. The first one,
// driver loading included, is the "first_context_ms" entry of the run's context.
void BM_ContextCreate(benchmark::State& state) {
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  for (auto _ : state) {
    std::unique_ptr<rc::gl::Context> ctx;
    if (spec.platform == rc::GlSpec::Platform::OSMesa) {
      ctx = rc::gl::createOsMesaContext();
    } else if (spec.platform == rc::GlSpec::Platform::EglDevice) {
      ctx = rc::gl::createEglDeviceContext(spec.device);
    } else {
      ctx = rc::gl::createEglSurfacelessContext();
    }
    ctx->makeCurrent();
    rc::gl::Functions gl;
    gl.load(ctx->loader());
    benchmark::DoNotOptimize(gl.GetString(GL_RENDERER));
    ctx->release();
  }
}

// One renderGl of the 1080p scene; the counters split it into the backend's stages.
void BM_Stages1080p(benchmark::State& state) {
  const auto color = static_cast<rc::ColorFormat>(state.range(0));
  const rc::Scene scene = rc::bench::sphere1080p(color);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  Stages stages;
  for (auto _ : state) stages.add(rc::renderGl(scene, spec));
  stages.report(state);
  state.SetLabel(stages.renderer + (color == rc::ColorFormat::RGBA8 ? ", rgba8" : ", rgba32f"));
}

// The harness's own cost per 1080p frame: upload and readback (with conversion) inside
// the backend, plus writing the frame directory (frame.exr, color.png, frame.json) as
// `rastercheck render` does. Each iteration writes into the same directory (replaced).
void BM_HarnessOverhead1080p(benchmark::State& state) {
  const rc::Scene scene = rc::bench::sphere1080p(rc::ColorFormat::RGBA32F);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rc_bench_gl_" + std::to_string(::getpid()));
  Stages stages;
  double write = 0;
  for (auto _ : state) {
    const rc::Frame f = rc::renderGl(scene, spec);
    const auto start = std::chrono::steady_clock::now();
    rc::writeFrameDir(f, dir);
    write += msSince(start);
    stages.add(f);
  }
  std::filesystem::remove_all(dir);
  stages.report(state);
  const auto n = static_cast<double>(state.iterations());
  state.counters["write_frame_ms"] = write / n;
  state.counters["backend_overhead_ms"] = (stages.upload + stages.readback) / n;
  state.counters["harness_overhead_ms"] = (stages.upload + stages.readback + write) / n;
}

// The reference benchmark's scenes through GL: same names and arguments as in
// bench_reference, so bench/run.sh can match them.
void renderScene(benchmark::State& state, const rc::Scene& scene) {
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  Stages stages;
  for (auto _ : state) stages.add(rc::renderGl(scene, spec));
  stages.report(state);
  state.SetLabel(stages.renderer);
}

void BM_SmallTriangles(benchmark::State& state) {
  static const rc::Scene scene = rc::bench::smallTriangles();
  renderScene(state, scene);
}

void BM_Layers(benchmark::State& state) {
  static const rc::Scene scenes[3] = {rc::bench::layers(rc::Shading::Flat),
                                      rc::bench::layers(rc::Shading::Gouraud),
                                      rc::bench::layers(rc::Shading::Phong)};
  renderScene(state, scenes[state.range(0)]);
}

}  // namespace

BENCHMARK(BM_ContextCreate)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stages1080p)
    ->ArgName("rgba8")
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA32F))
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA8))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_HarnessOverhead1080p)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SmallTriangles)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Layers)
    ->ArgName("shading")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

int main(int argc, char** argv) {
  if (const char* env = std::getenv("RASTERCHECK_GL_SPEC"); env != nullptr && *env != '\0')
    g_spec = env;
  // Our own flag, removed before Google Benchmark sees the arguments.
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--gl_spec=", 10) == 0) {
      g_spec = argv[i] + 10;
    } else {
      argv[out++] = argv[i];
    }
  }
  argc = out;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // The first render of the process creates the session (driver loading, context) and
  // compiles the program: what every `rastercheck render` child pays once.
  try {
    rc::Scene tiny = rc::bench::sphere1080p(rc::ColorFormat::RGBA32F);
    tiny.width = 16;
    tiny.height = 16;
    const rc::Frame f = rc::renderGl(tiny, rc::parseGlSpec(g_spec));
    benchmark::AddCustomContext("gl_spec", g_spec);
    benchmark::AddCustomContext("gl_renderer", f.meta.at("gl_renderer").get<std::string>());
    benchmark::AddCustomContext("first_context_ms", std::to_string(metaMs(f, "context")));
    benchmark::AddCustomContext("first_compile_ms", std::to_string(metaMs(f, "compile")));
  } catch (const rc::InputError& e) {
    std::fprintf(stderr, "bench_gl: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_gl: %s\n", e.what());
    return 3;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
