// Frame directories: exact round trip of every channel (ids as real uint32, not float),
// the EXR's channel names and types as DESIGN.md fixes them, byte-identical files, and
// all-or-nothing writes (also when a rename fails midway).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Imath/half.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/output_folder.h"

namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
  fs::path p =
      fs::temp_directory_path() / ("rc_frame_io_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

rc::Frame makeFrame(bool uncertainty) {
  rc::Frame f;
  const float clear[4] = {0.f, 0.f, 0.f, 0.f};
  f.allocate(7, 5, clear, 1.0f, uncertainty);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const std::size_t i = f.index(x, y);
      f.color[i * 4 + 0] = 0.1f * x;
      f.color[i * 4 + 1] = -0.25f * y;  // floats outside [0,1] must survive
      f.color[i * 4 + 2] = 1.5f + x * y;
      f.color[i * 4 + 3] = 0.5f;
      f.depth[i] = 1.0f / (1 + x + y);
      // 16777217 and 2^32-1 are not representable as float: proves a uint32 channel.
      f.id[i] = (x == 6 && y == 4) ? 0xFFFFFFFFu : 16777217u + static_cast<std::uint32_t>(i);
      if (uncertainty) {
        f.edge_dist[i] = 0.125f * x;
        f.depth_gap[i] = y == 0 ? std::numeric_limits<float>::infinity() : 3.0f * y;
      }
    }
  }
  f.color[0] = std::numeric_limits<float>::quiet_NaN();
  f.meta = {{"backend", "ref"}, {"subpixel_bits", 8}};
  f.drawn.depth_format = rc::DepthFormat::D16;
  f.drawn.color_format = rc::ColorFormat::RGBA8;
  f.drawn.texture_filter = rc::TextureFilter::Nearest;
  f.drawn.textured = true;
  return f;
}

nlohmann::json readJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace

// The clear values in every plane (a frame that had others first: kept storage must not
// show through), and no depth plane when the caller writes it (the reference renderer).
TEST(FrameIo, AllocateWritesTheClearValues) {
  rc::Frame f = makeFrame(true);
  const float clear[4] = {0.25f, 0.5f, -0.0f, 1.0f};
  f.allocate(3, 2, clear, 0.75f, true);
  ASSERT_EQ(f.color.size(), 24u);
  for (std::size_t i = 0; i < f.color.size(); ++i)
    EXPECT_EQ(std::bit_cast<std::uint32_t>(f.color[i]), std::bit_cast<std::uint32_t>(clear[i % 4]));
  EXPECT_EQ(f.depth, std::vector<float>(6, 0.75f));
  EXPECT_EQ(f.id, std::vector<std::uint32_t>(6, 0u));
  EXPECT_EQ(f.edge_dist.size(), 6u);
  f.allocate(3, 2, clear, std::nullopt, false);
  EXPECT_TRUE(f.depth.empty());
  EXPECT_EQ(f.color.size(), 24u);
  EXPECT_FALSE(f.hasUncertainty());
}

TEST(FrameIo, RoundTripsEveryChannelExactly) {
  for (bool unc : {false, true}) {
    const fs::path dir = tempDir(unc ? "unc" : "plain");
    const rc::Frame in = makeFrame(unc);
    rc::writeFrameDir(in, dir);
    ASSERT_TRUE(fs::exists(dir / "frame.exr"));
    ASSERT_TRUE(fs::exists(dir / "color.png"));
    ASSERT_TRUE(fs::exists(dir / "frame.json"));
    const rc::Frame out = rc::readFrameDir(dir);
    ASSERT_EQ(out.width, in.width);
    ASSERT_EQ(out.height, in.height);
    EXPECT_TRUE(std::isnan(out.color[0]));
    for (std::size_t i = 1; i < in.color.size(); ++i) EXPECT_EQ(out.color[i], in.color[i]) << i;
    EXPECT_EQ(out.depth, in.depth);
    EXPECT_EQ(out.id, in.id);
    EXPECT_EQ(out.edge_dist, in.edge_dist);
    EXPECT_EQ(out.depth_gap, in.depth_gap);
    EXPECT_EQ(out.hasUncertainty(), unc);
    EXPECT_EQ(out.meta, in.meta);
    EXPECT_EQ(out.drawn, in.drawn);
    fs::remove_all(dir);
  }
}

