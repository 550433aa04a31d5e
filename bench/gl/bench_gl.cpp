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
#include <ctime>
#include <filesystem>
#include <string>

#include "bench/gl/bench_scenes.h"
#include "fixtures/big_buffer.h"
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
// Wall times, plus the calling thread's CPU time for the harness's own stages (robust
// when other processes share the cores).
struct Stages {
  double context = 0, compile = 0, framebuffer = 0, upload = 0, draw = 0, readback = 0;
  double framebuffer_cpu = 0, upload_cpu = 0, readback_cpu = 0;
  std::string renderer;

  void add(const rc::Frame& f) {
    context += metaMs(f, "context");
    compile += metaMs(f, "compile");
    framebuffer += metaMs(f, "framebuffer");
    upload += metaMs(f, "upload");
    draw += metaMs(f, "draw");
    readback += metaMs(f, "readback");
    framebuffer_cpu += f.meta.at("timing_cpu_ms").at("framebuffer").get<double>();
    upload_cpu += f.meta.at("timing_cpu_ms").at("upload").get<double>();
    readback_cpu += f.meta.at("timing_cpu_ms").at("readback").get<double>();
    renderer = f.meta.at("gl_renderer").get<std::string>();
  }
  void report(benchmark::State& state) const {
    const auto n = static_cast<double>(state.iterations());
    state.counters["context_ms"] = context / n;
    state.counters["compile_ms"] = compile / n;
    state.counters["framebuffer_ms"] = framebuffer / n;
    state.counters["upload_ms"] = upload / n;
    state.counters["draw_ms"] = draw / n;
    state.counters["readback_ms"] = readback / n;
    state.counters["framebuffer_cpu_ms"] = framebuffer_cpu / n;
    state.counters["upload_cpu_ms"] = upload_cpu / n;
    state.counters["readback_cpu_ms"] = readback_cpu / n;
  }
};

// CPU time of the whole process (the PNG writer thread included; the driver's threads
// are idle while the frame is written).
double processCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// A context from nothing: display, context, made current, function table loaded.
// Returns GL_RENDERER.
std::string createContext(const rc::GlSpec& spec) {
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
  std::string renderer = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER));
  ctx->release();
  return renderer;
}

// Contexts after the process's first (Mesa keeps the driver loaded): what each further
// context costs. The first one, driver loading included, is "first_context_ms" in the
// run's context. Runs before any render: destroying an EGL context terminates the
// display, which a render session would share.
void BM_ContextCreate(benchmark::State& state) {
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  for (auto _ : state) benchmark::DoNotOptimize(createContext(spec));
}

// The process's first render, at 1080p: the session's context, the first shader
// compilation (llvmpipe JITs its variants in the first draw), the FBO allocation and a
// readback into memory the process has never touched: what a `rastercheck render`
// child pays. One iteration by construction.
void BM_FirstRender1080p(benchmark::State& state) {
  const rc::Scene scene = rc::bench::sphere1080p(rc::ColorFormat::RGBA32F);
  Stages stages;
  for (auto _ : state) stages.add(rc::renderGl(scene, rc::parseGlSpec(g_spec)));
  stages.report(state);
}

// One renderGl of the 1080p scene; the counters split it into the backend's stages.
void BM_Stages1080p(benchmark::State& state) {
  const auto color = static_cast<rc::ColorFormat>(state.range(0));
  const rc::Scene scene = rc::bench::sphere1080p(color);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  rc::renderGl(scene, spec);  // warm-up: llvmpipe JITs shader variants at the first draw
  Stages stages;
  for (auto _ : state) stages.add(rc::renderGl(scene, spec));
  stages.report(state);
  state.SetLabel(stages.renderer + (color == rc::ColorFormat::RGBA8 ? ", rgba8" : ", rgba32f"));
}

// The harness's own cost per 1080p frame: upload and readback (with conversion) inside
// the backend, plus writing the frame directory (frame.exr, color.png, frame.json) as
// `rastercheck render` does into a new DIR (as `rastercheck run` does; deleting the
// previous iteration's 50 MB frame, 10-20 ms of unlinking, happens outside the timing).
void BM_HarnessOverhead1080p(benchmark::State& state) {
  const rc::Scene scene = rc::bench::sphere1080p(rc::ColorFormat::RGBA32F);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rc_bench_gl_" + std::to_string(::getpid()));
  rc::renderGl(scene, spec);  // warm-up, as above
  Stages stages;
  double write = 0, write_cpu = 0;
  for (auto _ : state) {
    const rc::Frame f = rc::renderGl(scene, spec);
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = processCpuMs();
    rc::writeFrameDir(f, dir);
    write += msSince(start);
    write_cpu += processCpuMs() - cpu_start;
    stages.add(f);
    state.PauseTiming();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
  }
  std::filesystem::remove_all(dir);
  stages.report(state);
  const auto n = static_cast<double>(state.iterations());
  state.counters["write_frame_ms"] = write / n;
  state.counters["backend_overhead_ms"] = (stages.upload + stages.readback) / n;
  state.counters["harness_overhead_ms"] = (stages.upload + stages.readback + write) / n;
  state.counters["write_frame_cpu_ms"] = write_cpu / n;
  state.counters["harness_overhead_cpu_ms"] =
      (stages.upload_cpu + stages.readback_cpu + write_cpu) / n;
}

// The reference benchmark's scenes through GL: same names and arguments as in
// bench_reference, so bench/run.sh can match them.
void renderScene(benchmark::State& state, const rc::Scene& scene) {
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  rc::renderGl(scene, spec);  // warm-up, as above
  Stages stages;
  for (auto _ : state) stages.add(rc::renderGl(scene, spec));
  stages.report(state);
  state.SetLabel(stages.renderer);
}

void BM_SmallTriangles(benchmark::State& state) {
  static const rc::Scene scene = rc::bench::smallTriangles();
  renderScene(state, scene);
}

void BM_SmallTriangleMesh(benchmark::State& state) {
  static const rc::Scene scene = rc::bench::smallTriangleMesh();
  renderScene(state, scene);
}

void BM_Lines(benchmark::State& state) {
  static const rc::Scene scene = rc::bench::linesAndPoints();
  renderScene(state, scene);
}

void BM_ShadowMap(benchmark::State& state) {
  static const rc::Scene scene = rc::bench::shadowMap();
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
BENCHMARK(BM_FirstRender1080p)
    ->Iterations(1)
    ->Repetitions(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Stages1080p)
    ->ArgName("rgba8")
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA32F))
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA8))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_HarnessOverhead1080p)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SmallTriangles)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SmallTriangleMesh)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Lines)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShadowMap)->Unit(benchmark::kMillisecond)->UseRealTime();
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
  // As run's workers and bench_reference: freed frames stay in the process, so that the
  // reference-against-driver ratios compare the two under the same memory policy.
  rc::keepFreedMemory();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  try {
    const rc::GlSpec spec = rc::parseGlSpec(g_spec);
    // The driver is chosen by the first context of the process, as renderGl does.
    if (!spec.driver.empty()) {
      setenv("GALLIUM_DRIVER", spec.driver.c_str(), 1);
      if (spec.platform == rc::GlSpec::Platform::EglSurfaceless)
        setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
    }
    const auto start = std::chrono::steady_clock::now();
    const std::string renderer = createContext(spec);
    benchmark::AddCustomContext("first_context_ms", std::to_string(msSince(start)));
    benchmark::AddCustomContext("gl_spec", g_spec);
    benchmark::AddCustomContext("gl_renderer", renderer);
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
