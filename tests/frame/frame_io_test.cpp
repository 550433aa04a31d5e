// Frame directories: exact round trip of every channel (ids as real uint32, not float),
// the EXR's channel names and types as DESIGN.md fixes them, and all-or-nothing writes.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "fixtures/errors.h"
#include "fixtures/frame_io.h"

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
  return f;
}

}  // namespace

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
    fs::remove_all(dir);
  }
}

TEST(FrameIo, ExrHasTheContractChannelsAndTypes) {
  const fs::path dir = tempDir("chan");
  rc::writeFrameDir(makeFrame(true), dir);
  auto in = OIIO::ImageInput::open((dir / "frame.exr").string());
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  const std::vector<std::string> want = {"R", "G", "B", "A", "Z", "id", "edge_dist", "depth_gap"};
  ASSERT_EQ(spec.nchannels, static_cast<int>(want.size()));
  for (const std::string& name : want) {
    const int c = spec.channelindex(name);
    ASSERT_GE(c, 0) << name;
    const OIIO::TypeDesc t = spec.channelformat(c);
    EXPECT_EQ(t, name == "id" ? OIIO::TypeDesc::UINT32 : OIIO::TypeDesc::FLOAT) << name;
  }
  // Top row first: pixel (6, 4) is the bottom-right one and holds the max id.
  std::vector<std::uint32_t> ids(spec.width * spec.height);
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