TEST(FrameIo, ExrHasTheContractChannelsAndTypes) {
  const fs::path dir = tempDir("chan");
  rc::writeFrameDir(makeFrame(true), dir);
  auto in = OIIO::ImageInput::open((dir / "frame.exr").string());
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  // The contract's colour, depth and id channels, then every uncertainty channel by name.
  std::vector<std::string> want = {"R", "G", "B", "A", "Z", "id"};
  for (const rc::UncertaintyChannelInfo& info : rc::kUncertaintyChannelInfo)
    want.emplace_back(info.name);
  ASSERT_EQ(want.size(), 23u);
  ASSERT_EQ(spec.nchannels, static_cast<int>(want.size()));
  for (const std::string& name : want) {
    const int c = spec.channelindex(name);
    ASSERT_GE(c, 0) << name;
    const OIIO::TypeDesc t = spec.channelformat(c);
    EXPECT_EQ(t, name == "id" ? OIIO::TypeDesc::UINT32 : OIIO::TypeDesc::FLOAT) << name;
  }
  // Top row first: pixel (6, 4) is the bottom-right one and holds the max id.
  std::vector<std::uint32_t> ids(static_cast<std::size_t>(spec.width) * spec.height);
  const int idc = spec.channelindex("id");
  ASSERT_TRUE(in->read_image(0, 0, idc, idc + 1, OIIO::TypeDesc::UINT32, ids.data()));
  EXPECT_EQ(ids[4 * 7 + 6], 0xFFFFFFFFu);
  fs::remove_all(dir);
}

TEST(FrameIo, FailedWriteLeavesNothingBehind) {
  const fs::path base = tempDir("fail");
  fs::create_directories(base);
  // A frame whose buffers do not match its size cannot be written...
  rc::Frame bad = makeFrame(false);
  bad.depth.pop_back();
  EXPECT_THROW(rc::writeFrameDir(bad, base / "out"), rc::InputError);
  // ...and neither the target nor any temporary folder may remain.
  EXPECT_TRUE(fs::is_empty(base));
  fs::remove_all(base);
}

TEST(FrameIo, ReadingSomethingElseIsAnInputError) {
  const fs::path dir = tempDir("missing");
  EXPECT_THROW(rc::readFrameDir(dir), rc::InputError);
  fs::create_directories(dir);
  EXPECT_THROW(rc::readFrameDir(dir), rc::InputError);  // no frame.exr
  fs::remove_all(dir);
}

namespace {

std::string fileBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every entry of the directory that holds `dir` that is its staging folder
// (".rastercheck-staging." + dir's name) or an earlier version's temporary sibling.
std::vector<std::string> tempSiblings(const fs::path& dir) {
  std::vector<std::string> out;
  const std::string prefix = "." + dir.filename().string();
  for (const auto& e : fs::directory_iterator(dir.parent_path())) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0 || name.rfind(".rastercheck-staging" + prefix, 0) == 0)
      out.push_back(name);
  }
  return out;
}

rc::Frame otherFrame() {
  rc::Frame f = makeFrame(false);
  for (float& c : f.color) c = 0.75f;
  for (std::uint32_t& i : f.id) i = 7;
  f.meta = {{"backend", "new"}};
  return f;
}

}  // namespace

TEST(FrameIo, FilesAreByteIdenticalAndCarryNoTimeStamp) {
  const fs::path a = tempDir("det_a"), b = tempDir("det_b");
  rc::writeFrameDir(makeFrame(true), a);
  rc::writeFrameDir(makeFrame(true), b);
  for (const char* name : {"frame.exr", "color.png", "frame.json"})
    EXPECT_EQ(fileBytes(a / name), fileBytes(b / name)) << name;
  // Writes within one second would agree even with a time stamp: check the header too.
  auto in = OIIO::ImageInput::open((a / "frame.exr").string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("DateTime"), "");
  fs::remove_all(a);
  fs::remove_all(b);
}

