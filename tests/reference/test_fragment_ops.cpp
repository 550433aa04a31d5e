// The general fragment operations against hand-computed answers: each depth function,
// depth writes, depth range, polygon offset, every stencil op and both faces, scissor,
// colour mask and every blend equation and factor. windowScene(): window depth = 1 - z.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures/fragment_state.h"
#include "reference/fragment_ops.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr int kW = 8;
constexpr int kH = 8;

ReferenceOptions plain() {
  ReferenceOptions o;
  o.uncertainty = false;
  return o;
}

std::uint32_t idAt(const Frame& f, int x, int y) { return f.id[f.index(x, y)]; }
glm::dvec4 colorAt(const Frame& f, int x, int y) {
  const float* c = &f.color[4 * f.index(x, y)];
  return glm::dvec4(c[0], c[1], c[2], c[3]);
}

// Two full-image rectangles: the first at window depth 0.4 (ids 1-2), the second at
// `second` (ids 3-4) with depth function `func`.
Scene twoRects(double second, CompareFunc func) {
  Scene s = test::windowScene(kW, kH);
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);
  const std::size_t b = test::addRect(s, -1, -1, kW + 1, kH + 1, static_cast<float>(1.0 - second));
  s.objects[b].state.depth_func = func;
  return s;
}

TEST(FragmentOps, EveryDepthFunctionAgainstTheStoredDepth) {
  for (CompareFunc f : kCompareFuncs) {
    for (double second : {0.3, 0.4, 0.6}) {
      const Frame frame = renderReference(twoRects(second, f), plain());
      const bool expect = compares(f, second, 0.4);
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
          ASSERT_EQ(idAt(frame, x, y) >= 3, expect)
              << toString(f) << " second at " << second << " pixel " << x << "," << y;
    }
  }
}

TEST(FragmentOps, DepthWritesOffLeaveTheClearDepth) {
  Scene s = twoRects(0.6, CompareFunc::Less);
  s.objects[0].state.depth_write = false;
  const Frame f = renderReference(s, plain());
  EXPECT_GE(idAt(f, 3, 3), 3u);  // the second wins: the first left the clear depth
  EXPECT_NEAR(f.depth[f.index(3, 3)], 0.6, 1e-7);  // only its depth was written
  s.objects[1].state.depth_write = false;
  const Frame g = renderReference(s, plain());
  EXPECT_EQ(g.depth[g.index(3, 3)], 1.0f);  // nothing wrote depth
  EXPECT_GE(idAt(g, 3, 3), 3u);
}

TEST(FragmentOps, DepthRangeMapsWindowDepth) {
  Scene s = test::windowScene(kW, kH);
  s.state.depth_format = DepthFormat::D32F;
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);  // window depth 0.4
  s.state.ops.depth_range = {0.5, 1.0};
  Frame f = renderReference(s, plain());
  EXPECT_NEAR(f.depth[f.index(2, 2)], 0.5 + 0.5 * 0.4, 1e-7);
  s.state.ops.depth_range = {1.0, 0.0};  // reversed: 1 - 0.4
  f = renderReference(s, plain());
  EXPECT_NEAR(f.depth[f.index(2, 2)], 0.6, 1e-7);
}

TEST(FragmentOps, PolygonOffsetUnitsAreStepsOfTheFormatAndFactorScalesTheSlope) {
  Scene s = test::windowScene(kW, kH);
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);  // window depth 0.4, slope 0
  s.state.ops.polygon_offset = PolygonOffset{3.0, -10.0};
  for (DepthFormat format : {DepthFormat::D16, DepthFormat::D24}) {
    s.state.depth_format = format;
    const double steps = ref::depthStepsPerUnit(format);
    const Frame f = renderReference(s, plain());
    const double q = std::round((0.4 - 10.0 / steps) * steps);  // the factor adds 0: m = 0
    EXPECT_EQ(std::round(f.depth[f.index(4, 4)] * steps), q) << toString(format);
  }
  // A plane whose depth rises 1/64 per pixel in x: m = 1/64, o = 2 * m (units 0).
  Scene t = test::windowScene(kW, kH);
  t.state.depth_format = DepthFormat::D32F;
  test::addTriangle(t, {-8, -8, 1.0f}, {56, -8, 0.0f}, {-8, 56, 1.0f});
  Frame base = renderReference(t, plain());
  t.state.ops.polygon_offset = PolygonOffset{2.0, 0.0};
  Frame offset = renderReference(t, plain());
  EXPECT_NEAR(offset.depth[offset.index(1, 6)] - base.depth[base.index(1, 6)], 2.0 / 64.0, 1e-6);
}

