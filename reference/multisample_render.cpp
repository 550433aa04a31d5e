// Multisampling: the scene rendered once per sample position and resolved (colour mean,
// owners, the channels reduced over the samples).
#include "reference/renderer_internal.h"

#include <chrono>

#include "fixtures/errors.h"
#include "fixtures/multisample.h"
#include "reference/fragment_ops.h"
#include "reference/rounding.h"

namespace rc::ref {
namespace {

// How each uncertainty channel of a multisampled pixel follows from its samples' (a
// pixel may differ wherever one of its samples may): the smallest distance or gap, the
// largest slope, count or colour range.
constexpr bool kTakeSmallest[kUncertaintyChannels] = {
    true,   // edge_dist
    true,   // depth_gap
    false,  // depth_slope
    false,  // gap_slope
    true,   // texel_dist
    false,  // texel_alt
    false,  // blend_count
    true,   // blend_gap
    false,  // blend_slope
    true,   // clear_gap
    false,  // clear_slope
    false,  // texel_gain
    false,  // depth_reach
    false,  // texel_reach
    false,  // shade_reach
    false,  // normal_reach
};

}  // namespace

// Multisampling: edge_dist from the sample position (out of line, so that the
// single-sample drawPolygon() compiles as it did before multisampling).
void Renderer::addSampleEdgeDistances(const WindowVertex* wv, int count, const double* reach) {
  WindowVertex moved[kMaxClipVertices];
  for (int i = 0; i < count; ++i) {
    moved[i] = wv[i];
    moved[i].x -= shift_.offset.x;
    moved[i].y -= shift_.offset.y;
  }
  addEdgeDistances(moved, count, clip_, fb_width_, fb_height_, frame_.edge_dist.data(), reach);
}

// Multisampling: one render per sample (SampleShift), then the resolve: the colour is the
// mean of the samples' stored colours (converted to the colour format again), id, depth
// and coverage by resolveSampleOwners(), the uncertainty channels reduced over the
// samples (kTakeSmallest), per-sample edge_dist kept, and sample_alt.
Frame renderMultisample(const Scene& scene, const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const int samples = scene.state.samples;
  const bool given = !options.sample_positions.empty();
  const std::vector<glm::dvec2> positions =
      given ? options.sample_positions : standardSamplePositions(samples);
  if (static_cast<int>(positions.size()) != samples)
    throw InputError(sceneLabel(scene) + ": " + std::to_string(positions.size()) +
                     " sample positions given for " + std::to_string(samples) + " samples");
  for (const glm::dvec2& p : positions)
    if (!(p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0))
      throw InputError(sceneLabel(scene) + ": sample position outside the pixel [0, 1]^2");

  const double scale = std::ldexp(1.0, options.subpixel_bits);
  Frame out;
  std::vector<float> sample_color;  // per sample plane, RGBA
  std::vector<double> sum;
  std::uint64_t fragments = 0;
  std::uint64_t triangles = 0;
  bool on_grid = true;
  ABufferTally abuffer;  // ref:abuffer: the samples' resolves joined
  for (int s = 0; s < samples; ++s) {
    SampleShift shift;
    shift.active = true;
    shift.offset = positions[s] - glm::dvec2(0.5);
    const double ux = shift.offset.x * scale;
    const double uy = shift.offset.y * scale;
    shift.units_x = static_cast<std::int64_t>(roundHalfEven(ux));
    shift.units_y = static_cast<std::int64_t>(roundHalfEven(uy));
    on_grid = on_grid && static_cast<double>(shift.units_x) == ux &&
              static_cast<double>(shift.units_y) == uy;
    Renderer renderer(scene, options, PixelRect{0, 0, scene.width, scene.height}, nullptr, shift);
    Frame f = renderer.run();
    if (options.abuffer) {
      ABufferTally& t = renderer.abufferTally();
      if (s == 0) {
        abuffer = std::move(t);
      } else {
        for (std::size_t i = 0; i < t.pixel_flags.size(); ++i)
          abuffer.pixel_flags[i] |= t.pixel_flags[i];
        abuffer.pair_pixels.insert(abuffer.pair_pixels.end(), t.pair_pixels.begin(),
                                   t.pair_pixels.end());
        abuffer.kept_fragments += t.kept_fragments;
      }
    }
    const std::size_t n = f.pixelCount();
    fragments += f.meta["fragments"].get<std::uint64_t>();
    triangles = f.meta["triangles_rasterized"].get<std::uint64_t>();
    if (s == 0) {
      out.width = f.width;
      out.height = f.height;
      out.samples = samples;
      out.meta = f.meta;
      out.sample_id.resize(n * samples);
      out.sample_depth.resize(n * samples);
      sample_color.resize(n * 4 * samples);
      sum.assign(n * 4, 0.0);
      if (f.hasUncertainty()) {
        out.sample_edge_dist.resize(n * samples);
        const auto from = f.uncertainty();
        const auto to = out.uncertainty();
        for (int c = 0; c < kUncertaintyChannels; ++c) *to[c] = *from[c];
      }
    } else if (f.hasUncertainty()) {
      const auto from = f.uncertainty();
      const auto to = out.uncertainty();
      for (int c = 0; c < kUncertaintyChannels; ++c) {
        std::vector<float>& dst = *to[c];
        const std::vector<float>& src = *from[c];
        for (std::size_t i = 0; i < n; ++i)
          dst[i] = kTakeSmallest[c] ? std::min(dst[i], src[i]) : std::max(dst[i], src[i]);
      }
    }
    std::copy(f.id.begin(), f.id.end(), out.sample_id.begin() + static_cast<std::ptrdiff_t>(s * n));
    std::copy(f.depth.begin(), f.depth.end(),
              out.sample_depth.begin() + static_cast<std::ptrdiff_t>(s * n));
    std::copy(f.color.begin(), f.color.end(),
              sample_color.begin() + static_cast<std::ptrdiff_t>(s * n * 4));
    if (f.hasUncertainty())
      std::copy(f.edge_dist.begin(), f.edge_dist.end(),
                out.sample_edge_dist.begin() + static_cast<std::ptrdiff_t>(s * n));
    for (std::size_t k = 0; k < n * 4; ++k)
      sum[k] += loadColor(f.color[k], scene.state.color_format);
  }

  const std::size_t n = out.pixelCount();
  out.color.resize(n * 4);
  for (std::size_t k = 0; k < n * 4; ++k)
    out.color[k] = storeColor(sum[k] / samples, scene.state.color_format);
  resolveSampleOwners(out);
  if (out.hasUncertainty()) {
    // sample_alt: the colour range (8-bit units, any channel) over the samples of the pixel
    // and its eight neighbours.
    out.sample_alt.assign(n, 0.0f);
    const int w = out.width;
    const int h = out.height;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        float lo[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
        float hi[4] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
          for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
            const std::size_t j = out.index(xx, yy);
            for (int s = 0; s < samples; ++s) {
              const float* c = &sample_color[(static_cast<std::size_t>(s) * n + j) * 4];
              for (int k = 0; k < 4; ++k) {
                lo[k] = std::min(lo[k], c[k]);
                hi[k] = std::max(hi[k], c[k]);
              }
            }
          }
        }
        float range = 0.0f;
        for (int k = 0; k < 4; ++k)
          if (std::isfinite(hi[k] - lo[k])) range = std::max(range, hi[k] - lo[k]);
        out.sample_alt[out.index(x, y)] = 255.0f * range;
      }
    }
  }
  nlohmann::json pos = nlohmann::json::array();
  for (const glm::dvec2& p : positions) pos.push_back({p.x, p.y});
  out.meta["fragments"] = fragments;
  out.meta["triangles_rasterized"] = triangles;
  out.meta["multisample"] = {{"samples", samples},
                             {"positions", pos},
                             {"positions_source", given ? "given" : "standard"},
                             {"positions_on_grid", on_grid}};
  if (options.abuffer)
    out.meta["abuffer"] =
        abufferMeta(abuffer, PixelRect{0, 0, scene.width, scene.height}, scene.height);
  out.meta["timing_ms"]["render"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace rc::ref