// Encoded frames are kept in the user cache (fixtures/shared_cache.h) under their planes:
// a later write of the same frame copies frame.exr and color.png from there (an entry
// changed on disk shows), the files are the encoder's own bytes, and a frame that differs
// in one uncertainty value is another key, encoded again.
TEST(FrameIo, TheUserCacheServesAFrameEncodedBefore) {
  const fs::path dir = tempDir("user_cache");
  const fs::path user = dir / "user";
  ::setenv("RASTERCHECK_CACHE_DIR", user.c_str(), 1);
  const rc::Frame f = makeFrame(true);
  rc::writeFrameDir(f, dir / "a");
  auto entries = [&](const std::string& ext) {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(user))
      if (e.path().extension() == ext) out.push_back(e.path());
    return out;
  };
  const std::vector<fs::path> exr = entries(".rcexr");
  ASSERT_EQ(exr.size(), 1u);
  ASSERT_EQ(entries(".rcpng").size(), 1u);
  ::setenv("RASTERCHECK_CACHE_DISABLE", "1", 1);
  rc::writeFrameDir(f, dir / "plain");
  ::unsetenv("RASTERCHECK_CACHE_DISABLE");
  for (const char* name : {"frame.exr", "color.png"})
    EXPECT_EQ(fileBytes(dir / "a" / name), fileBytes(dir / "plain" / name)) << name;

  // Served from the entry: its last byte changed there is the file's last byte.
  std::string entry = fileBytes(exr[0]);
  const std::string original = entry;
  entry.back() = static_cast<char>(entry.back() ^ 0x5a);
  std::ofstream(exr[0], std::ios::binary | std::ios::trunc) << entry;
  rc::writeFrameDir(f, dir / "b");
  EXPECT_EQ(fileBytes(dir / "b" / "frame.exr").back(), entry.back());
  EXPECT_EQ(fileBytes(dir / "b" / "color.png"), fileBytes(dir / "a" / "color.png"));
  // An entry cut short is not served: the encoder's bytes again.
  std::ofstream(exr[0], std::ios::binary | std::ios::trunc)
      << original.substr(0, original.size() - 1);
  rc::writeFrameDir(f, dir / "cut");
  EXPECT_EQ(fileBytes(dir / "cut" / "frame.exr"), fileBytes(dir / "plain" / "frame.exr"));
  std::ofstream(exr[0], std::ios::binary | std::ios::trunc) << original;

  // One uncertainty value more: another key, the encoder's bytes.
  rc::Frame g = makeFrame(true);
  g.normal_reach[3] += 1.0f;
  rc::writeFrameDir(g, dir / "c");
  EXPECT_EQ(entries(".rcexr").size(), 2u);
  ::setenv("RASTERCHECK_CACHE_DISABLE", "1", 1);
  rc::writeFrameDir(g, dir / "c_plain");
  ::unsetenv("RASTERCHECK_CACHE_DISABLE");
  EXPECT_EQ(fileBytes(dir / "c" / "frame.exr"), fileBytes(dir / "c_plain" / "frame.exr"));
  EXPECT_NE(fileBytes(dir / "c" / "frame.exr"), fileBytes(dir / "a" / "frame.exr"));
  EXPECT_EQ(rc::readFrameDir(dir / "c").normal_reach, g.normal_reach);
  ::unsetenv("RASTERCHECK_CACHE_DIR");
  fs::remove_all(dir);
}

TEST(FrameIo, EveryLosslessCompressionRoundTrips) {
  const rc::Frame in = makeFrame(true);
  const fs::path dir = tempDir("comp");
  fs::create_directories(dir);
  for (const char* compression : {"none", "rle", "zips", "zip", "zip:1", "piz"}) {
    rc::FrameEncoding enc;
    enc.exr_compression = compression;
    rc::writeFrameExr(in, dir / "f.exr", enc);
    const rc::Frame out = rc::readFrameExr(dir / "f.exr");
    EXPECT_TRUE(std::isnan(out.color[0])) << compression;
    EXPECT_TRUE(std::equal(in.color.begin() + 1, in.color.end(), out.color.begin() + 1))
        << compression;
    EXPECT_EQ(out.depth, in.depth) << compression;
    EXPECT_EQ(out.id, in.id) << compression;
    EXPECT_EQ(out.edge_dist, in.edge_dist) << compression;
    EXPECT_EQ(out.depth_gap, in.depth_gap) << compression;
  }
  fs::remove_all(dir);
}