TEST(FragmentOps, EveryStencilOpOnTheStoredValue) {
  struct Case {
    StencilOp op;
    int before;
    int ref;
    std::uint32_t write_mask;
    int after;
  };
  const Case cases[] = {{StencilOp::Keep, 7, 3, 0xff, 7},
                        {StencilOp::Zero, 7, 3, 0xff, 0},
                        {StencilOp::Replace, 7, 3, 0xff, 3},
                        {StencilOp::Incr, 255, 0, 0xff, 255},
                        {StencilOp::Incr, 7, 0, 0xff, 8},
                        {StencilOp::IncrWrap, 255, 0, 0xff, 0},
                        {StencilOp::Decr, 0, 0, 0xff, 0},
                        {StencilOp::Decr, 7, 0, 0xff, 6},
                        {StencilOp::DecrWrap, 0, 0, 0xff, 255},
                        {StencilOp::Invert, 0x0f, 0, 0xff, 0xf0},
                        {StencilOp::Replace, 0xaa, 0x55, 0x0f, 0xa5}};
  for (const Case& c : cases) {
    Scene s = test::windowScene(kW, kH);
    s.state.stencil_format = StencilFormat::S8;
    s.clear_stencil = c.before;
    test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);
    StencilTest st;
    st.front.ref = c.ref;
    st.front.write_mask = c.write_mask;
    st.front.pass = c.op;
    st.back = st.front;
    s.state.ops.stencil = st;
    const Frame f = renderReference(s, plain());
    ASSERT_EQ(f.stencil.size(), f.pixelCount());
    EXPECT_EQ(f.stencil[f.index(3, 3)], static_cast<std::uint32_t>(c.after))
        << toString(c.op) << " on " << c.before;
  }
}

TEST(FragmentOps, StencilMaskThenMaskedDrawAndTheOpsOfEachOutcome) {
  Scene s = test::windowScene(kW, kH);
  s.state.stencil_format = StencilFormat::S8;
  // A mask over the left half (x < 4), no colour, no depth: stencil := 1.
  const std::size_t mask = test::addRect(s, -1, -1, 4, kH + 1, 0.9f);
  StencilTest write;
  write.front.ref = 1;
  write.front.pass = StencilOp::Replace;
  write.back = write.front;
  s.objects[mask].state.stencil = write;
  s.objects[mask].state.color_mask = std::array<bool, 4>{false, false, false, false};
  s.objects[mask].state.depth_write = false;
  // Then a full rectangle where the stencil equals 1; failing pixels invert, depth-failing
  // ones would zero, passing ones incr.
  const std::size_t full = test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);
  StencilTest test;
  test.front.func = CompareFunc::Equal;
  test.front.ref = 1;
  test.front.fail = StencilOp::Invert;
  test.front.depth_fail = StencilOp::Zero;
  test.front.pass = StencilOp::Incr;
  test.back = test.front;
  s.objects[full].state.stencil = test;
  const Frame f = renderReference(s, plain());
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const bool left = x < 4;
      // The mask writes its id (the colour mask is colour only), the full one over it.
      EXPECT_EQ(idAt(f, x, y) >= 3, left) << x << "," << y;
      EXPECT_EQ(f.stencil[f.index(x, y)], left ? 2u : 255u) << x << "," << y;
      EXPECT_EQ(f.color[4 * f.index(x, y)], left ? 1.0f : 0.0f);
    }
  }
}

