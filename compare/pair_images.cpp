// Per-pair error images: see pair_images.h. Heat maps go through OpenImageIO's
// color_map so they use a perceptually uniform map people already know from idiff/oiiotool.
#include "compare/pair_images.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "compare/atomic_file.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/image_io.h"
#include "fixtures/shared_cache.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

using image_io::ImageFormat;
using image_io::PixelType;

// PNGs for people: fast deflate (level 1) and one cheap row filter (SUB) write a 1080p
// image several times faster than the defaults for files ~1.5x larger; these images are
// looked at, not archived. Above kStoreAbove pixels they are stored (level 0, no filter):
// at 1080p deflate was ~12% of a whole `compare` process's CPU time, for 19 MB instead of
// ~3 MB per pair (docs/performance.md).
constexpr int kPngCompressionLevel = 1;
constexpr int kPngFilterSub = 16;
constexpr int kPngFilterNone = 8;
constexpr std::size_t kPngStoreAbove = std::size_t{1} << 20;
// diff.exr: mostly zero rows (background, no error) that fast zip (level 1) shrinks to a
// few percent, at ~0.1 us per pixel. Above ~1 M pixels that is the longest single task of
// a comparison (0.24 s CPU at 1080p, five times the comparison itself), so large frames
// are written uncompressed (36 bytes per pixel).
constexpr const char* kDiffExrCompression = "zip:1";
constexpr std::size_t kDiffExrCompressUpTo = std::size_t{1} << 20;

bool storePng(int w, int h) {
  return static_cast<std::size_t>(w) * static_cast<std::size_t>(h) > kPngStoreAbove;
}

// Pair images in the user cache (shared_cache.h), as frames are (frame_io.cpp): a pair that
// fails in the same way run after run (a known failure) writes its images without loading
// the image library. Keyed by every input of the file and the image module; images of more
// than kCachedPixels pixels are encoded every time (their hashing would cost more than the
// cache saves for files that rarely repeat).
constexpr std::size_t kCachedPixels = std::size_t{1} << 20;
constexpr std::uintmax_t kUserPairImageCacheBytes = std::uintmax_t{64} << 20;

// The user cache for an image of w x h pixels: empty for none.
fs::path pairImageCache(int w, int h) {
  if (static_cast<std::size_t>(w) * static_cast<std::size_t>(h) > kCachedPixels) return {};
  return userCacheDir();
}

void writeRgb8(const fs::path& file, int w, int h, const std::vector<std::uint8_t>& rgb,
               const fs::path& target) {
  ImageFormat format{.width = w, .height = h, .channels = 3, .type = PixelType::UInt8};
  const bool store = storePng(w, h);
  if (file.extension() == ".png") {
    format.numbers = {{"png:compressionLevel", store ? 0 : kPngCompressionLevel},
                      {"png:filter", store ? kPngFilterNone : kPngFilterSub}};
  }
  const fs::path user = pairImageCache(w, h);
  const std::string key =
      user.empty() ? std::string()
                   : fmt::format("rastercheck rgb8 1|{}|{}|{}x{}|{}|{}", image_io::moduleIdentity(),
                                 file.extension().string(), w, h, store, bytesKey(rgb));
  writeThroughUserCache(
      user, key, "rcpair", file, [&] { image_io::writeImage(file, format, rgb.data(), target); },
      kUserPairImageCacheBytes);
}

// v >= 0 rounded to nearest, halves up, as std::lround: v - trunc(v) is exact in float
// (adding 0.5 first would round 0.49999997 up).
inline int roundHalfUp(float v) {
  const auto q = static_cast<int>(v);
  return q + (v - static_cast<float>(q) >= 0.5f ? 1 : 0);
}

// v clamped to [0, 255] and rounded; NaN fails both comparisons and becomes 0.
inline std::uint8_t toByte(float v) {
  v = v > 0.0f ? v : 0.0f;
  v = v < 255.0f ? v : 255.0f;
  return static_cast<std::uint8_t>(roundHalfUp(v));
}