// A file from another tool (half-float colour, channels in another order) takes the
// converting path and still reads.
TEST(FrameIo, ReadsOtherChannelEncodings) {
  const fs::path dir = tempDir("half");
  fs::create_directories(dir);
  const fs::path file = dir / "frame.exr";
  OIIO::ImageSpec spec(3, 2, 6, OIIO::TypeDesc::HALF);
  spec.channelnames = {"id", "Z", "A", "B", "G", "R"};
  spec.channelformats = {OIIO::TypeDesc::UINT32, OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::HALF,
                         OIIO::TypeDesc::HALF,   OIIO::TypeDesc::HALF,  OIIO::TypeDesc::HALF};
  // Native pixels: uint32 id, float Z, then four halves (16 bytes).
  std::vector<unsigned char> native(std::size_t{6} * 16);
  for (std::uint32_t i = 0; i < 6; ++i) {
    unsigned char* px = native.data() + std::size_t{i} * 16;
    const std::uint32_t id = i + 1;
    const float z = 0.5f;
    const Imath::half rgba[4] = {Imath::half(1.0f), Imath::half(0.25f), Imath::half(0.125f),
                                 Imath::half(2.0f)};  // A B G R
    std::memcpy(px, &id, 4);
    std::memcpy(px + 4, &z, 4);
    std::memcpy(px + 8, rgba, 8);
  }
  {
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out && out->open(file.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UNKNOWN, native.data()));
    ASSERT_TRUE(out->close());
  }
  const rc::Frame f = rc::readFrameExr(file);
  ASSERT_EQ(f.pixelCount(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(f.id[i], i + 1);
    EXPECT_EQ(f.depth[i], 0.5f);
    EXPECT_EQ(f.color[i * 4 + 0], 2.0f);
    EXPECT_EQ(f.color[i * 4 + 1], 0.125f);
    EXPECT_EQ(f.color[i * 4 + 2], 0.25f);
    EXPECT_EQ(f.color[i * 4 + 3], 1.0f);
  }
  fs::remove_all(dir);
}

// color.png: clamp to [0,1] (NaN as 0), scale by 255, round halves away from zero; the
// oracle is std::lround on the same float product.
TEST(FrameIo, PngRoundsLikeLround) {
  rc::Frame f;
  const float clear[4] = {0.f, 0.f, 0.f, 1.f};
  f.allocate(256, 64, clear, 1.0f, false);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> any(-0.25f, 1.25f);
  for (std::size_t i = 0; i < f.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) f.color[i * 4 + c] = any(rng);
  // Exact halves (k + 0.5 after the float multiply), the clamps and NaN.
  for (std::size_t k = 0; k < 255; ++k) f.color[k * 4] = (static_cast<float>(k) + 0.5f) / 255.0f;
  f.color[1] = std::numeric_limits<float>::quiet_NaN();
  f.color[5] = -std::numeric_limits<float>::infinity();
  f.color[9] = std::numeric_limits<float>::infinity();
  const fs::path dir = tempDir("png");
  fs::create_directories(dir);
  rc::writeColorPng(f, dir / "c.png");
  auto in = OIIO::ImageInput::open((dir / "c.png").string());
  ASSERT_TRUE(in);
  ASSERT_EQ(in->spec().nchannels, 3);
  std::vector<std::uint8_t> px(f.pixelCount() * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  int halves_up = 0;
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    for (int c = 0; c < 3; ++c) {
      float v = f.color[i * 4 + c];
      v = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
      const long want = std::lround(v * 255.0f);
      ASSERT_EQ(px[i * 3 + c], want)
          << "pixel " << i << " channel " << c << " value " << f.color[i * 4 + c];
      if (i < 255 && c == 0 && v * 255.0f == static_cast<float>(i) + 0.5f) ++halves_up;
    }
  }
  EXPECT_GT(halves_up, 100) << "the exact-half cases should mostly survive the float divide";
  fs::remove_all(dir);
}

