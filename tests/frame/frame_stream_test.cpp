// Frames through the worker pipe format (fixtures/frame_stream.h): every buffer and the
// meta come back bit for bit, with and without the reference's channels, and damaged
// bytes are refused with an InputError instead of a wrong frame.
#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "fixtures/errors.h"
#include "fixtures/frame_stream.h"

namespace rc {
namespace {

Frame sample(bool uncertainty) {
  Frame f;
  const float clear[4] = {0.1f, 0.2f, 0.3f, 1.0f};
  f.allocate(7, 5, clear, 1.0f, uncertainty);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    f.color[i * 4] = static_cast<float>(i) / 3.0f;
    f.depth[i] = static_cast<float>(i) * 1e-3f;
    f.id[i] = static_cast<std::uint32_t>(i * 7919u);
    if (uncertainty) {
      // A different value in every channel, so that a swapped or dropped one shows.
      const auto channels = f.uncertainty();
      for (int c = 0; c < kUncertaintyChannels; ++c)
        (*channels[c])[i] = static_cast<float>(i % 3) / 4.0f + static_cast<float>(c);
      f.depth_gap[i] = i == 3 ? std::numeric_limits<float>::infinity() : static_cast<float>(i);
    }
  }
  f.color[5] = std::numeric_limits<float>::quiet_NaN();
  f.meta = {{"backend", "gl:egl:llvmpipe"}, {"fixture", "a/b"}, {"time_ms", 1.25}};
  f.drawn.depth_format = DepthFormat::D16;
  f.drawn.color_format = ColorFormat::RGBA8;
  f.drawn.texture_filter = TextureFilter::Linear;
  f.drawn.textured = true;
  return f;
}

// Empty buffers (a frame without uncertainty or samples) have no data() to compare: memcmp
// of a null pointer is undefined even for 0 bytes (the asan-ubsan build stops there).
bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

TEST(FrameStream, RoundTripsEveryBufferBitForBit) {
  for (const bool uncertainty : {false, true}) {
    const Frame in = sample(uncertainty);
    const Frame out = decodeFrame(encodeFrame(in));
    EXPECT_EQ(out.width, in.width);
    EXPECT_EQ(out.height, in.height);
    EXPECT_TRUE(sameBits(out.color, in.color));
    EXPECT_TRUE(sameBits(out.depth, in.depth));
    EXPECT_EQ(out.id, in.id);
    for (int c = 0; c < kUncertaintyChannels; ++c)
      EXPECT_TRUE(sameBits(*out.uncertainty()[c], *in.uncertainty()[c]))
          << kUncertaintyChannelInfo[c].name;
    EXPECT_EQ(out.hasUncertainty(), uncertainty);
    EXPECT_EQ(out.meta, in.meta);
    EXPECT_EQ(out.drawn, in.drawn);  // the formats and texture facts travel too
  }
}

// Multisampled frames: the per-sample planes and coverage (GL), plus the reference's
// per-sample edge_dist and sample_alt, come back bit for bit.
TEST(FrameStream, RoundTripsMultisampledFrames) {
  for (const bool uncertainty : {false, true}) {
    Frame in = sample(uncertainty);
    in.samples = 4;
    const std::size_t n = in.pixelCount();
    for (std::size_t k = 0; k < 4 * n; ++k) {
      in.sample_id.push_back(static_cast<std::uint32_t>(k * 31u));
      in.sample_depth.push_back(static_cast<float>(k) * 1e-4f);
      if (uncertainty) in.sample_edge_dist.push_back(static_cast<float>(k % 9) / 8.0f);
    }
    in.coverage.assign(n, 3.0f);
    if (uncertainty) in.sample_alt.assign(n, 7.5f);
    const Frame out = decodeFrame(encodeFrame(in));
    EXPECT_EQ(out.samples, 4);
    EXPECT_EQ(out.sample_id, in.sample_id);
    EXPECT_TRUE(sameBits(out.sample_depth, in.sample_depth));
    EXPECT_TRUE(sameBits(out.coverage, in.coverage));
    EXPECT_TRUE(sameBits(out.sample_edge_dist, in.sample_edge_dist));
    EXPECT_TRUE(sameBits(out.sample_alt, in.sample_alt));
    EXPECT_EQ(out.id, in.id);
  }
}

// A plane whose elements are all the same is sent as one element: it comes back whole, bit
// for bit (a NaN, a negative zero, +inf), and a plane that differs in its last element only
// is not taken for one.
TEST(FrameStream, ConstantPlanesTravelAsOneElementAndComeBackWhole) {
  Frame in = sample(true);
  const std::size_t n = in.pixelCount();
  const auto channels = in.uncertainty();
  channels[0]->assign(n, 0.0f);
  channels[1]->assign(n, -0.0f);
  channels[2]->assign(n, std::numeric_limits<float>::quiet_NaN());
  channels[3]->assign(n, std::numeric_limits<float>::infinity());
  channels[4]->assign(n, 2.5f);
  channels[4]->back() = 2.25f;
  in.id.assign(n, 42u);
  const std::string constant = encodeFrame(in);
  const Frame out = decodeFrame(constant);
  for (int c = 0; c < kUncertaintyChannels; ++c)
    EXPECT_TRUE(sameBits(*out.uncertainty()[c], *in.uncertainty()[c]))
        << kUncertaintyChannelInfo[c].name;
  EXPECT_EQ(out.id, in.id);
  EXPECT_TRUE(std::signbit((*out.uncertainty()[1])[n - 1]));
  // Four channels and the ids sent as one element each (and its count): that many fewer bytes.
  EXPECT_EQ(constant.size() + 5 * (n - 1) * sizeof(float) - 5 * sizeof(std::uint64_t),
            encodeFrame(sample(true)).size());
  // A constant plane that claims another size is refused.
  std::string marker = "c";
  const std::uint64_t count = n;
  marker.append(reinterpret_cast<const char*>(&count), sizeof count);
  const std::size_t at = constant.find(marker);
  ASSERT_NE(at, std::string::npos);
  std::string damaged = constant;
  damaged[at + 1] = static_cast<char>(damaged[at + 1] + 1);
  EXPECT_THROW(decodeFrame(damaged), InputError);
}

TEST(FrameStream, DamagedBytesAreRefused) {
  const std::string good = encodeFrame(sample(true));
  EXPECT_THROW(decodeFrame(good.substr(0, good.size() - 1)), InputError);
  EXPECT_THROW(decodeFrame(good + "x"), InputError);
  EXPECT_THROW(decodeFrame("RCF1" + good.substr(4)), InputError);  // older layouts
  EXPECT_THROW(decodeFrame("RCF2" + good.substr(4)), InputError);
  EXPECT_THROW(decodeFrame("RCF3" + good.substr(4)), InputError);
  EXPECT_THROW(decodeFrame(""), InputError);
  std::string huge = good;
  const std::uint32_t big = 1u << 20;
  std::memcpy(huge.data() + 4, &big, sizeof big);  // width
  EXPECT_THROW(decodeFrame(huge), InputError);
}

}  // namespace
}  // namespace rc
