// GL backend benchmarks at 1920x1080. Each stage of renderGl is timed inside the backend
// (frame.meta timing_ms) and reported here as counters; the harness overhead adds the
// frame files (writeFrameDir) to upload + readback. One driver per process:
//   RASTERCHECK_GL_SPEC=gl:egl:softpipe ./bench_gl   or   ./bench_gl --gl_spec=gl:egl:softpipe
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "fixtures/frame_io.h"
#include "fixtures/scene.h"
#include "gl_backend/context.h"
#include "gl_backend/gl_backend.h"
#include "gl_backend/gl_functions.h"

namespace {

std::string g_spec = "gl:egl:llvmpipe";

// A lit sphere (64 x 32 segments) over a ground grid, perspective, Phong shading: the
// kind of scene the conformance suite renders, at 1080p.
rc::Scene benchScene(rc::ColorFormat color) {
  rc::Scene s;
  s.name = "bench/sphere_1080p";
  s.width = 1920;
  s.height = 1080;
  s.camera.eye = {0.0, 1.0, 4.0};
  s.camera.target = {0.0, 0.3, 0.0};
  s.ambient_light = {0.1, 0.1, 0.1};
  s.state.color_format = color;
  rc::Light key;
  key.position = {2, 3, 3};
  s.lights.push_back(key);
  rc::Light fill;
  fill.type = rc::LightType::Directional;
  fill.direction = {-1, -1, -0.5};
  fill.intensity = 0.4;
  s.lights.push_back(fill);
  rc::Material m;
  m.ambient = {0.8, 0.3, 0.2};
  m.diffuse = {0.8, 0.3, 0.2};
  m.specular = {0.5, 0.5, 0.5};
  s.materials.push_back(m);

  rc::Object ball;
  const int seg = 64, rings = 32;
  for (int r = 0; r <= rings; ++r) {
    const double th = std::numbers::pi * r / rings;
    for (int i = 0; i <= seg; ++i) {
      const double ph = 2 * std::numbers::pi * i / seg;
      const glm::vec3 p(static_cast<float>(std::sin(th) * std::cos(ph)),
                        static_cast<float>(std::cos(th)),
                        static_cast<float>(-std::sin(th) * std::sin(ph)));
      ball.mesh.positions.push_back(p);
      ball.mesh.normals.push_back(p);
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int i = 0; i < seg; ++i) {
      const auto a = static_cast<std::uint32_t>(r * (seg + 1) + i);
      const auto b = a + static_cast<std::uint32_t>(seg + 1);
      ball.mesh.triangles.push_back({a, b, a + 1});
      ball.mesh.triangles.push_back({a + 1, b, b + 1});
    }
  }
  ball.model = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0.5, 0));
  s.objects.push_back(ball);

  rc::Object ground;
  ground.mesh.positions = {{-5, -0.5f, 5}, {5, -0.5f, 5}, {5, -0.5f, -5}, {-5, -0.5f, -5}};
  ground.mesh.normals.assign(4, glm::vec3(0, 1, 0));
  ground.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(ground);
  return s;
}

double metaMs(const rc::Frame& f, const char* key) {
  return f.meta.at("timing_ms").at(key).get<double>();
}

// Creating the provider's context from nothing (display, context, function table): what a
// fresh `rastercheck render` child pays once.
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

// One full renderGl at 1080p; the counters split it into the backend's stages.
void BM_Render1080p(benchmark::State& state) {
  const auto color = static_cast<rc::ColorFormat>(state.range(0));
  const rc::Scene scene = benchScene(color);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  double upload = 0, draw = 0, readback = 0, context = 0;
  std::string renderer;
  for (auto _ : state) {
    const rc::Frame f = rc::renderGl(scene, spec);
    upload += metaMs(f, "upload");
    draw += metaMs(f, "draw");
    readback += metaMs(f, "readback");
    context += metaMs(f, "context");
    renderer = f.meta.at("gl_renderer").get<std::string>();
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["context_ms"] = context / n;
  state.counters["upload_ms"] = upload / n;
  state.counters["draw_ms"] = draw / n;
  state.counters["readback_ms"] = readback / n;
  state.SetLabel(renderer + (color == rc::ColorFormat::RGBA8 ? ", rgba8" : ", rgba32f"));
}

// The harness's own cost per frame: upload + readback (with conversion) inside the
// backend, plus writing the frame directory (frame.exr, color.png, frame.json).
void BM_HarnessOverhead1080p(benchmark::State& state) {
  const rc::Scene scene = benchScene(rc::ColorFormat::RGBA32F);
  const rc::GlSpec spec = rc::parseGlSpec(g_spec);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rc_bench_gl_" + std::to_string(::getpid()));
  double upload = 0, readback = 0, write = 0;
  for (auto _ : state) {
    const rc::Frame f = rc::renderGl(scene, spec);
    const auto start = std::chrono::steady_clock::now();
    rc::writeFrameDir(f, dir);
    write +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    upload += metaMs(f, "upload");
    readback += metaMs(f, "readback");
  }
  std::filesystem::remove_all(dir);
  const auto n = static_cast<double>(state.iterations());
  state.counters["upload_ms"] = upload / n;
  state.counters["readback_ms"] = readback / n;
  state.counters["write_frame_ms"] = write / n;
  state.counters["backend_overhead_ms"] = (upload + readback) / n;
  state.counters["harness_overhead_ms"] = (upload + readback + write) / n;
}

}  // namespace

BENCHMARK(BM_ContextCreate)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_Render1080p)
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA32F))
    ->Arg(static_cast<int>(rc::ColorFormat::RGBA8))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK(BM_HarnessOverhead1080p)->Unit(benchmark::kMillisecond)->MinTime(2.0);

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
  try {
    const rc::GlSpec spec = rc::parseGlSpec(g_spec);
    // The driver is chosen by the first context of the process (as renderGl does).
    if (!spec.driver.empty()) {
      setenv("GALLIUM_DRIVER", spec.driver.c_str(), 1);
      if (spec.platform == rc::GlSpec::Platform::EglSurfaceless)
        setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  benchmark::AddCustomContext("gl_spec", g_spec);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