TEST(FrameIo, ReplacesAFrameDirectoryWhole) {
  const fs::path dir = tempDir("swap");
  rc::writeFrameDir(makeFrame(true), dir);
  rc::writeFrameDir(otherFrame(), dir);
  const rc::Frame out = rc::readFrameDir(dir);
  EXPECT_EQ(out.meta, otherFrame().meta);
  EXPECT_EQ(out.id, otherFrame().id);
  EXPECT_FALSE(out.hasUncertainty());
  EXPECT_TRUE(tempSiblings(dir).empty());
  fs::remove_all(dir);
}

TEST(FrameIo, KeepsTheUsersOtherFiles) {
  const fs::path dir = tempDir("keep");
  rc::writeFrameDir(makeFrame(false), dir);
  std::ofstream(dir / "notes.txt") << "mine\n";
  rc::writeFrameDir(otherFrame(), dir);
  EXPECT_EQ(rc::readFrameDir(dir).meta, otherFrame().meta);
  EXPECT_EQ(fileBytes(dir / "notes.txt"), "mine\n");
  EXPECT_TRUE(tempSiblings(dir).empty());
  fs::remove_all(dir);
}

// Whichever rename fails, DIR keeps the complete old frame (byte for byte) and the
// user's other files, and no temporary directory is left.
TEST(FrameIo, FailedReplacementLeavesTheOldFrame) {
  for (bool with_other_file : {false, true}) {
    int injected = 0;  // budgets that did fail midway: with none, nothing was tested
    for (int budget = 0; budget < 6; ++budget) {
      const fs::path dir = tempDir("midway");
      rc::writeFrameDir(makeFrame(true), dir);
      if (with_other_file) std::ofstream(dir / "notes.txt") << "mine\n";
      std::vector<std::string> before;
      for (const char* name : {"frame.exr", "color.png", "frame.json"})
        before.push_back(fileBytes(dir / name));
      rc::testing::output_renames_before_failure = budget;
      bool threw = false;
      try {
        rc::writeFrameDir(otherFrame(), dir);
      } catch (const rc::InputError& e) {
        threw = true;
        EXPECT_NE(std::string(e.what()).find("injected rename failure"), std::string::npos);
      }
      rc::testing::output_renames_before_failure = -1;
      const std::string where =
          (with_other_file ? "per-file, " : "swap, ") + std::to_string(budget) + " renames allowed";
      EXPECT_TRUE(tempSiblings(dir).empty()) << where;
      if (!threw) {  // enough renames for the whole replacement
        EXPECT_EQ(rc::readFrameDir(dir).meta, otherFrame().meta) << where;
        fs::remove_all(dir);
        continue;
      }
      ++injected;
      int i = 0;
      for (const char* name : {"frame.exr", "color.png", "frame.json"})
        EXPECT_EQ(fileBytes(dir / name), before[i++]) << where << ": " << name;
      if (with_other_file) {
        EXPECT_EQ(fileBytes(dir / "notes.txt"), "mine\n") << where;
      }
      fs::remove_all(dir);
    }
    EXPECT_GT(injected, 0) << (with_other_file ? "per-file" : "swap");
  }
}

// Multisampled frames: coverage, the per-sample planes (ids as uint32) and, with the
// uncertainty channels, sample_alt and per-sample edge_dist survive the round trip; a GL
// frame (no uncertainty) has none of the reference's.
TEST(FrameIo, RoundTripsMultisampledFrames) {
  for (bool unc : {false, true}) {
    const fs::path dir = tempDir(unc ? "ms_unc" : "ms_plain");
    rc::Frame in = makeFrame(unc);
    in.samples = 4;
    const std::size_t n = in.pixelCount();
    for (std::size_t k = 0; k < 4 * n; ++k) {
      in.sample_id.push_back(16777217u + static_cast<std::uint32_t>(k));
      in.sample_depth.push_back(0.001f * static_cast<float>(k));
      if (unc) in.sample_edge_dist.push_back(0.01f * static_cast<float>(k % 100));
    }
    in.coverage.assign(n, 3.0f);
    if (unc) in.sample_alt.assign(n, 12.5f);
    rc::writeFrameDir(in, dir);
    auto spec_in = OIIO::ImageInput::open((dir / "frame.exr").string());
    ASSERT_TRUE(spec_in);
    const OIIO::ImageSpec& spec = spec_in->spec();
    const int id3 = spec.channelindex("s3.id");
    ASSERT_GE(id3, 0);
    EXPECT_EQ(spec.channelformat(id3), OIIO::TypeDesc::UINT32);
    EXPECT_EQ(spec.channelindex("s0.edge_dist") >= 0, unc);
    spec_in->close();
    const rc::Frame out = rc::readFrameDir(dir);
    EXPECT_EQ(out.samples, 4);
    EXPECT_EQ(out.sample_id, in.sample_id);
    EXPECT_EQ(out.sample_depth, in.sample_depth);
    EXPECT_EQ(out.coverage, in.coverage);
    EXPECT_EQ(out.sample_edge_dist, in.sample_edge_dist);
    EXPECT_EQ(out.sample_alt, in.sample_alt);
    fs::remove_all(dir);
  }
  rc::Frame bad = makeFrame(false);
  bad.samples = 4;  // planes missing
  EXPECT_THROW(rc::writeFrameDir(bad, tempDir("ms_bad")), rc::InputError);
}