TEST(FragmentOps, BackFacingTrianglesUseTheBackStencilState) {
  Scene s = test::windowScene(kW, kH);
  s.state.stencil_format = StencilFormat::S8;
  test::addTriangle(s, {-8, -8, 0.5f}, {24, -8, 0.5f}, {-8, 24, 0.5f});  // counter-clockwise
  test::addTriangle(s, {-8, -8, 0.5f}, {-8, 24, 0.5f}, {24, -8, 0.5f});  // clockwise
  s.state.ops.depth_func = CompareFunc::Always;  // the second, at the same depth, passes too
  StencilTest st;
  st.front.pass = StencilOp::Incr;
  st.back.pass = StencilOp::DecrWrap;
  s.state.ops.stencil = st;
  const Frame f = renderReference(s, plain());
  EXPECT_EQ(f.stencil[f.index(1, 6)], 0u);  // +1 then -1
  s.state.ops.stencil->back.pass = StencilOp::Incr;
  const Frame g = renderReference(s, plain());
  EXPECT_EQ(g.stencil[g.index(1, 6)], 2u);
}

TEST(FragmentOps, ScissorBoxInWindowCoordinates) {
  Scene s = test::windowScene(kW, kH);
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);
  s.state.ops.scissor = Scissor{2, 3, 5, 4};  // x 2..6, GL rows 3..6
  const Frame f = renderReference(s, plain());
  for (int y = 0; y < kH; ++y) {
    const int gl_row = kH - 1 - y;
    for (int x = 0; x < kW; ++x) {
      const bool inside = x >= 2 && x < 7 && gl_row >= 3 && gl_row < 7;
      EXPECT_EQ(idAt(f, x, y) != 0, inside) << x << "," << y;
    }
  }
}

TEST(FragmentOps, ColourMaskKeepsTheMaskedChannels) {
  Scene s = test::windowScene(kW, kH);
  s.clear_color = {0.25, 0.5, 0.75, 0.125};
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);  // white, alpha 1
  s.state.ops.color_mask = {true, false, true, false};
  const Frame f = renderReference(s, plain());
  EXPECT_EQ(colorAt(f, 1, 1), glm::dvec4(1.0, 0.5, 1.0, 0.125));
  EXPECT_NE(idAt(f, 1, 1), 0u);
}

TEST(FragmentOps, EveryBlendEquationAndFactor) {
  const glm::dvec4 src(0.75, 0.5, 0.25, 0.5);
  const glm::dvec4 dst(0.25, 0.125, 1.0, 0.75);
  const glm::dvec4 k(0.5, 0.25, 0.125, 0.25);
  auto factor = [&](BlendFactor f, int c) {
    switch (f) {
      case BlendFactor::Zero:
        return 0.0;
      case BlendFactor::One:
        return 1.0;
      case BlendFactor::SrcColor:
        return src[c];
      case BlendFactor::OneMinusSrcColor:
        return 1.0 - src[c];
      case BlendFactor::DstColor:
        return dst[c];
      case BlendFactor::OneMinusDstColor:
        return 1.0 - dst[c];
      case BlendFactor::SrcAlpha:
        return src.a;
      case BlendFactor::OneMinusSrcAlpha:
        return 1.0 - src.a;
      case BlendFactor::DstAlpha:
        return dst.a;
      case BlendFactor::OneMinusDstAlpha:
        return 1.0 - dst.a;
      case BlendFactor::ConstantColor:
        return k[c];
      case BlendFactor::OneMinusConstantColor:
        return 1.0 - k[c];
      case BlendFactor::ConstantAlpha:
        return k.a;
      case BlendFactor::OneMinusConstantAlpha:
        return 1.0 - k.a;
      case BlendFactor::SrcAlphaSaturate:
        return c == 3 ? 1.0 : 0.25;  // min(0.5, 1 - 0.75)
    }
    return -1.0;
  };
  for (BlendEquation e : kBlendEquations) {
    for (BlendFactor fs : kBlendFactors) {
      BlendFunction b;
      b.equation = b.equation_alpha = e;
      b.src = b.src_alpha = fs;
      b.dst = b.dst_alpha = BlendFactor::OneMinusSrcColor;
      b.constant = k;
      const glm::dvec4 out = ref::blendWithFunction(b, src, dst, ColorFormat::RGBA32F);
      for (int c = 0; c < 4; ++c) {
        const double s = src[c] * factor(fs, c);
        const double d = dst[c] * factor(b.dst, c);
        const double want = e == BlendEquation::Add               ? s + d
                            : e == BlendEquation::Subtract        ? s - d
                            : e == BlendEquation::ReverseSubtract ? d - s
                            : e == BlendEquation::Min             ? std::min(src[c], dst[c])
                                                                  : std::max(src[c], dst[c]);
        EXPECT_DOUBLE_EQ(out[c], want) << toString(e) << " " << toString(fs) << " channel " << c;
      }
    }
  }
  // rgba8 clamps the source first; rgba32f keeps it (and a negative result).
  BlendFunction sub;
  sub.equation = sub.equation_alpha = BlendEquation::Subtract;
  sub.dst = sub.dst_alpha = BlendFactor::One;
  const glm::dvec4 big(2.0, 0.0, 0.0, 1.0);
  EXPECT_DOUBLE_EQ(ref::blendWithFunction(sub, big, dst, ColorFormat::RGBA8).r, 1.0 - 0.25);
  EXPECT_DOUBLE_EQ(ref::blendWithFunction(sub, big, dst, ColorFormat::RGBA32F).r, 2.0 - 0.25);
  EXPECT_DOUBLE_EQ(ref::blendWithFunction(sub, big, dst, ColorFormat::RGBA32F).g, -0.125);
}

