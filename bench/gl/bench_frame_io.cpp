// Frame files at 1920x1080: write time, read time and size of frame.exr for each
// lossless EXR compression, of color.png for each zlib level, the defaults through
// writeFrameDir/readFrameDir, and the floors (memcpy and a plain write() of the same
// bytes). Frames: the reference's render of bench/sphere_1080p, with its uncertainty
// channels (8 channels, what `render --backend ref` writes) and without (6, what a GL
// backend writes). Files go to $TMPDIR (default /tmp); results: docs/gl_backend.md.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "bench/gl/bench_scenes.h"
#include "fixtures/frame_io.h"
#include "reference/reference_renderer.h"

namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 9> kExrCompressions = {"none",  "rle", "zips",  "zips:1", "zip",
                                                         "zip:1", "piz", "zip:6", "zips:6"};
constexpr std::array<int, 5> kPngLevels = {0, 1, 3, 6, 9};

// range 1 of every benchmark: 6 (GL frame) or 8 (reference frame with uncertainty).
const rc::Frame& frame(int channels) {
  static const rc::Frame ref = [] {
    rc::ReferenceOptions options;
    options.uncertainty = true;
    return rc::renderReference(rc::bench::sphere1080p(rc::ColorFormat::RGBA32F), options);
  }();
  static const rc::Frame gl = [] {
    rc::Frame f = ref;
    f.clearUncertainty();
    return f;
  }();
  return channels == 8 ? ref : gl;
}

fs::path scratchDir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("rc_bench_frame_io_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

double megabytes(const fs::path& file) { return static_cast<double>(fs::file_size(file)) / 1e6; }

void BM_ExrWrite(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(1)));
  rc::FrameEncoding enc;
  enc.exr_compression = kExrCompressions[state.range(0)];
  const fs::path file = scratchDir() / "write.exr";
  for (auto _ : state) rc::writeFrameExr(f, file, enc);
  state.counters["file_MB"] = megabytes(file);
  state.SetLabel(enc.exr_compression);
  fs::remove(file);
}

void BM_ExrRead(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(1)));
  rc::FrameEncoding enc;
  enc.exr_compression = kExrCompressions[state.range(0)];
  const fs::path file = scratchDir() / ("read_" + std::to_string(state.range(0)) + ".exr");
  rc::writeFrameExr(f, file, enc);
  for (auto _ : state) benchmark::DoNotOptimize(rc::readFrameExr(file).id.data());
  state.counters["file_MB"] = megabytes(file);
  state.SetLabel(enc.exr_compression);
  fs::remove(file);
}

void BM_PngWrite(benchmark::State& state) {
  const rc::Frame& f = frame(6);
  rc::FrameEncoding enc;
  enc.png_level = kPngLevels[state.range(0)];
  enc.png_filter = static_cast<int>(state.range(1));
  const fs::path file = scratchDir() / "write.png";
  for (auto _ : state) rc::writeColorPng(f, file, enc);
  state.counters["file_MB"] = megabytes(file);
  state.SetLabel("level " + std::to_string(enc.png_level) + " filter " +
                 std::to_string(enc.png_filter));
  fs::remove(file);
}

// What `rastercheck render` does after rendering: both images (on two threads) and
// frame.json into a temporary sibling, then renamed into place (replace:0, a new DIR,
// the old one deleted outside the timing) or swapped with an existing DIR whose old
// frame is then deleted (replace:1).
void BM_WriteFrameDir(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(0)));
  const bool replace = state.range(1) != 0;
  const fs::path dir = scratchDir() / "frame";
  for (auto _ : state) {
    rc::writeFrameDir(f, dir);
    if (!replace) {
      state.PauseTiming();
      fs::remove_all(dir);
      state.ResumeTiming();
    }
  }
  rc::writeFrameDir(f, dir);
  state.counters["exr_MB"] = megabytes(dir / "frame.exr");
  state.counters["png_MB"] = megabytes(dir / "color.png");
  fs::remove_all(dir);
}