// The typed facts are frame.json's contract keys (DESIGN.md: depth format beside the
// backend); a frame that does not say keeps them unset, and a wrong value is refused on
// reading with the file and the key.
// reserveFrame(): buffers sized from frame.json and the file's size; reading into them,
// whatever they hold, gives what reading without them gives.
TEST(FrameIo, ReservedBuffersChangeNothingThatIsRead) {
  const fs::path dir = tempDir("reserve");
  rc::Frame in = makeFrame(true);
  in.meta["width"] = in.width;  // as `render` writes them (app/backends.cpp)
  in.meta["height"] = in.height;
  rc::writeFrameDir(in, dir);
  rc::Frame storage = rc::reserveFrame(dir);
  const std::size_t n = in.pixelCount();
  ASSERT_EQ(storage.color.size(), n * 4);
  ASSERT_EQ(storage.id.size(), n);
  ASSERT_EQ(storage.edge_dist.size(), n);  // an uncompressed file with every channel
  for (float& v : storage.color) v = 99.0f;
  for (std::uint32_t& v : storage.id) v = 99u;
  for (std::vector<float>* c : storage.uncertainty()) std::fill(c->begin(), c->end(), -7.0f);
  const float* reserved_color = storage.color.data();
  const rc::Frame plain = rc::readFrameDir(dir);
  const rc::Frame out = rc::readFrameDir(dir, std::move(storage));
  EXPECT_EQ(out.color.data(), reserved_color);  // the reserved buffer was used
  EXPECT_TRUE(std::isnan(out.color[0]));
  EXPECT_TRUE(std::equal(plain.color.begin() + 1, plain.color.end(), out.color.begin() + 1));
  EXPECT_EQ(out.depth, plain.depth);
  EXPECT_EQ(out.id, plain.id);
  for (int c = 0; c < rc::kUncertaintyChannels; ++c)
    EXPECT_EQ(*out.uncertainty()[c], *plain.uncertainty()[c]) << c;
  EXPECT_EQ(out.meta, plain.meta);

  // A frame without the uncertainty channels read into buffers that have them has none.
  rc::Frame gl = makeFrame(false);
  gl.meta = in.meta;
  rc::writeFrameDir(gl, dir);
  EXPECT_TRUE(rc::reserveFrame(dir).edge_dist.empty());  // the file is too small for them
  rc::Frame spare;
  const float clear[4] = {0.f, 0.f, 0.f, 0.f};
  spare.allocate(in.width, in.height, clear, 1.0f, true);
  const rc::Frame read_gl = rc::readFrameDir(dir, std::move(spare));
  EXPECT_FALSE(read_gl.hasUncertainty());
  EXPECT_EQ(read_gl.id, gl.id);
  // Buffers of another size are not used.
  rc::Frame small;
  small.allocate(2, 2, clear, 1.0f, true);
  EXPECT_EQ(rc::readFrameDir(dir, std::move(small)).id, gl.id);
  fs::remove_all(dir);
}

