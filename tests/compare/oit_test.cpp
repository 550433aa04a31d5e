// The report's "oit" block (compare/oit.h) on hand-made frames: only against an A-buffer
// frame, colour error over every pixel, the reference's out-of-order pairs passed through.
#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/oit.h"

namespace rc {
namespace {

Frame frame(bool abuffer) {
  Frame f;
  const float clear[4] = {0.5f, 0.5f, 0.5f, 1.0f};
  f.allocate(4, 2, clear, 1.0f, abuffer);
  if (abuffer) {
    f.meta["abuffer"] = {
        {"unsorted_pixels", 1},
        {"out_of_order_pairs", 1},
        {"out_of_order", {{{"near", 3}, {"far", 5}, {"pixels", 1}, {"first", {2, 1}}}}}};
    f.blend_count[f.index(2, 1)] = 2.0f;
    f.blend_count[f.index(3, 1)] = 1.0f;
  }
  return f;
}

TEST(Oit, OnlyAgainstAnABufferFrame) {
  Tolerances t;
  EXPECT_FALSE(compareOit(frame(false), frame(false), t).has_value());
  EXPECT_TRUE(compareOit(frame(true), frame(false), t).has_value());
}

TEST(Oit, CountsColourErrorAtEveryPixel) {
  Tolerances t;
  t.shading.warn = 1.0;
  const Frame e = frame(true);
  Frame a = frame(false);
  a.color[4 * a.index(2, 1) + 1] += 10.0f / 255.0f;  // a blended pixel, 10 units
  a.color[4 * a.index(0, 0)] += 0.5f / 255.0f;       // under the threshold
  a.id[a.index(2, 1)] = 7;                           // whatever the visibility class
  const OitStats s = *compareOit(e, a, t);
  EXPECT_EQ(s.blended_pixels, 2u);
  EXPECT_EQ(s.unsorted_pixels, 1u);
  EXPECT_EQ(s.pixels, 1u);
  EXPECT_NEAR(s.max_abs, 10.0, 1e-4);
  EXPECT_NEAR(s.mean_abs, 5.0, 1e-4);  // (10 + 0) / 2 blended pixels
  EXPECT_EQ(s.worst_x, 2);
  EXPECT_EQ(s.worst_y, 1);
  ASSERT_EQ(s.out_of_order.size(), 1u);
  EXPECT_EQ(s.out_of_order[0].near_id, 3u);
  EXPECT_EQ(s.out_of_order[0].far_id, 5u);
  const nlohmann::json j = oitJson(s, 2);
  EXPECT_EQ(j["worst_window"], nlohmann::json::array({2, 0}));
  EXPECT_EQ(j["out_of_order"][0]["first"], nlohmann::json::array({2, 1}));
  // compareFrames carries it in the pair result.
  const PairResult r = compareFrames(e, a, e, t);
  ASSERT_TRUE(r.oit.has_value());
  EXPECT_EQ(r.oit->pixels, 1u);
  EXPECT_FALSE(r.flip.has_value());  // no maps, no threshold: FLIP not computed
}

}  // namespace
}  // namespace rc