// What `rastercheck compare` does per side.
void BM_ReadFrameDir(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(0)));
  const fs::path dir = scratchDir() / "frame_read";
  rc::writeFrameDir(f, dir);
  for (auto _ : state) benchmark::DoNotOptimize(rc::readFrameDir(dir).id.data());
  fs::remove_all(dir);
}

std::size_t rawBytes(const rc::Frame& f) {
  return f.pixelCount() * (6 + (f.hasUncertainty() ? rc::kUncertaintyChannels : 0)) * sizeof(float);
}

// Floor 1: copying the frame's bytes once in memory (warm destination).
void BM_FloorMemcpy(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(0)));
  const std::size_t bytes = rawBytes(f);
  std::vector<char> src(bytes, 1), dst(bytes, 0);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), bytes);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
}

// Floor 2: a fresh Frame's buffers of that size, allocated and zero-filled (page faults
// included): what any readback into a new Frame pays before the first byte is copied.
void BM_FloorFreshFrame(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    rc::Frame fresh;
    fresh.color.resize(f.color.size());
    fresh.depth.resize(f.depth.size());
    fresh.id.resize(f.id.size());
    const auto from = f.uncertainty();
    const auto to = fresh.uncertainty();
    for (int c = 0; c < rc::kUncertaintyChannels; ++c) to[c]->resize(from[c]->size());
    benchmark::DoNotOptimize(fresh.color.data());
  }
}

// Floor 3: handing the same bytes to the kernel as one write() of a new file (page
// cache, no fsync; the previous file is deleted outside the timing): what writing an
// uncompressed frame.exr cannot beat.
void BM_FloorWriteFile(benchmark::State& state) {
  const rc::Frame& f = frame(static_cast<int>(state.range(0)));
  const std::size_t bytes = rawBytes(f);
  const std::vector<char> src(bytes, 1);
  const fs::path file = scratchDir() / "raw.bin";
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove(file);
    state.ResumeTiming();
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || ::write(fd, src.data(), bytes) != static_cast<ssize_t>(bytes)) {
      state.SkipWithError("write failed");
    }
    if (fd >= 0) ::close(fd);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  fs::remove(file);
}

}  // namespace

BENCHMARK(BM_ExrWrite)
    ->ArgNames({"compression", "channels"})
    ->ArgsProduct({benchmark::CreateDenseRange(0, kExrCompressions.size() - 1, 1), {6, 8}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ExrRead)
    ->ArgNames({"compression", "channels"})
    ->ArgsProduct({benchmark::CreateDenseRange(0, kExrCompressions.size() - 1, 1), {6, 8}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_PngWrite)
    ->ArgNames({"level", "filter"})
    ->ArgsProduct({benchmark::CreateDenseRange(0, kPngLevels.size() - 1, 1), {0, 8, 16, 32}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_WriteFrameDir)
    ->ArgNames({"channels", "replace"})
    ->ArgsProduct({{6, 8}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ReadFrameDir)
    ->ArgName("channels")
    ->Arg(6)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FloorMemcpy)
    ->ArgName("channels")
    ->Arg(6)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FloorFreshFrame)
    ->ArgName("channels")
    ->Arg(6)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FloorWriteFile)
    ->ArgName("channels")
    ->Arg(6)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

int main(int argc, char** argv) {
  // --exr_threads=N: OpenEXR's thread pool size (OIIO "exr_threads"; -1 none, 0 one per
  // core, the default). With -1, CPU time is all the encoding work.
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--exr_threads=", 14) == 0) {
      OIIO::attribute("exr_threads", std::atoi(argv[i] + 14));
      benchmark::AddCustomContext("exr_threads", argv[i] + 14);
    } else if (std::strncmp(argv[i], "--exr_core=", 11) == 0) {
      OIIO::attribute("openexr:core", std::atoi(argv[i] + 11));
      benchmark::AddCustomContext("openexr:core", argv[i] + 11);
    } else {
      argv[out++] = argv[i];
    }
  }
  argc = out;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ec;
  fs::remove_all(scratchDir(), ec);
  return 0;
}