// A hint, never an error: anything unusable gives no buffers (the read says what is wrong).
TEST(FrameIo, ReserveFrameIsOnlyAHint) {
  const fs::path dir = tempDir("reserve_hint");
  EXPECT_TRUE(rc::reserveFrame(dir).color.empty());  // no directory
  rc::Frame in = makeFrame(true);
  in.meta["width"] = in.width;
  in.meta["height"] = in.height;
  rc::writeFrameDir(in, dir);
  ASSERT_FALSE(rc::reserveFrame(dir).color.empty());
  const nlohmann::json good = readJson(dir / "frame.json");
  const std::vector<std::pair<std::string, nlohmann::json>> bad = {
      {"width", 1 << 20}, {"height", 1 << 20},  // 2^40 pixels
      {"width", 70},      {"height", 50},       // more than the file holds
      {"width", -7},      {"height", 0},       {"width", "seven"}, {"height", 2.5}};
  for (const auto& [key, value] : bad) {
    nlohmann::json doc = good;
    doc[key] = value;
    std::ofstream(dir / "frame.json") << doc.dump();
    EXPECT_TRUE(rc::reserveFrame(dir).color.empty()) << key << " " << value.dump();
  }
  std::ofstream(dir / "frame.json") << "[1, 2";
  EXPECT_TRUE(rc::reserveFrame(dir).color.empty());
  std::ofstream(dir / "frame.json") << good.dump();
  // Over the comparison's memory limit (fixtures/resource_estimate.h).
  ::setenv("RASTERCHECK_MAX_MEMORY", "1K", 1);
  EXPECT_TRUE(rc::reserveFrame(dir).color.empty());
  ::unsetenv("RASTERCHECK_MAX_MEMORY");
  ASSERT_FALSE(rc::reserveFrame(dir).color.empty());
  fs::remove(dir / "frame.json");
  EXPECT_TRUE(rc::reserveFrame(dir).color.empty());

  // A compressed file is smaller than its pixels: how many channels it has is not known.
  rc::Frame flat;
  const float grey[4] = {0.5f, 0.5f, 0.5f, 1.0f};
  flat.allocate(256, 128, grey, 1.0f, true);
  flat.meta = {{"width", 256}, {"height", 128}};
  rc::writeFrameDir(flat, dir, rc::FrameEncoding{"zip", 1, 8});
  EXPECT_TRUE(rc::reserveFrame(dir).color.empty());
  rc::writeFrameDir(flat, dir);
  EXPECT_EQ(rc::reserveFrame(dir).edge_dist.size(), flat.pixelCount());
  fs::remove_all(dir);
}

TEST(FrameIo, DrawFactsAreFrameJsonKeys) {
  const fs::path dir = tempDir("facts");
  rc::writeFrameDir(makeFrame(false), dir);
  nlohmann::json doc = readJson(dir / "frame.json");
  EXPECT_EQ(doc["depth_format"], "d16");
  EXPECT_EQ(doc["color_format"], "rgba8");
  EXPECT_EQ(doc["texture_filter"], "nearest");
  EXPECT_EQ(doc["textured"], true);
  EXPECT_EQ(doc["backend"], "ref");
  // Read back, they are typed, not left in meta as strings.
  const rc::Frame read = rc::readFrameDir(dir);
  EXPECT_FALSE(read.meta.contains("depth_format"));
  EXPECT_EQ(read.drawn.depth_format, rc::DepthFormat::D16);

  rc::Frame unsaid = makeFrame(false);
  unsaid.drawn = {};
  rc::writeFrameDir(unsaid, dir);
  doc = readJson(dir / "frame.json");
  for (const char* key : {"depth_format", "color_format", "texture_filter", "textured"})
    EXPECT_FALSE(doc.contains(key)) << key;
  EXPECT_EQ(rc::readFrameDir(dir).drawn, rc::DrawFacts{});

  const std::pair<const char*, nlohmann::json> bad[] = {{"depth_format", "d99"},
                                                        {"depth_format", 16},
                                                        {"color_format", "rgb8"},
                                                        {"texture_filter", "cubic"},
                                                        {"textured", "yes"}};
  for (const auto& [key, value] : bad) {
    doc[key] = value;
    std::ofstream(dir / "frame.json") << doc.dump();
    try {
      (void)rc::readFrameDir(dir);
      ADD_FAILURE() << key << " = " << value.dump() << " was accepted";
    } catch (const rc::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find((dir / "frame.json").string()), std::string::npos) << what;
      EXPECT_NE(what.find(key), std::string::npos) << what;
    }
    doc.erase(key);
  }
  fs::remove_all(dir);
}
