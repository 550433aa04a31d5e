// Multi-pass scenes in the reference: see multipass.h.
#include "reference/multipass.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "fixtures/scene_logic.h"

namespace rc::ref {
namespace {

// Steps of the format: one unit in the last place of d16/d24, 2^-24 for d32f (the
// comparator's depth steps, docs/tolerances.md section 2).
double depthStep(DepthFormat f) {
  const int bits = depthBits(f);
  return bits > 0 ? 1.0 / (std::ldexp(1.0, bits) - 1.0) : std::ldexp(1.0, -24);
}

// The comparator's fail threshold for the format's depth (compare/tolerances.cpp): what a
// stored depth may be off by before a depth error fails.
double depthFailSteps(DepthFormat f) { return f == DepthFormat::D16 ? 2.0 : 16.0; }

// px: how far a driver's vertices and attribute planes may sit from the reference's (the
// snap band of a 4-bit-subpixel rasterizer, sqrt(1/2) / 16 each side, rounded up).
constexpr double kMapBandPx = 0.1;

float finiteOr0(float v) { return std::isfinite(v) ? v : 0.0f; }

// A target frame's pixel (x, y) (rows top-down) as its texel index (rows bottom-up, GL's).
std::size_t texelIndex(const Frame& frame, int x, int y) {
  return static_cast<std::size_t>(frame.height - 1 - y) * frame.width + x;
}

// fn(j) for pixel (x, y) and its eight neighbours inside the frame (frame indices).
template <class Fn>
void forEach3x3(const Frame& frame, int x, int y, Fn&& fn) {
  for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, frame.height - 1); ++ny)
    for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, frame.width - 1); ++nx)
      fn(frame.index(nx, ny));
}

// Steps a fragment of depth gradient `slope` (steps/px) at pixel i of a target the
// reference drew may be off by in another implementation (the comparator's rule of
// docs/tolerances.md section 2 with the widest driver's band): the fail threshold, its
// plane moved by the band, its vertices' float32 reach, another r for its offset's units.
double depthAllowanceSteps(const Frame& frame, DepthFormat format, std::size_t i, double slope) {
  double a = depthFailSteps(format);
  if (!frame.hasUncertainty()) return a;
  return a + kMapBandPx * slope + finiteOr0(frame.depth_reach[i]) +
         finiteOr0(frame.offset_steps[i]);
}

// Whether another implementation may show another surface (or the background) at pixel i
// of a target the reference drew: an edge within the band, a depth test within twice the
// tolerances of a tie, a fragment within its tolerance of the clear depth.
bool coverageOpen(const Frame& frame, DepthFormat format, std::size_t i) {
  if (!frame.hasUncertainty()) return false;
  return frame.edge_dist[i] <= kMapBandPx ||
         frame.depth_gap[i] <=
             2.0 * depthAllowanceSteps(frame, format, i, finiteOr0(frame.gap_slope[i])) ||
         frame.clear_gap[i] <=
             depthAllowanceSteps(frame, format, i, finiteOr0(frame.clear_slope[i]));
}

// The colour target `frame` (rows top-down) as a texture (rows bottom-up, 8-bit).
std::shared_ptr<Texture> targetTexture(const Frame& frame, const std::string& name) {
  auto t = std::make_shared<Texture>();
  t->path = "target:" + name;
  t->width = frame.width;
  t->height = frame.height;
  t->rgba.resize(static_cast<std::size_t>(frame.width) * frame.height * 4);
  for (int j = 0; j < frame.height; ++j) {
    const std::size_t row = frame.index(0, frame.height - 1 - j);
    for (int i = 0; i < frame.width * 4; ++i) {
      const float v = frame.color[row * 4 + static_cast<std::size_t>(i)];
      t->rgba[(static_cast<std::size_t>(j) * frame.width) * 4 + static_cast<std::size_t>(i)] =
          static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    }
  }
  return t;
}

// How far another implementation's drawing of colour target `frame` may differ at each
// texel (8-bit units, the largest channel; rows bottom-up): the comparator's allowances
// there (a unit of rounding, the float32 normal and shading reaches, blends' rounding,
// the texel choice of a texture it sampled), and where an edge or a depth tie may go the
// other way, any colour of its 3x3 neighbourhood or the clear colour (another surface, or
// none); where a depth test is within twice its tolerances of a tie, or a blend may go
// either way, any colour (the other fragment shows nowhere in the target).
std::vector<float> targetUncertainty(const Frame& frame, DepthFormat format,
                                     const glm::dvec4& clear,
                                     const std::vector<std::uint8_t>& optional_cover) {
  std::vector<float> out(frame.pixelCount(), 0.0f);
  if (!frame.hasUncertainty()) return out;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const std::size_t i = frame.index(x, y);
      double u = 1.0 + finiteOr0(frame.normal_reach[i]) +
                 kMapBandPx * finiteOr0(frame.shade_reach[i]) + finiteOr0(frame.blend_count[i]) +
                 finiteOr0(frame.texel_alt[i]);
      // A depth tie (or a blend whose order or coverage is open) may show a fragment whose
      // colour no pixel of the target shows: anything.
      const bool tie =
          frame.depth_gap[i] <=
              2.0 * depthAllowanceSteps(frame, format, i, finiteOr0(frame.gap_slope[i])) ||
          (frame.blend_count[i] > 0.0f &&
           (frame.edge_dist[i] <= kMapBandPx ||
            frame.blend_gap[i] <=
                2.0 * depthAllowanceSteps(frame, format, i, finiteOr0(frame.blend_slope[i]))));
      // A primitive drawn in one implementation and not the other: any colour.
      if (tie || (!optional_cover.empty() && optional_cover[i] != 0)) u = 255.0;
      if (!tie && coverageOpen(frame, format, i)) {
        for (int c = 0; c < 4; ++c)  // the background
          u = std::max(u, 1.0 + 255.0 * std::fabs(clear[c] - frame.color[i * 4 + c]));
        forEach3x3(frame, x, y, [&](std::size_t j) {
          for (int c = 0; c < 4; ++c)
            u = std::max(u, 1.0 + 255.0 * std::fabs(static_cast<double>(frame.color[j * 4 + c]) -
                                                    frame.color[i * 4 + c]));
        });
      }
      out[texelIndex(frame, x, y)] = static_cast<float>(u);
    }
  }
  return out;
}