TEST(FragmentOps, BlendFunctionInARender) {
  Scene s = test::windowScene(kW, kH);
  s.clear_color = {0.25, 0.5, 0.0, 1.0};
  const std::size_t o = test::addRect(s, -1, -1, kW + 1, kH + 1, 0.6f);  // white, alpha 1
  s.objects[o].state.blend = Blend::Function;
  BlendFunction add;
  add.src = add.src_alpha = BlendFactor::ConstantColor;
  add.dst = add.dst_alpha = BlendFactor::One;
  add.constant = {0.5, 0.25, 0.125, 0.0};
  s.objects[o].state.blend_function = add;
  const Frame f = renderReference(s, plain());
  EXPECT_EQ(colorAt(f, 2, 2), glm::dvec4(0.75, 0.75, 0.125, 1.0));
}

TEST(FragmentOps, NothingDrawnLeavesEveryClearValue) {
  Scene s = test::windowScene(kW, kH);
  s.state.stencil_format = StencilFormat::S8;
  s.clear_stencil = 9;
  s.clear_depth = 0.5;
  s.clear_color = {0.1, 0.2, 0.3, 0.4};
  test::addRect(s, -1, -1, kW + 1, kH + 1, 0.9f);  // window depth 0.1
  s.state.ops.scissor = Scissor{0, 0, 0, 0};
  const Frame f = renderReference(s);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    ASSERT_EQ(f.id[i], 0u);
    ASSERT_EQ(f.stencil[i], 9u);
    ASSERT_NEAR(f.depth[i], 0.5, 1e-7);
    ASSERT_EQ(f.color[4 * i + 1], 0.2f);
  }
}

// The general path renders a scene with only original passes bit for bit like the
// specialised one: a scene made extended by a no-op (a colour mask of all four channels is
// the default; a scissor box covering the image changes nothing).
TEST(FragmentOps, GeneralPathDrawsOriginalScenesTheSame) {
  for (Shading shading : {Shading::Flat, Shading::Gouraud, Shading::Phong}) {
    Scene s = test::windowScene(16, 12);
    s.state.shading = shading;
    test::addTriangle(s, {-2, -3, 0.2f}, {18, 1, 0.7f}, {3, 14, 0.4f});
    test::addRect(s, 2, 2, 12, 9, 0.5f);
    const Frame a = renderReference(s, plain());
    s.state.ops.scissor = Scissor{-5, -5, 100, 100};
    const Frame b = renderReference(s, plain());
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.color, b.color);
  }
}

}  // namespace
}  // namespace rc
