// compareFrames and the other entry points of compare.h: checks the frames, fills in what a
// PairResult knows before any pixel is compared, runs the Comparator (compare_internal.h),
// then the additive measures. Formulas and their derivation in docs/tolerances.md.
#include "compare/compare.h"

#include <chrono>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "compare/compare_internal.h"
#include "compare/pair_tolerances.h"
#include "fixtures/errors.h"
#include "fixtures/multisample.h"

namespace rc {
namespace {

std::string metaString(const Frame& f, const char* key) {
  const auto it = f.meta.find(key);
  return it != f.meta.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string frameLabel(const Frame& f, const char* role) {
  const std::string backend = metaString(f, "backend");
  return backend.empty() ? std::string(role) : fmt::format("{} ({})", role, backend);
}

int subpixelBits(const Frame& f, const char* role) {
  const auto it = f.meta.find("subpixel_bits");
  if (it == f.meta.end() || it->is_null()) return 8;
  if (!it->is_number_integer() || it->get<long long>() < 0 || it->get<long long>() > 24)
    throw InputError(
        fmt::format("{}: frame.json: subpixel_bits must be an integer in [0, 24], "
                    "got {}",
                    frameLabel(f, role), it->dump()));
  return it->get<int>();
}

void checkBuffers(const Frame& f, const char* role, bool need_color) {
  if (f.width < 0 || f.height < 0 || static_cast<long long>(f.width) * f.height > (1LL << 31))
    throw InputError(
        fmt::format("{}: unusable frame size {}x{}", frameLabel(f, role), f.width, f.height));
  const std::size_t n = f.pixelCount();
  if ((need_color && f.color.size() != n * 4) || f.depth.size() != n || f.id.size() != n)
    throw InputError(fmt::format("{}: frame buffers do not match its size {}x{}",
                                 frameLabel(f, role), f.width, f.height));
  const bool unc = f.hasUncertainty();
  for (int c = 0; c < kUncertaintyChannels; ++c) {
    if (f.uncertainty()[c]->size() != (unc ? n : 0))
      throw InputError(fmt::format("{}: {} does not match its size", frameLabel(f, role),
                                   kUncertaintyChannelInfo[c].name));
  }
  checkSamplePlanes(f, frameLabel(f, role));
}

}  // namespace

PairResult errorResult(std::string fixture, std::string expected, std::string actual,
                       std::string message) {
  PairResult r;
  r.fixture = std::move(fixture);
  r.expected = std::move(expected);
  r.actual = std::move(actual);
  r.status = Status::Error;
  r.error = std::move(message);
  return r;
}

PairResult notSupportedResult(std::string fixture, std::string expected, std::string actual,
                              std::string reason) {
  PairResult r =
      errorResult(std::move(fixture), std::move(expected), std::move(actual), std::move(reason));
  r.status = Status::NotSupported;
  return r;
}

std::optional<std::string> notSupportedReason(const std::string& message) {
  constexpr std::string_view kMarker = "not supported: ";
  const std::size_t at = message.find(kMarker);
  if (at == std::string::npos) return std::nullopt;
  return message.substr(at + kMarker.size());
}

PairResult compareFrames(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                         const Tolerances& tolerances, ClassMaps* maps) {
  const auto start = std::chrono::steady_clock::now();
  checkBuffers(expected, "expected", true);
  checkBuffers(actual, "actual", true);
  const bool separate_uncertainty = &uncertainty != &expected;
  if (separate_uncertainty) checkBuffers(uncertainty, "uncertainty", false);
  if (expected.width != actual.width || expected.height != actual.height)
    throw InputError(fmt::format("frames differ in size: {} is {}x{}, {} is {}x{}",
                                 frameLabel(expected, "expected"), expected.width, expected.height,
                                 frameLabel(actual, "actual"), actual.width, actual.height));
  if (expected.samples != actual.samples)
    throw InputError(fmt::format("frames differ in samples per pixel: {} has {}, {} has {}",
                                 frameLabel(expected, "expected"), expected.samples,
                                 frameLabel(actual, "actual"), actual.samples));
  if (uncertainty.width != expected.width || uncertainty.height != expected.height)
    throw InputError(fmt::format("frames differ in size: {} is {}x{}, {} is {}x{}",
                                 frameLabel(expected, "expected"), expected.width, expected.height,
                                 frameLabel(uncertainty, "uncertainty"), uncertainty.width,
                                 uncertainty.height));

  PairResult r;
  r.fixture = metaString(expected, "fixture");
  if (r.fixture.empty()) r.fixture = metaString(actual, "fixture");
  r.expected = metaString(expected, "backend");
  r.actual = metaString(actual, "backend");
  for (const Frame* f : {&expected, &actual}) {
    const auto st = f->meta.find("state");
    if (st != f->meta.end() && st->is_object()) {
      r.state = *st;
      break;
    }
  }
  r.actual_driver = metaString(actual, "gl_version");
  r.width = expected.width;
  r.height = expected.height;
  r.pixels = expected.pixelCount();
  r.expected_subpixel_bits = subpixelBits(expected, "expected");
  r.actual_subpixel_bits = subpixelBits(actual, "actual");
  r.tolerances = tolerances;
  BandInputs band;
  band.expected_bits = r.expected_subpixel_bits;
  band.actual_bits = r.actual_subpixel_bits;
  band.width = expected.width;
  band.height = expected.height;
  r.visibility.band_px = snapBandPx(tolerances, band);
  auto offsetR = [](const Frame& f) {
    const auto it = f.meta.find("polygon_offset_r");
    return it != f.meta.end() && it->is_number() ? it->get<double>()
                                                 : std::numeric_limits<double>::quiet_NaN();
  };
  r.depth.offset_r_expected = offsetR(expected);
  r.depth.offset_r_actual = offsetR(actual);
  r.depth.offset_r_spread =
      std::isnan(r.depth.offset_r_expected) || std::isnan(r.depth.offset_r_actual)
          ? kUnknownOffsetSpread
          : std::fabs(r.depth.offset_r_expected - r.depth.offset_r_actual);
  r.depth.band_px = slopeBandPx(tolerances, band);

  // Quantized formats have integer errors: exact percentiles (histogram.h).
  const bool int_depth = tolerances.depth_format != DepthFormat::D32F;
  const bool int_color = tolerances.color_format == ColorFormat::RGBA8;
  r.depth.histogram = ErrorHistogram(int_depth ? 1.0 : 1.0 / 64.0, int_depth);
  r.shading.histogram = ErrorHistogram(int_color ? 1.0 : 1.0 / 4096.0, int_color);
  detail::Comparator(expected, actual, uncertainty, tolerances, r).run(maps);
  r.oit = compareOit(expected, actual, tolerances);
  r.ciede2000 = deltaE2000Frames(expected, actual);  // cheap: only differing pixels
  if ((maps && maps->want_flip) || tolerances.flip_mean_fail) {
    r.flip = flipFrames(expected, actual, tolerances, maps ? &maps->flip : nullptr);
    r.status = worse(r.status, r.flip->status);
  } else if (maps) {
    maps->flip.clear();  // no stale map from an earlier comparison
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Tolerances tolerancesForFrames(const Frame& expected, const Frame& actual) {
  const DrawFacts& e = expected.drawn;
  const DrawFacts& a = actual.drawn;
  if (e.depth_format && a.depth_format && *e.depth_format != *a.depth_format)
    throw InputError(fmt::format("{} has depth_format {}, {} has {}",
                                 frameLabel(expected, "expected"), toString(*e.depth_format),
                                 frameLabel(actual, "actual"), toString(*a.depth_format)));
  if (e.color_format && a.color_format && *e.color_format != *a.color_format)
    throw InputError(fmt::format("{} has color_format {}, {} has {}",
                                 frameLabel(expected, "expected"), toString(*e.color_format),
                                 frameLabel(actual, "actual"), toString(*a.color_format)));
  const DepthFormat depth = e.depth_format.value_or(a.depth_format.value_or(DepthFormat::D24));
  const ColorFormat color = e.color_format.value_or(a.color_format.value_or(ColorFormat::RGBA32F));
  DrawnWith drawn;
  drawn.linear_textures = e.linearTextures() || a.linearTextures();
  return defaultTolerances(depth, color, drawn);
}

PairResult compareFrames(const Frame& expected, const Frame& actual) {
  return compareFrames(expected, actual, expected,
                       pairTolerances(expected, actual, fixtureTolerance(expected, actual)));
}

void checkSameSize(const Frame& expected, const Frame& actual,
                   const std::filesystem::path& expected_dir,
                   const std::filesystem::path& actual_dir) {
  if (expected.width != actual.width || expected.height != actual.height)
    throw InputError(fmt::format("{} ({}x{}) and {} ({}x{}) differ in size", expected_dir.string(),
                                 expected.width, expected.height, actual_dir.string(), actual.width,
                                 actual.height));
}

}  // namespace rc