struct Bound {
  std::map<std::string, std::shared_ptr<const Texture>> textures;
  std::map<std::string, std::shared_ptr<const ShadowMapData>> maps;
};

void bindInputs(Scene& pass_scene, const Bound& bound) {
  for (Material& m : pass_scene.materials) {
    if (!m.texture_target.empty()) {
      const auto it = bound.textures.find(m.texture_target);
      if (it != bound.textures.end()) m.texture = it->second;
    }
    if (m.shadow) {
      const auto it = bound.maps.find(m.shadow->map);
      if (it != bound.maps.end()) m.shadow->data = it->second;
    }
  }
}

}  // namespace

void shadowMapRange(const Frame& frame, double clear_depth, ShadowMapData& map,
                    const std::vector<std::uint8_t>* optional_cover) {
  const std::size_t n = frame.pixelCount();
  map.lo.assign(n, 0.0);
  map.hi.assign(n, 0.0);
  const double step = depthStep(map.format);
  const bool channels = frame.hasUncertainty();
  // Steps a texel's own surface may be off by.
  auto allowance = [&](std::size_t i) {
    return depthAllowanceSteps(frame, map.format, i,
                               channels ? finiteOr0(frame.depth_slope[i]) : 0.0);
  };
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const std::size_t i = frame.index(x, y);
      const std::size_t k = texelIndex(frame, x, y);
      const double d = frame.depth[i];
      const double a = allowance(i) * step;
      double lo = d - a;
      double hi = d + a;
      if (channels) {
        // Two fragments within their tolerances of a tie: the other may be stored.
        const double gap = frame.depth_gap[i];
        const double tie = depthAllowanceSteps(frame, map.format, i, finiteOr0(frame.gap_slope[i]));
        if (std::isfinite(gap) && gap <= 2.0 * tie) {
          lo = std::min(lo, d - (gap + tie) * step);
          hi = std::max(hi, d + (gap + tie) * step);
        }
        // Within the band of an edge another surface (or the clear depth) may cover the
        // texel: those of its neighbours, each carried over one texel along its slope.
        if (coverageOpen(frame, map.format, i)) {
          forEach3x3(frame, x, y, [&](std::size_t j) {
            const double reach = (allowance(j) + 1.5 * finiteOr0(frame.depth_slope[j])) * step;
            lo = std::min(lo, frame.depth[j] - reach);
            hi = std::max(hi, frame.depth[j] + reach);
          });
          lo = std::min(lo, clear_depth);
          hi = std::max(hi, clear_depth);
        }
        // A primitive only another implementation draws (or only this one): any depth.
        if (optional_cover != nullptr && i < optional_cover->size() && (*optional_cover)[i] != 0) {
          lo = 0.0;
          hi = 1.0;
        }
      }
      map.lo[k] = lo;
      map.hi[k] = hi;
    }
  }
}

PassOutputs renderPasses(const Scene& scene, const ReferenceOptions& options) {
  PassOutputs out;
  Bound bound;
  for (std::size_t k = 0; k + 1 < scene.passes.size(); ++k) {
    Scene ps = passScene(scene, k);
    bindInputs(ps, bound);
    ReferenceOptions o = options;
    o.uncertainty = true;  // the map's range comes from its channels
    std::vector<std::uint8_t> cover;
    o.optional_cover = &cover;
    Frame f = renderReference(ps, o);
    const std::string& name = scene.passes[k].target;
    const RenderTarget* target = findTarget(scene, name);
    f.meta["pass"] = {{"index", k},
                      {"target", name},
                      {"format", target != nullptr ? toString(target->format) : "frame"}};
    if (target != nullptr && target->depth()) {
      auto map = std::make_shared<ShadowMapData>();
      map->width = f.width;
      map->height = f.height;
      map->format = ps.state.depth_format;
      map->matrix = shadowMatrix(scene, name);
      map->depth.resize(f.pixelCount());
      for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) map->depth[texelIndex(f, x, y)] = f.depth[f.index(x, y)];
      if (options.uncertainty) shadowMapRange(f, ps.clear_depth, *map, &cover);
      bound.maps[name] = std::move(map);
    } else if (target != nullptr) {
      auto texture = targetTexture(f, name);
      if (options.uncertainty)
        texture->uncertainty = targetUncertainty(f, ps.state.depth_format, ps.clear_color, cover);
      bound.textures[name] = std::move(texture);
    }
    out.frames.push_back(std::move(f));
  }
  out.frame_scene = passScene(scene, scene.passes.size() - 1);
  bindInputs(out.frame_scene, bound);
  return out;
}

}  // namespace rc::ref