// The picture of one frame: a link to (or copy of) a ready-made one, else encoded.
void writePicture(const Frame& frame, const fs::path& ready, const fs::path& file) {
  if (!ready.empty()) {
    std::error_code ec;
    fs::create_hard_link(ready, file, ec);
    if (!ec) return;
    if (fs::copy_file(ready, file, fs::copy_options::overwrite_existing, ec)) return;
  }
  // Encoded as render's color.png is, from the frame that was compared.
  const bool store = storePng(frame.width, frame.height);
  writeColorPng(frame, file,
                FrameEncoding{"none", store ? 0 : kPngCompressionLevel,
                              store ? kPngFilterNone : kPngFilterSub});
}

float luminance(const float* c) {
  const float l = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
  return std::isfinite(l) ? std::clamp(l, 0.0f, 1.0f) : 0.0f;
}

// The heat colour map sampled once (OpenImageIO's color_map), looked up per pixel.
constexpr int kHeatLutSize = 1024;
const std::vector<Rgb8>& heatLut() {
  static const std::vector<Rgb8> lut = heatColorStops(kHeatLutSize);
  return lut;
}

// Colours `values` (NaN = non-finite) of compared pixels through the heat colour map.
std::vector<std::uint8_t> heatImage(const ClassMaps& maps, const std::vector<float>& values,
                                    double scale) {
  const std::vector<Rgb8>& lut = heatLut();
  const std::size_t n = static_cast<std::size_t>(maps.width) * maps.height;
  std::vector<std::uint8_t> out(n * 3);
  for (std::size_t i = 0; i < n; ++i) {
    Rgb8 px;
    if (maps.pixel_class[i] != PixelClass::Match) {
      px = kNotComparedColor;
    } else if (std::isnan(values[i])) {
      px = kNonFiniteColor;
    } else if (values[i] == 0.0f) {
      px = lut[0];  // heatPosition(0) is 0: most compared pixels, without the log2
    } else {
      px = lut[static_cast<std::size_t>(
          roundHalfUp(heatPosition(values[i], scale) * static_cast<float>(kHeatLutSize - 1)))];
    }
    std::copy(px.begin(), px.end(), out.begin() + static_cast<std::ptrdiff_t>(i * 3));
  }
  return out;
}

// diff.exr: every float a tool might want, one channel each, written in bands of rows so
// that the interleaved pixels never exist for the whole image.
void writeDiffExrRows(const Frame& expected, const Frame& actual, const ClassMaps& maps,
                      const ImageFormat& format, const fs::path& file, const fs::path& target) {
  const int w = format.width;
  const int h = format.height;
  const int nch = format.channels;
  const std::unique_ptr<image_io::RowWriter> out =
      image_io::functions().open_rows(file, format, target);
  constexpr int kBandRows = 32;  // a multiple of every EXR compression's block height
  std::vector<float> band(static_cast<std::size_t>(w) * kBandRows * nch);
  for (int y0 = 0; y0 < h; y0 += kBandRows) {
    const int y1 = std::min(h, y0 + kBandRows);
    for (std::size_t i = static_cast<std::size_t>(y0) * w, k = 0;
         i < static_cast<std::size_t>(y1) * w; ++i, ++k) {
      float* p = &band[k * nch];
      p[0] = static_cast<float>(maps.pixel_class[i]);
      p[1] = maps.depth_steps[i];
      p[2] = maps.depth_tolerance[i];
      p[3] = maps.shading_abs[i];
      p[4] = maps.shading_tolerance[i];
      for (int c = 0; c < 4; ++c)
        p[5 + c] = (actual.color[i * 4 + c] - expected.color[i * 4 + c]) * 255.0f;
    }
    out->rows(y0, y1, band.data());
  }
  out->close();
}

// diff.exr, from the user cache when it was written before.
void writeDiffExr(const Frame& expected, const Frame& actual, const ClassMaps& maps,
                  const PairResult& result, const fs::path& file, const fs::path& target) {
  const int w = maps.width;
  const int h = maps.height;
  const std::vector<std::string> names = {
      "id_class", "depth_steps", "depth_tolerance", "shading_abs", "shading_tolerance", "dR", "dG",
      "dB",       "dA"};
  const int nch = static_cast<int>(names.size());
  ImageFormat format{
      .width = w, .height = h, .channel_names = names, .channels = nch, .type = PixelType::Float};
  format.text = {
      {"compression",
       static_cast<std::size_t>(w) * h <= kDiffExrCompressUpTo ? kDiffExrCompression : "none"},
      {"rastercheck:fixture", result.fixture},
      {"rastercheck:pair", result.expected + " vs " + result.actual},
      // No write time (OIIO stamps capDate otherwise): the same pair gives the same bytes,
      // which the user cache relies on.
      {"DateTime", ""}};
  const fs::path user = pairImageCache(w, h);
  std::string key;
  if (!user.empty()) {
    // The names with their lengths: no two pairs' texts run together into one key.
    const std::string pair = result.expected + " vs " + result.actual;
    key = fmt::format("rastercheck diff.exr 1|{}|{}x{}|{}|{}:{}|{}:{}|", image_io::moduleIdentity(),
                      w, h, format.text.at(0).second, result.fixture.size(), result.fixture,
                      pair.size(), pair);
    for (const std::string& part :
         {bytesKey(maps.pixel_class), bytesKey(maps.depth_steps), bytesKey(maps.depth_tolerance),
          bytesKey(maps.shading_abs), bytesKey(maps.shading_tolerance), bytesKey(expected.color),
          bytesKey(actual.color)})
      key += part + ',';
  }
  writeThroughUserCache(
      user, key, "rcpair", file,
      [&] { writeDiffExrRows(expected, actual, maps, format, file, target); },
      kUserPairImageCacheBytes);
}

// Runs the writers concurrently (each file is independent and most time is deflate), and
// rethrows the first failure once all have finished.
void runAll(std::vector<std::function<void()>> tasks) {
  std::vector<std::future<void>> running;
  running.reserve(tasks.size());
  for (auto& t : tasks) running.push_back(std::async(std::launch::async, std::move(t)));
  std::exception_ptr first;
  for (auto& f : running) {
    try {
      f.get();
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

std::string safeName(const std::string& s) {
  std::string out;
  for (char ch : s) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '.' || ch == '_' || ch == '-';
    out += ok ? ch : '_';
  }
  if (out.size() > 100) out.resize(100);  // ASCII by now; names stay far below NAME_MAX
  if (out.empty() || out == "." || out == "..") out = "_" + out;
  return out;
}

std::string fixtureFolderName(const PairResult& result) {
  return safeName(result.fixture.empty() ? "fixture" : result.fixture);
}

std::string pairFolderName(const PairResult& result) {
  return safeName(result.expected) + "_vs_" + safeName(result.actual);
}

}  // namespace

namespace {

// 64-bit FNV-1a over whole words: not cryptographic, only to notice a changed frame.
class FrameHash {
 public:
  void word(std::uint64_t w) { h_ = (h_ ^ w) * 0x100000001b3ull; }
  // The buffer's bytes, eight at a time, the rest one by one.
  template <class T>
  void bytes(const std::vector<T>& v) {
    h_ = fnv1aWords(std::string_view(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)),
                    h_);
  }
  // A plane: its length, then its bytes (an empty plane still counts).
  template <class T>
  void plane(const std::vector<T>& v) {
    word(v.size());
    bytes(v);
  }
  std::string hex() const { return fmt::format("{:016x}", h_); }

 private:
  std::uint64_t h_ = kFnv1aOffset;
};

}  // namespace

std::string colorDigest(const Frame& frame) {
  FrameHash h;
  h.word(static_cast<std::uint64_t>(frame.width) << 32 | static_cast<std::uint32_t>(frame.height));
  h.bytes(frame.color);
  return h.hex();
}

std::string frameDigest(const Frame& frame) {
  FrameHash h;
  h.word(static_cast<std::uint64_t>(frame.width) << 32 | static_cast<std::uint32_t>(frame.height));
  h.word(static_cast<std::uint64_t>(frame.samples));
  h.plane(frame.color);
  h.plane(frame.depth);
  h.plane(frame.id);
  h.plane(frame.stencil);
  h.plane(frame.sample_id);
  h.plane(frame.sample_depth);
  h.plane(frame.coverage);
  return h.hex();
}

std::uint64_t differingPixels(const Frame& a, const Frame& b, int* first_x, int* first_y) {
  if (a.width != b.width || a.height != b.height || a.samples != b.samples)
    throw InputError(fmt::format("frames of {}x{} and {}x{} cannot be compared pixel by pixel",
                                 a.width, a.height, b.width, b.height));
  auto same = [](const auto& x, const auto& y, std::size_t i, std::size_t n) {
    if (x.size() != y.size()) return false;
    if (x.empty()) return true;
    return std::memcmp(&x[i * n], &y[i * n], n * sizeof(x[0])) == 0;
  };
  std::uint64_t count = 0;
  *first_x = *first_y = -1;
  const std::size_t pixels = a.pixelCount();
  for (std::size_t i = 0; i < pixels; ++i) {
    bool equal = same(a.color, b.color, i, 4) && same(a.depth, b.depth, i, 1) &&
                 same(a.id, b.id, i, 1) && same(a.stencil, b.stencil, i, 1);
    for (int s = 0; equal && s < a.samples && a.samples > 1; ++s) {
      const std::size_t k = a.sampleIndex(s, i);
      equal = same(a.sample_id, b.sample_id, k, 1) && same(a.sample_depth, b.sample_depth, k, 1);
    }
    if (equal) continue;
    if (count++ == 0) {
      *first_x = static_cast<int>(i % static_cast<std::size_t>(a.width));
      *first_y = static_cast<int>(i / static_cast<std::size_t>(a.width));
    }
  }
  return count;
}

Rgb8 classColor(PixelClass c) { return pixelClassInfo(c).color; }

float heatPosition(float value, double scale) {
  if (!(value > 0.0f)) return 0.0f;  // zero and NaN
  const double t = std::log2(1.0 + value) / std::log2(1.0 + std::max(scale, 1e-12));
  return static_cast<float>(std::clamp(t, 0.0, 1.0));
}

// The colour maps kept in the user cache: a few hundred bytes each.
constexpr std::uintmax_t kUserColorMapCacheBytes = std::uintmax_t{1} << 20;

std::vector<Rgb8> colorStops(int count, const char* map) {
  count = std::max(count, 2);
  std::vector<float> ramp(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) ramp[i] = static_cast<float>(i) / static_cast<float>(count - 1);
  // OpenImageIO's map, kept in the user cache (fixtures/shared_cache.h) under the image
  // module that made it: report.html's legend would otherwise load the image library at the
  // end of every run.
  const std::filesystem::path user = userCacheDir();
  const std::string key =
      fmt::format("rastercheck color map 1|{}|{}|{}", image_io::moduleIdentity(), map, count);
  std::vector<float> rgb;
  if (const std::optional<std::string> bytes =
          user.empty() ? std::nullopt : readSharedEntry(user, key, "rcmap");
      bytes && bytes->size() == ramp.size() * 3 * sizeof(float)) {
    rgb.resize(ramp.size() * 3);
    std::memcpy(rgb.data(), bytes->data(), bytes->size());
  } else {
    rgb = image_io::functions().color_map(ramp, map);
    if (!user.empty() && rgb.size() == ramp.size() * 3)
      writeUserEntry(
          user, key, "rcmap",
          std::string_view(reinterpret_cast<const char*>(rgb.data()), rgb.size() * sizeof(float)),
          kUserColorMapCacheBytes);
  }
  std::vector<Rgb8> stops(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c)
      stops[i][c] =
          static_cast<std::uint8_t>(std::lround(std::clamp(rgb[i * 3 + c], 0.0f, 1.0f) * 255.0f));
  return stops;
}

std::vector<Rgb8> heatColorStops(int count) { return colorStops(count, kHeatColorMap); }

void setHeatScales(PairResult& result) {
  result.depth_heat_scale = std::max({result.depth.max_steps, result.tolerances.depth.fail, 1.0});
  result.shading_heat_scale =
      std::max({result.shading.max_abs, result.tolerances.shading.fail, 1.0});
}

void writePairImages(const Frame& expected, const Frame& actual, const ClassMaps& maps,
                     const fs::path& dir, PairResult& result, const PairPictures& pictures,
                     bool with_diff_exr) {
  const int w = maps.width;
  const int h = maps.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  if (w <= 0 || h <= 0 || expected.width != w || expected.height != h || actual.width != w ||
      actual.height != h || maps.pixel_class.size() != n || maps.depth_steps.size() != n ||
      maps.depth_tolerance.size() != n || maps.shading_abs.size() != n ||
      maps.shading_tolerance.size() != n)
    throw InputError(fmt::format("{}: class maps do not match the frames ({}x{})", dir.string(),
                                 expected.width, expected.height));

  AtomicFileSet files;
  const fs::path expected_png = dir / "expected.png";
  const fs::path actual_png = dir / "actual.png";
  const fs::path visibility_png = dir / "visibility.png";
  const fs::path depth_png = dir / "depth_heat.png";
  const fs::path shading_png = dir / "shading_heat.png";
  const fs::path diff_exr = dir / "diff.exr";
  // Staged names first (stage() is not thread-safe), then every file in parallel.
  const fs::path tmp_expected = files.stage(expected_png);
  const fs::path tmp_actual = files.stage(actual_png);
  const fs::path tmp_visibility = files.stage(visibility_png);
  const fs::path tmp_depth = files.stage(depth_png);
  const fs::path tmp_shading = files.stage(shading_png);
  const fs::path tmp_diff = with_diff_exr ? files.stage(diff_exr) : fs::path();
  setHeatScales(result);
  heatLut();  // built once, before the threads that share it

  runAll({
      [&] { writePicture(expected, pictures.expected, tmp_expected); },
      [&] { writePicture(actual, pictures.actual, tmp_actual); },
      [&] {
        // Visibility: classes in colour over a dim copy of the expected image for context.
        std::vector<std::uint8_t> vis(n * 3);
        for (std::size_t i = 0; i < n; ++i) {
          Rgb8 px = classColor(maps.pixel_class[i]);
          if (maps.pixel_class[i] == PixelClass::Match) {
            const std::uint8_t g = toByte(48.0f + 96.0f * luminance(&expected.color[i * 4]));
            px = {g, g, g};
          }
          std::copy(px.begin(), px.end(), vis.begin() + static_cast<std::ptrdiff_t>(i * 3));
        }
        writeRgb8(tmp_visibility, w, h, vis, visibility_png);
      },
      [&] {
        writeRgb8(tmp_depth, w, h, heatImage(maps, maps.depth_steps, result.depth_heat_scale),
                  depth_png);
      },
      [&] {
        writeRgb8(tmp_shading, w, h, heatImage(maps, maps.shading_abs, result.shading_heat_scale),
                  shading_png);
      },
      [&] {
        if (with_diff_exr) writeDiffExr(expected, actual, maps, result, tmp_diff, diff_exr);
      },
  });

  // LDR-FLIP's heat map (compare/flip.h), when the comparison computed FLIP.
  const fs::path flip_png = dir / "flip_heat.png";
  if (maps.flip.size() == n)
    writeRgb8(files.stage(flip_png), w, h, flipHeatRgb(maps.flip), flip_png);

  files.commit();
  result.images = pairImageNames(dir, with_diff_exr, maps);
}

std::map<std::string, fs::path> pairImageNames(const fs::path& dir, bool with_diff_exr,
                                               const ClassMaps& maps) {
  std::map<std::string, fs::path> names = {{"expected", dir / "expected.png"},
                                           {"actual", dir / "actual.png"},
                                           {"visibility", dir / "visibility.png"},
                                           {"depth_heat", dir / "depth_heat.png"},
                                           {"shading_heat", dir / "shading_heat.png"}};
  if (with_diff_exr) names["diff_exr"] = dir / "diff.exr";
  if (!maps.flip.empty() && maps.flip.size() == maps.pixel_class.size())
    names["flip_heat"] = dir / "flip_heat.png";
  return names;
}

fs::path pairDirectory(const fs::path& out_dir, const PairResult& result) {
  return out_dir / "pairs" / fixtureFolderName(result) / pairFolderName(result);
}

fs::path PairFolders::take(const fs::path& out_dir, const PairResult& result) {
  auto [slot, fresh] = fixture_folder_.try_emplace(result.fixture);
  if (fresh) {
    const std::string wanted = fixtureFolderName(result);
    std::string name = wanted;
    for (int k = 2; !fixture_folders_taken_.insert(name).second; ++k)
      name = fmt::format("{}~{}", wanted, k);
    slot->second = name;
  }
  const std::string wanted = pairFolderName(result);
  std::string name = wanted;
  for (int k = 2; !pair_folders_taken_.insert(slot->second + "/" + name).second; ++k)
    name = fmt::format("{}~{}", wanted, k);
  return out_dir / "pairs" / slot->second / name;
}

}  // namespace rc
