// The reference renderer's fragment loop: for each covered pixel centre of a fan triangle
// the depth, the depth test, the colour (shading.h) and the writes; the tracing loop of
// `explain` beside it, the same expressions with a record per fragment.
#include "reference/renderer_internal.h"

#include <functional>
#include <string_view>
#include <type_traits>

#include "fixtures/scene_geometry.h"
#include "reference/fragment_ops.h"
#include "reference/shading_lanes.h"
#include "reference/texture_sampling.h"

// Lane4 and Lane8 values stay inside shadePhongQuad() (everything it calls is inlined):
// -Wpsabi's note on passing 32-byte vectors without AVX does not apply (for the rest of the
// file: GCC also gives it at the end of the translation unit).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace rc::ref {
namespace {

struct PhongQuad {
  static constexpr int kMax = 8;
  const FragmentInterpolator* interp = nullptr;
  const PreparedShading* shading = nullptr;
  glm::dvec3 world[3];   // the original vertices' world positions
  glm::dvec3 normal[3];  // and normals
  float* colors = nullptr;
  bool rgba8 = false;
  float alpha = 0.0f;  // the stored opacity
  int count = 0;       // fragments pending
  std::size_t index[kMax] = {};
  double dx[kMax] = {};
};

using Float4 = float __attribute__((vector_size(16)));

// Lanes 4h .. 4h + 3 of v.
template <class V>
[[gnu::always_inline]] inline Lane4 quarterOf(V v, int h) {
  if constexpr (std::is_same_v<V, Lane8>) {
    return h == 0 ? v.lo : v.hi;
  } else {
    return v;
  }
}

// rgba32f: fragments 0 .. n-1 of four (channels r, g, b per lane, each float(c) as the
// scalar cast rounds it), each fragment's four channels stored as one vector.
[[gnu::always_inline]] inline void storeRgba32f(float* colors, const std::size_t* index, int n,
                                                Lane4 cr, Lane4 cg, Lane4 cb, float alpha) {
  const Float4 r = __builtin_convertvector(cr, Float4);
  const Float4 g = __builtin_convertvector(cg, Float4);
  const Float4 b = __builtin_convertvector(cb, Float4);
  const Float4 a = {alpha, alpha, alpha, alpha};
  const Float4 rg_lo = __builtin_shufflevector(r, g, 0, 4, 1, 5);  // r0 g0 r1 g1
  const Float4 rg_hi = __builtin_shufflevector(r, g, 2, 6, 3, 7);  // r2 g2 r3 g3
  const Float4 ba_lo = __builtin_shufflevector(b, a, 0, 4, 1, 5);  // b0 a b1 a
  const Float4 ba_hi = __builtin_shufflevector(b, a, 2, 6, 3, 7);  // b2 a b3 a
  const Float4 px[4] = {__builtin_shufflevector(rg_lo, ba_lo, 0, 1, 4, 5),
                        __builtin_shufflevector(rg_lo, ba_lo, 2, 3, 6, 7),
                        __builtin_shufflevector(rg_hi, ba_hi, 0, 1, 4, 5),
                        __builtin_shufflevector(rg_hi, ba_hi, 2, 3, 6, 7)};
  for (int lane = 0; lane < n; ++lane)
    __builtin_memcpy(colors + 4 * index[lane], &px[lane], sizeof px[lane]);
}

// The pending fragments in the lanes of V (Lane4 for up to four, Lane8 for more).
template <class V>
[[gnu::always_inline]] inline void shadePhongLanes(const PhongQuad& q,
                                                   const FragmentInterpolator::Row& row) {
  // One load (a loop over the lanes compiled to a call of memcpy); unused lanes repeat the
  // first fragment.
  V dx;
  __builtin_memcpy(&dx, q.dx, sizeof dx);
  dx = selectLanes(lanesBelow<V>(q.count), dx, splatAs<V>(q.dx[0]));
  V b[3];
  q.interp->barycentricAtLanes(row, dx, b);
  const Vec3L<V> p = combineLanes(b[0], b[1], b[2], q.world[0], q.world[1], q.world[2]);
  const Vec3L<V> n =
      safeNormalizeLanes(combineLanes(b[0], b[1], b[2], q.normal[0], q.normal[1], q.normal[2]));
  const LitColorL<V> lit = shadePreparedLanes(*q.shading, p, n);
  const Vec3L<V> c = lit.ambient_diffuse + lit.specular;
  if (q.rgba8) {
    for (int k = 0; k < q.count; ++k) {
      float* out = q.colors + 4 * q.index[k];
      out[0] = storeColor(c.x[k], ColorFormat::RGBA8);
      out[1] = storeColor(c.y[k], ColorFormat::RGBA8);
      out[2] = storeColor(c.z[k], ColorFormat::RGBA8);
      out[3] = q.alpha;
    }
    return;
  }
  for (int h = 0; 4 * h < q.count; ++h)
    storeRgba32f(q.colors, &q.index[static_cast<std::size_t>(4 * h)], std::min(4, q.count - 4 * h),
                 quarterOf(c.x, h), quarterOf(c.y, h), quarterOf(c.z, h), q.alpha);
}

// The colour of the pending fragments: with b = barycentricAt(row, dx), the scalar form is
// store(ambient_diffuse + specular of shadePrepared(shading, b.x * w0 + b.y * w1 + b.z *
// w2, safeNormalize(b.x * n0 + b.y * n1 + b.z * n2))); here lane by lane the same
// operations (shading_lanes.h), in four lanes up to four fragments and in eight above (two
// independent halves the processor overlaps: the chain of divisions and square roots of
// one quad is long). Compiled twice, for x86-64's baseline and for AVX2 (no FMA), and
// picked at load time: the bits are the same either way, AVX2 only does four lanes per
// instruction where SSE2 does two.
__attribute__((target_clones("avx2", "default"))) void shadePhongQuad(
    const PhongQuad& q, const FragmentInterpolator::Row& row) {
  if (q.count <= 4) {
    shadePhongLanes<Lane4>(q, row);
  } else {
    shadePhongLanes<Lane8>(q, row);
  }
}

// The shade functor of fillSpans() for untextured, unblended Phong: fragments that passed
// are collected and coloured eight at a time, the rest at the end of each span (fillSpans()
// calls flush()). Deferring a colour write past later fragments of the span changes
// nothing: nothing in the loop reads colour, and a span's pixels are distinct.
class PhongQuads {
 public:
  PhongQuads(const TriangleContext& t, const FragmentInterpolator& interp, float* colors,
             bool rgba8, float alpha) {
    q_.interp = &interp;
    q_.shading = t.shading;
    for (int k = 0; k < 3; ++k) {
      q_.world[k] = t.v[k]->world;
      q_.normal[k] = t.v[k]->normal;
    }
    q_.colors = colors;
    q_.rgba8 = rgba8;
    q_.alpha = alpha;
  }
  TexelNote operator()(std::size_t index, const FragmentInterpolator::Row& row, double dx) {
    q_.index[q_.count] = index;
    q_.dx[q_.count] = dx;
    if (++q_.count == PhongQuad::kMax) flush(row);
    return TexelNote{};
  }
  void flush(const FragmentInterpolator::Row& row) {
    if (q_.count != 0) shadePhongQuad(q_, row);
    q_.count = 0;
  }

 private:
  PhongQuad q_;
};

}  // namespace

template <Shading kShading>
inline glm::dvec4 Renderer::fragmentColor(const TriangleContext& t, const glm::dvec3& b,
                                          ShadingTerms* terms, TexelNote* note,
                                          const FragmentInterpolator* interp,
                                          const FragmentInterpolator::Row* row, double dx) const {
  glm::dvec3 tex(1.0);
  glm::dvec2 uv(0.0);
  if (t.texture) {
    uv = b.x * t.v[0]->uv + b.y * t.v[1]->uv + b.z * t.v[2]->uv;
    if (t.chain != nullptr && interp != nullptr && row != nullptr) {
      tex = glm::dvec3(lodTexel(t, uv, b, *interp, *row, dx, terms));
    } else if (t.chain != nullptr && !std::isnan(t.line_lambda)) {  // lines and points
      const LodSample sample = sampleAtLod(*t.chain, uv, t.line_lambda, lod_state_);
      tex = glm::dvec3(sample.color);
      if (terms != nullptr) {
        terms->lod.used = true;
        terms->lod.lambda = t.line_lambda;
        terms->lod.magnified = sample.magnified;
        terms->lod.level0 = sample.level0;
        terms->lod.level1 = sample.level1;
        terms->lod.weight = sample.weight;
      }
    } else {
      tex = glm::dvec3(
          sampleTexture(*t.texture, uv, magFilter(scene_.state), scene_.state.texture_wrap));
    }
  }
  LitColor lit;
  if constexpr (kShading == Shading::Flat) {
    lit = t.flat;
  } else if constexpr (kShading == Shading::Gouraud) {
    lit.ambient_diffuse = b.x * t.gouraud[0]->ambient_diffuse +
                          b.y * t.gouraud[1]->ambient_diffuse + b.z * t.gouraud[2]->ambient_diffuse;
    lit.specular =
        b.x * t.gouraud[0]->specular + b.y * t.gouraud[1]->specular + b.z * t.gouraud[2]->specular;
  } else {
    const glm::dvec3 p = b.x * t.v[0]->world + b.y * t.v[1]->world + b.z * t.v[2]->world;
    const glm::dvec3 n =
        safeNormalize(b.x * t.v[0]->normal + b.y * t.v[1]->normal + b.z * t.v[2]->normal);
    lit = shadePrepared(*t.shading, p, n, terms);
  }
  const glm::dvec4 color = finalColor(lit, tex, t.material->opacity);
  if (note && t.texel_choice) *note = texelNote(t, uv, b, lit.ambient_diffuse, *interp, *row, dx);
  if constexpr (kShading == Shading::Gouraud) {
    if (note && t.thin) note->shade = gouraudReach(t, b, lit, tex, *interp, *row, dx);
  } else if constexpr (kShading == Shading::Phong) {
    if (note && t.thin) note->shade = phongReach(t, b, tex, lit, *interp, *row, dx);
    if (note && t.short_normals) {
      const glm::dvec3 p = b.x * t.v[0]->world + b.y * t.v[1]->world + b.z * t.v[2]->world;
      note->normal = normalReach(t, b, p, *interp, *row, dx);
    }
    if (note && t.shading->shadowed)
      note->normal = std::max(note->normal, shadowReach(t, b, tex, interp, row, dx));
  }
  // A texture another pass drew: its texels may differ by their own uncertainty, times the
  // light on the texture (normal_reach, 8-bit units; docs/tolerances.md section 11).
  if (note && t.texture && !t.texture->uncertainty.empty()) {
    const bool linear = magFilter(scene_.state) == TextureFilter::Linear ||
                        minFilter(scene_.state) == MinFilter::Linear;
    const double reach =
        texelValueReach(*t.texture, uv, linear ? TextureFilter::Linear : TextureFilter::Nearest,
                        scene_.state.texture_wrap);
    const double light =
        std::max({lit.ambient_diffuse.x, lit.ambient_diffuse.y, lit.ambient_diffuse.z});
    note->normal = std::max(note->normal, static_cast<float>(reach * std::fabs(light)));
  }
  if (terms) {
    if constexpr (kShading != Shading::Phong) traceTerms(t, b, *terms);
    terms->texture = tex;
    terms->uv = uv;
    terms->color = color;
  }
  return color;
}

// The ambient and per-light terms of flat and Gouraud fragments (Phong records them
// while lighting). Gouraud interpolates each vertex's terms like AD and S.
void Renderer::traceTerms(const TriangleContext& t, const glm::dvec3& b,
                          ShadingTerms& terms) const {
  if (scene_.state.shading == Shading::Flat) {
    shadePrepared(*t.shading, t.centroid, t.face_normal, &terms);
    return;
  }
  ShadingTerms vt[3];
  for (int k = 0; k < 3; ++k) shadePrepared(*t.shading, t.v[k]->world, t.v[k]->normal, &vt[k]);
  terms.points.clear();
  for (int k = 0; k < 3; ++k) {
    terms.points.push_back(std::move(vt[k].points.front()));
    terms.points.back().weight = b[k];
  }
  terms.ambient = b.x * vt[0].ambient + b.y * vt[1].ambient + b.z * vt[2].ambient;
  terms.lights.assign(vt[0].lights.size(), LightTerms{});
  for (std::size_t i = 0; i < terms.lights.size(); ++i) {
    terms.lights[i].diffuse = b.x * vt[0].lights[i].diffuse + b.y * vt[1].lights[i].diffuse +
                              b.z * vt[2].lights[i].diffuse;
    terms.lights[i].specular = b.x * vt[0].lights[i].specular + b.y * vt[1].lights[i].specular +
                               b.z * vt[2].lights[i].specular;
  }
}

void Renderer::uvDerivatives(const TriangleContext& t, const FragmentInterpolator& interp,
                             const FragmentInterpolator::Row& row, double dx, const glm::dvec3& b,
                             glm::dvec2& d_dx, glm::dvec2& d_dy) const {
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  const glm::dvec2 size(t.texture->width, t.texture->height);
  d_dx = (db[0].x * t.v[0]->uv + db[0].y * t.v[1]->uv + db[0].z * t.v[2]->uv) * size;
  d_dy = (db[1].x * t.v[0]->uv + db[1].y * t.v[1]->uv + db[1].z * t.v[2]->uv) * size;
}

glm::dvec4 Renderer::lodTexel(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                              const FragmentInterpolator& interp,
                              const FragmentInterpolator::Row& row, double dx,
                              ShadingTerms* terms) const {
  glm::dvec2 d_dx;
  glm::dvec2 d_dy;
  uvDerivatives(t, interp, row, dx, b, d_dx, d_dy);
  const double rho = scaleFactor(d_dx, d_dy);
  const double lambda = lodOf(rho, lod_state_);
  const LodSample sample = sampleAtLod(*t.chain, uv, lambda, lod_state_);
  if (terms != nullptr) {  // explain
    ShadingTerms::Lod& l = terms->lod;
    l.used = true;
    l.d_dx = d_dx;
    l.d_dy = d_dy;
    l.rho = rho;
    l.lambda = lambda;
    l.magnified = sample.magnified;
    l.level0 = sample.level0;
    l.level1 = sample.level1;
    l.weight = sample.weight;
    std::tie(l.lambda_lo, l.lambda_hi) = lodInterval(t, interp, row, dx);
  }
  return sample.color;
}

glm::dvec4 Renderer::storedColor(std::size_t index) const {
  const float* c = &frame_.color[4 * index];
  return glm::dvec4(loadColor(c[0], color_format_), loadColor(c[1], color_format_),
                    loadColor(c[2], color_format_), loadColor(c[3], color_format_));
}

void Renderer::writeColor(std::size_t index, const glm::dvec4& src, bool blend) {
  if (blend && defer_blends_) {  // the fragment loop has just kept this fragment
    kept_.back().color = src;
    return;
  }
  float* c = &frame_.color[4 * index];
  if (!blend) {
    for (int k = 0; k < 4; ++k) c[k] = storeColor(src[k], color_format_);
    return;
  }
  const glm::dvec4 out = blendSourceOver(src, storedColor(index), color_format_);
  for (int k = 0; k < 4; ++k) c[k] = storeColor(out[k], color_format_);
}

// The fragment loop: for every covered pixel centre, depth (from the unsnapped plane,
// clamped, quantized), the depth test, the uncertainty bookkeeping, then depth, id and
// colour writes. `shade(index, row, dx)` writes the colour of a fragment that passed.
// Everything constant along a row is computed once per row (FragmentInterpolator::Row).
template <DepthFormat kFormat, bool kGaps, bool kBarycentrics, class Shade>
void Renderer::fillSpans(const TriangleContext& t, const TriangleCoverage& coverage,
                         const FragmentInterpolator& interp, Shade&& shade) {
  const bool always = t.pass->depth_func == DepthFunc::Always;
  const bool depth_write = t.pass->depth_write;
  const bool blend = t.pass->blend;
  const bool keep = blend && defer_blends_;
  const float slope = t.depth_slope;
  const auto alpha = static_cast<float>(std::clamp(t.material->opacity, 0.0, 1.0));
  const std::uint32_t id = t.prim->id;
  std::uint32_t* const depth = depth_.data();
  std::uint32_t* const ids = frame_.id.data();
  ++triangles_drawn_;
  coverage.forEachSpan([&](int py, int x_begin, int x_end) {
    fragments_ += static_cast<std::uint64_t>(x_end - x_begin);
    const double cy = py + 0.5;  // pixel centres
    const FragmentInterpolator::Row row = kBarycentrics ? interp.row(cy) : interp.depthRow(cy);
    const std::size_t row_index =
        static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_);
    // In a local: the depth and id stores (std::uint32_t) may alias clip_.x0 (int), so the
    // member would be reloaded for every fragment.
    const int x0 = clip_.x0;
    for (int px = x_begin; px < x_end; ++px) {
      const double dx = interp.dx(px + 0.5);
      const std::size_t index = row_index + static_cast<std::size_t>(px - x0);
      const double z = clampDepth(interp.depthAt(row, dx));
      const std::uint32_t key = depthKey(z, kFormat);  // kFormat constant: the switch folds
      const bool pass = always || key < depth[index];
      if constexpr (kGaps) {
        const float reach = t.depth_reach.at(px + 0.5, cy);
        if (pass) {
          gaps_.passed(index, z, slope, reach, !always, depth_write, blend);
        } else {
          gaps_.failed(index, z, slope, reach, blend);
        }
      }
      if (!pass) continue;
      if (depth_write) depth[index] = key;
      if (keep) {  // blended later, in depth order (resolveABuffer)
        kept_.push_back({static_cast<std::uint32_t>(index), blend_seq_, id, slope, z});
        KeptFragment& kept = kept_.back();
        kept.alpha = alpha;
        kept.note = shade(index, row, dx);  // its colour goes to kept.color
        continue;
      }
      ids[index] = id;
      const TexelNote note = shade(index, row, dx);
      if constexpr (kGaps)
        gaps_.colourWritten(index, blend, alpha, note.dist, note.alt, note.gain, note.reach,
                            note.shade, note.normal);
    }
    if constexpr (requires { shade.flush(row); }) shade.flush(row);
  });
}

// Flattened: everything it calls that the compiler can see is inlined into each fragment
// loop. The renderer's lambdas and templates have external linkage (Renderer is shared by
// the files of renderer_internal.h), so GCC no longer inlines them as local functions called
// once, and the loops then reload what they capture on every fragment (Gouraud layers: 116
// -> 132 instructions a fragment). Flattened, every benchmark scene is as fast or faster
// than with the renderer in one file (docs/performance.md), at about twice the code size.
template <DepthFormat kFormat>
__attribute__((flatten)) void Renderer::shadeFanFormat(const TriangleContext& t,
                                                       const TriangleCoverage& coverage,
                                                       const FragmentInterpolator& interp) {
  auto fill = [&](auto&& shade) {
    if (uncertainty_) {
      fillSpans<kFormat, true, true>(t, coverage, interp, shade);
    } else {
      fillSpans<kFormat, false, true>(t, coverage, interp, shade);
    }
  };
  float* const colors = frame_.color.data();
  const bool blend = t.pass->blend;
  if (t.constant) {  // one stored colour for the whole triangle
    const float c0 = t.constant_stored[0];
    const float c1 = t.constant_stored[1];
    const float c2 = t.constant_stored[2];
    const float c3 = t.constant_stored[3];
    auto shade = [=](std::size_t index, const FragmentInterpolator::Row&, double) {
      float* c = colors + 4 * index;
      c[0] = c0;
      c[1] = c1;
      c[2] = c2;
      c[3] = c3;
      return TexelNote{};
    };
    if (uncertainty_) {  // only the depth plane was set up
      fillSpans<kFormat, true, false>(t, coverage, interp, shade);
    } else {
      fillSpans<kFormat, false, false>(t, coverage, interp, shade);
    }
    return;
  }
  // Untextured, unblended Gouraud and Phong: fragmentColor() and writeColor() written out
  // with the triangle's constants in locals (the same expressions: an untextured colour is
  // (ambient + diffuse) * 1 + specular, and x * 1 == x exactly).
  // (Phong fans that record shade_reach take the general path.)
  if (t.texture == nullptr && !blend && scene_.state.shading != Shading::Flat &&
      !options_.fragment_definition_only && !t.shading->shadowed &&
      !(uncertainty_ && (t.thin || t.short_normals) && scene_.state.shading == Shading::Phong)) {
    const bool rgba8 = color_format_ == ColorFormat::RGBA8;
    const float alpha = storeColor(t.material->opacity, color_format_);
    auto store = [=](std::size_t index, const glm::dvec3& c) {
      float* out = colors + 4 * index;
      if (rgba8) {
        out[0] = storeColor(c.x, ColorFormat::RGBA8);
        out[1] = storeColor(c.y, ColorFormat::RGBA8);
        out[2] = storeColor(c.z, ColorFormat::RGBA8);
      } else {
        out[0] = static_cast<float>(c.x);
        out[1] = static_cast<float>(c.y);
        out[2] = static_cast<float>(c.z);
      }
      out[3] = alpha;
    };
    if (scene_.state.shading == Shading::Gouraud) {
      const LitColor g0 = *t.gouraud[0];
      const LitColor g1 = *t.gouraud[1];
      const LitColor g2 = *t.gouraud[2];
      // Two loops: the shade_reach of thin triangles (uncertainty channels) in its own, so
      // that every other triangle's loop is the one without it.
      auto gouraud = [&](auto reach) {
        fill([&](std::size_t index, const FragmentInterpolator::Row& row, double dx) {
          const glm::dvec3 b = interp.barycentricAt(row, dx);
          const glm::dvec3 ad =
              b.x * g0.ambient_diffuse + b.y * g1.ambient_diffuse + b.z * g2.ambient_diffuse;
          const glm::dvec3 sp = b.x * g0.specular + b.y * g1.specular + b.z * g2.specular;
          store(index, ad + sp);
          TexelNote note;
          if constexpr (decltype(reach)::value)
            note.shade = gouraudReach(t, b, LitColor{ad, sp}, glm::dvec3(1.0), interp, row, dx);
          return note;
        });
      };
      if (uncertainty_ && t.thin) {
        gouraud(std::true_type{});
      } else {
        gouraud(std::false_type{});
      }
    } else {
      // Phong: four fragments at a time (shadePhongQuad() has the scalar form).
      PhongQuads quads(t, interp, colors, rgba8, alpha);
      fill(quads);
    }
    return;
  }
  // The general path, the definition the forms above are held to (FragmentLoop.* tests);
  // the texel note only where the uncertainty channels are kept.
  const bool notes = uncertainty_;
  auto general = [&](auto shading) {
    constexpr Shading kShading = decltype(shading)::value;
    fill([&](std::size_t index, const FragmentInterpolator::Row& row, double dx) {
      TexelNote note;
      const glm::dvec3 b = interp.barycentricAt(row, dx);
      writeColor(index,
                 fragmentColor<kShading>(t, b, nullptr, notes ? &note : nullptr, &interp, &row, dx),
                 blend);
      return note;
    });
  };
  switch (scene_.state.shading) {
    case Shading::Flat:
      general(std::integral_constant<Shading, Shading::Flat>{});
      break;
    case Shading::Gouraud:
      general(std::integral_constant<Shading, Shading::Gouraud>{});
      break;
    case Shading::Phong:
      general(std::integral_constant<Shading, Shading::Phong>{});
      break;
  }
}

GeneralSetup Renderer::generalSetup(const TriangleContext& t) const {
  const DrawPass& pass = *t.pass;
  const FragmentOps& ops = pass.ops;
  GeneralSetup g;
  if (ops.stencil && !stencil_.empty())
    g.face = t.front_facing ? &ops.stencil->front : &ops.stencil->back;
  g.near = ops.depth_range.x;
  g.scale = ops.depth_range.y - ops.depth_range.x;
  g.mapped = ops.depth_range != glm::dvec2(0.0, 1.0);
  g.tested = pass.depth_func != DepthFunc::Always && pass.depth_func != DepthFunc::Never;
  const bool masked = ops.color_mask != std::array<bool, 4>{true, true, true, true};
  // What the channels weigh the old colour by: alpha-over (1 - alpha); a blend function or
  // a masked write keeps any part of it (the conservative 0).
  g.alpha = static_cast<float>(
      pass.blend && !pass.blend_function ? std::clamp(t.material->opacity, 0.0, 1.0) : 0.0);
  g.composited = pass.blend || masked;
  return g;
}

namespace {
// True when the pass's scissor box rejects pixel (px, py).
bool scissored(const FragmentOps& ops, int px, int py) {
  if (!ops.scissor) return false;
  const Scissor& box = *ops.scissor;
  return px < box.x || py < box.y || px - box.x >= box.width || py - box.y >= box.height;
}
}  // namespace

// GL's per-fragment operations in order (glspec 4.6 chapter 14.9 and 17.3) for one fragment
// at pixel (px, py), framebuffer index `index`, window z `z_window` (before the depth range
// and offset): scissor, stencil test, depth test (window z mapped by the depth range,
// polygon offset added, clamped, quantized), the stencil op its outcome selects, depth
// write, id, blending and the colour mask. Its colour is fragmentColor() (the definition)
// at the barycentrics bary() returns (w.r.t. the original primitive's vertices); the
// uncertainty channels count every depth comparison (UncertaintyTracker::compared()).
// `interp`, `row`, `dx`: the fan's interpolator at the fragment (null for lines and
// points); `colour_reach` (8-bit units) joins the fragment's normal_reach.
template <Shading kShading, class Bary, class Extra>
void Renderer::generalFragment(const TriangleContext& t, const GeneralSetup& g, int px, int py,
                               std::size_t index, double z_window, float reach, Bary&& bary,
                               const FragmentInterpolator* interp,
                               const FragmentInterpolator::Row* row, double dx,
                               Extra&& extra_note) {
  const DrawPass& pass = *t.pass;
  const FragmentOps& ops = pass.ops;
  const std::uint32_t id = t.prim->id;
  ++fragments_;
  FragmentTrace f;
  if (trace_ != nullptr) {
    f.primitive = id;
    f.object = t.prim->object;
    f.barycentric = bary();
    f.offset = t.offset;
    f.line = t.line_trace;
  }
  auto traced = [&] {
    if (trace_ == nullptr) return;
    f.color_written = storedColor(index);
    trace_->push_back(std::move(f));
  };
  if (scissored(ops, px, py)) {
    f.scissor_pass = false;
    traced();
    return;
  }
  double z = z_window;
  if (g.mapped) z = g.near + g.scale * z;
  z = clampDepth(z + t.offset);
  const std::uint32_t key = depthKey(z, depth_format_);
  const std::uint32_t stored = depth_[index];
  f.window_z = z;
  f.stored_z = storedDepth(key, depth_format_);
  f.depth_against = storedDepth(stored, depth_format_);
  const StencilFace* face = g.face;
  if (face != nullptr) {
    const std::uint8_t s = stencil_[index];
    f.stencil_before = s;
    const auto mask = static_cast<unsigned>(face->read_mask);
    f.stencil_pass = compares(face->func, static_cast<unsigned>(face->ref) & mask, s & mask);
    if (!f.stencil_pass) {
      stencil_[index] = applyStencilOp(face->fail, s, face->ref, face->write_mask);
      f.stencil_after = stencil_[index];
      if (uncertainty_)
        gaps_.compared(index, z, t.depth_slope, reach, t.offset_steps, false, false, false);
      if (trace_ != nullptr)
        fragmentColor<kShading>(t, f.barycentric, &f.shading, nullptr, interp, row, dx);
      traced();
      return;
    }
  }
  const bool depth_pass = compares(pass.depth_func, key, stored);
  f.depth_pass = depth_pass;
  if (uncertainty_)
    gaps_.compared(index, z, t.depth_slope, reach, t.offset_steps, g.tested, pass.blend,
                   plane_keys_[index] == t.plane_key);
  if (face != nullptr) {
    const StencilOp op = depth_pass ? face->pass : face->depth_fail;
    stencil_[index] = applyStencilOp(op, stencil_[index], face->ref, face->write_mask);
    f.stencil_after = stencil_[index];
  }
  if (!depth_pass) {
    if (trace_ != nullptr)
      fragmentColor<kShading>(t, f.barycentric, &f.shading, nullptr, interp, row, dx);
    traced();
    return;
  }
  if (pass.depth_write) {
    depth_[index] = key;
    plane_keys_[index] = t.plane_key;
    if (uncertainty_) gaps_.storedDepth(index, z, t.depth_slope);
  }
  frame_.id[index] = id;
  TexelNote note;
  const glm::dvec3 b = trace_ != nullptr ? f.barycentric : bary();
  const glm::dvec4 src = fragmentColor<kShading>(t, b, trace_ != nullptr ? &f.shading : nullptr,
                                                 uncertainty_ ? &note : nullptr, interp, row, dx);
  glm::dvec4 out = src;
  if (pass.blend) {
    const glm::dvec4 dst = storedColor(index);
    out = pass.blend_function ? blendWithFunction(ops.blend_function, src, dst, color_format_)
                              : blendSourceOver(src, dst, color_format_);
  }
  float* c = &frame_.color[4 * index];
  for (int k = 0; k < 4; ++k)
    if (ops.color_mask[static_cast<std::size_t>(k)]) c[k] = storeColor(out[k], color_format_);
  if (uncertainty_) {
    const TexelNote extra = extra_note();
    gaps_.colourWritten(index, g.composited, g.alpha, std::min(note.dist, extra.dist),
                        std::max(note.alt, extra.alt), std::max(note.gain, extra.gain),
                        std::max(note.reach, extra.reach), std::max(note.shade, extra.shade),
                        std::max(note.normal, extra.normal));
  }
  traced();
}

template <Shading kShading>
void Renderer::fillSpansGeneral(const TriangleContext& t, const TriangleCoverage& coverage,
                                const FragmentInterpolator& interp) {
  const GeneralSetup g = generalSetup(t);
  ++triangles_drawn_;
  coverage.forEachSpan([&](int py, int x_begin, int x_end) {
    const double cy = py + 0.5;
    const FragmentInterpolator::Row row = interp.row(cy);
    const std::size_t row_index =
        static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_);
    for (int px = x_begin; px < x_end; ++px) {
      const double dx = interp.dx(px + 0.5);
      const std::size_t index = row_index + static_cast<std::size_t>(px - clip_.x0);
      const float reach = uncertainty_ ? t.depth_reach.at(px + 0.5, cy) : 0.0f;
      auto bary = [&] {
        return trace_ != nullptr ? interp.barycentric(px + 0.5, cy) : interp.barycentricAt(row, dx);
      };
      generalFragment<kShading>(t, g, px, py, index, interp.depthAt(row, dx), reach, bary, &interp,
                                &row, dx, [] { return TexelNote{}; });
    }
  });
}

// The fragments of one segment (or point, a == b): each fragment's parameter t is its centre
// projected onto a -> b (GL 14.5.1), its depth (1 - t) z_a + t z_b, its other attributes
// perspective-correct (the barycentrics w.r.t. the primitive's original vertices).
template <Shading kShading>
void Renderer::shadeLineFragments(const std::vector<LinePixel>& pixels, const WindowVertex& a,
                                  const WindowVertex& b, bool segment, double size,
                                  double depth_reach, bool polygon_edge) {
  TriangleContext& t = context_;
  const GeneralSetup g = generalSetup(t);
  const glm::dvec2 pa(a.x, a.y);
  const glm::dvec2 pb(b.x, b.y);
  const glm::dvec2 d = pb - pa;
  const double len2 = glm::dot(d, d);
  const double len = std::sqrt(len2);
  // Where GL's t and a driver's may part: drivers interpolate along the major axis (and
  // wide lines over their whole width), up to max(1, w) / 2 px along the segment from the
  // projection.
  const double slack_px = segment ? 0.5 * std::max(1.0, size) : 0.0;
  const double major = std::max(std::fabs(d.x), std::fabs(d.y));
  const double z_per_px =
      major > 0.0 ? std::fabs((b.z - a.z) * g.scale) / major * depth_steps_ : 0.0;
  t.depth_slope = static_cast<float>(z_per_px);
  const double planes[8] = {a.x, a.y, a.z, b.x, b.y, b.z, g.near, g.scale};
  const std::size_t h = std::hash<std::string_view>{}(
      std::string_view(reinterpret_cast<const char*>(planes), sizeof planes));
  t.plane_key = h == 0 ? 1 : h;

  // How far beyond the ends a parameter is taken: the fragments of a line's ends lie up to
  // w / 2 + 1 px past them (slack included), while the perspective weights stay positive
  // (bary_at() falls back to the window-space parameter where they would not).
  const double overshoot = len > 0.0 ? (std::max(1.0, size) / 2.0 + 1.0 + slack_px) / len : 0.0;
  auto param = [&](double px, double py) {
    if (!(len2 > 0.0)) return 0.0;
    // Not clamped (GL's t): a fragment centre beyond an end extrapolates, as the attribute
    // planes of a driver's line quad do; bounded so that the perspective weights stay
    // positive.
    return std::clamp(glm::dot(glm::dvec2(px, py) - pa, d) / len2, -overshoot, 1.0 + overshoot);
  };
  auto bary_at = [&](double s) {
    const double wa = (1.0 - s) * a.inv_w;
    const double wb = s * b.inv_w;
    const double q = wa + wb > 0.0 ? wb / (wa + wb) : s;
    return (1.0 - q) * a.bary + q * b.bary;
  };
  // The level of detail at parameter s: the texture coordinate's derivative along the
  // segment, the attribute constant across it (GL's t); NaN without mipmaps.
  const Texture* tex = t.texture;
  auto lambda_at = [&](double s, double& lo, double& hi) {
    lo = hi = std::numeric_limits<double>::quiet_NaN();
    if (t.chain == nullptr) return lo;
    if (!segment || !(len > 0.0)) {  // a point: constant coordinates, magnified
      lo = hi = lodOf(0.0, lod_state_);
      return lo;
    }
    const double e = 1e-4;
    const double s0 = std::max(0.0, s - e);
    const double s1 = std::min(1.0, s + e);
    auto uv = [&](double q) {
      const glm::dvec3 w = bary_at(q);
      return w.x * t.v[0]->uv + w.y * t.v[1]->uv + w.z * t.v[2]->uv;
    };
    const glm::dvec2 duv =
        (uv(s1) - uv(s0)) / (s1 - s0) * glm::dvec2(tex->width, tex->height);  // per unit t
    // GL's projection: d/dx = duv * dx / L^2; a driver interpolating along the major axis:
    // duv / major. The two differ by up to a factor of 2 (at 45 degrees).
    const double rho_spec = scaleFactor(duv * (d.x / len2), duv * (d.y / len2));
    const double rho_major = glm::length(duv) / major;
    const double l_spec = lodOf(rho_spec, lod_state_);
    const double l_major = lodOf(rho_major, lod_state_);
    lo = std::min(l_spec, l_major) - 0.5;
    hi = std::max(l_spec, l_major) + 0.5;
    return l_spec;
  };
  // The polygon's merged record of a shared pixel (outline_spread_), or null.
  auto spread_at = [&](std::size_t index) -> const OutlineSpread* {
    const auto it =
        std::lower_bound(outline_spread_.begin(), outline_spread_.end(), index,
                         [](const OutlineSpread& x, std::size_t i) { return x.index < i; });
    return it != outline_spread_.end() && it->index == index ? &*it : nullptr;
  };
  const double slack_t = len > 0.0 ? slack_px / len : 0.0;
  const bool half_width = segment && halfLineWidth(t.pass->ops.line_width);
  LineTrace& trace = t.line_trace;
  trace = LineTrace{};
  if (trace_ != nullptr) {
    trace.kind = segment ? LineTrace::Kind::Segment : LineTrace::Kind::Point;
    trace.polygon_edge = polygon_edge;
    trace.a = pa;
    trace.b = pb;
    trace.size = size;
  }
  const bool varies = kShading != Shading::Flat || tex != nullptr;
  for (const LinePixel& p : pixels) {
    const double cx = p.x + 0.5;
    const double cy = p.y + 0.5;
    const std::size_t index = frameIndex(p.x, p.y);
    const double s = segment ? param(cx, cy) : 0.0;
    const double z = (1.0 - s) * a.z + s * b.z;
    // A pixel another edge (vertex) of the same polygon also produces (outline_shared_): the
    // dry run records this fragment's depth and colour over its slack; the drawing run
    // widens its reaches to the range of all of them there (outline_spread_).
    const bool shared = !outline_shared_.empty() &&
                        std::binary_search(outline_shared_.begin(), outline_shared_.end(), index);
    // A record of a pixel outside the scissor box is never read (its fragments stop there).
    if (outline_dry_ && (!shared || scissored(t.pass->ops, p.x, p.y))) continue;
    // The fragment's level of detail and the interval a driver's may lie in (NaN: none).
    double lambda_lo = 0.0;
    double lambda_hi = 0.0;
    const double lambda = lambda_at(s, lambda_lo, lambda_hi);
    // Depth: the slack's reach, or at a shared pixel the farthest any of the polygon's
    // fragments there may be (each at its own slack).
    const double z_before = (1.0 - s + slack_t) * a.z + (s - slack_t) * b.z;
    const double z_after = (1.0 - s - slack_t) * a.z + (s + slack_t) * b.z;
    const double z_lo = std::min(z_before, z_after);
    const double z_hi = std::max(z_before, z_after);
    // The fragment's colour slack and texel channels: computed only where they are used (the
    // dry run's record of a shared pixel, a fragment that writes its colour), since they
    // cost up to 147 colour evaluations; c_lo, c_hi receive the colour's range.
    glm::dvec3 c_lo(0.0);
    glm::dvec3 c_hi(0.0);
    auto slack = [&]() -> TexelNote {
      // normal_reach: the colour's range over the parameters and levels of detail a
      // conforming driver may use here, against the reference's own (8-bit units).
      TexelNote extra;
      float& colour_reach = extra.normal;
      if (uncertainty_ && (varies || outline_dry_)) {
        t.line_lambda = lambda;
        const glm::dvec4 own = fragmentColor<kShading>(t, bary_at(s), nullptr);
        c_lo = c_hi = glm::dvec3(own);
        const double lo = lambda_lo;
        const double hi = lambda_hi;
        // Sampled at kSteps + 1 parameters; untextured, the largest change between neighbouring
        // samples is added (how far the smooth lighting can go past the samples between two).
        // A point (no slack) and a level of detail without an interval (lo == hi) give the
        // same sample every time: taken once (the same bits, a point's fragment 147x cheaper).
        constexpr int kSteps = 48;
        const int steps = slack_t > 0.0 ? kSteps : 0;
        const int levels = std::isnan(lo) || lo == hi ? 1 : 3;
        // What another implementation's inputs may change at each sampled parameter (a shadow
        // lookup that may go the other way, a rendered texture's texels): the driver's colour
        // at its parameter q may differ from the reference's there by that much, on top of
        // the slack, so the largest over q is added (the note at s alone missed a fragment lit
        // at another parameter where the reference's was in shadow: campaign s20261341 scene
        // 00039, 47 units on llvmpipe and zink).
        const bool cross_terms = (t.shading != nullptr && t.shading->shadowed) ||
                                 (t.texture != nullptr && !t.texture->uncertainty.empty());
        double inputs = 0.0;
        double worst = 0.0;
        double step = 0.0;
        glm::dvec4 last(0.0);
        for (int k = 0; k <= steps; ++k) {
          const double q =
              std::clamp(s - slack_t + 2.0 * slack_t * k / kSteps, -overshoot, 1.0 + overshoot);
          const glm::dvec3 w = bary_at(q);
          for (int l = 0; l < levels; ++l) {
            double ignore_lo = 0.0;
            double ignore_hi = 0.0;
            t.line_lambda = std::isnan(lo) ? lambda_at(q, ignore_lo, ignore_hi)
                                           : (l == 0 ? lo : (l == 1 ? hi : 0.5 * (lo + hi)));
            TexelNote q_note;
            const glm::dvec4 c =
                fragmentColor<kShading>(t, w, nullptr, cross_terms ? &q_note : nullptr);
            inputs = std::max(inputs, static_cast<double>(q_note.normal));
            c_lo = glm::min(c_lo, glm::dvec3(c));
            c_hi = glm::max(c_hi, glm::dvec3(c));
            for (int ch = 0; ch < 3; ++ch) {
              worst = std::max(worst, std::fabs(c[ch] - own[ch]));
              if (l == 0 && k > 0) step = std::max(step, std::fabs(c[ch] - last[ch]));
            }
            if (l == 0) last = c;
          }
        }
        if (tex == nullptr) {
          worst += step;
          c_lo -= step;
          c_hi += step;
        }
        colour_reach = static_cast<float>(255.0 * worst + inputs);
        // The range another edge's fragment here may take (outline_spread_) includes it too.
        if (inputs > 0.0) {
          c_lo -= inputs / 255.0;
          c_hi += inputs / 255.0;
        }
        if (shared && !outline_dry_) {
          if (const OutlineSpread* it = spread_at(index)) {
            const glm::dvec3 d_lo = glm::dvec3(own) - it->c_lo;
            const glm::dvec3 d_hi = it->c_hi - glm::dvec3(own);
            const double spread = std::max({d_lo.x, d_lo.y, d_lo.z, d_hi.x, d_hi.y, d_hi.z});
            colour_reach = std::max(colour_reach, static_cast<float>(255.0 * spread));
          }
        }
      }
      // The texel channels: the texels the filter may read there (a 2x2 footprint, at every
      // level of the lambda interval), as triangles' level-of-detail fragments record them
      // (texel_dist 0: always within; texel_alt the range times the light, plus a unit).
      if (uncertainty_ && tex != nullptr && !outline_dry_) {
        const glm::dvec3 w = bary_at(s);
        const glm::dvec2 uv = w.x * t.v[0]->uv + w.y * t.v[1]->uv + w.z * t.v[2]->uv;
        glm::dvec4 range(0.0);
        if (t.chain != nullptr) {
          const double lo = lambda_lo;
          const double hi = lambda_hi;
          const auto& chain = *t.chain;
          const int q = static_cast<int>(chain.size()) - 1;
          const auto coarsest =
              static_cast<std::size_t>(std::clamp(static_cast<int>(std::ceil(hi)), 0, q));
          const glm::dvec2 shift(1.0 / (256.0 * chain[coarsest]->width),
                                 1.0 / (256.0 * chain[coarsest]->height));
          range = lodRange(chain, uv, lo, hi, shift, lod_state_);
        } else {
          range =
              linearReachRange(*tex, uv, scene_.state.texture_wrap, 0.0, 0.0, textureRangeOf(tex));
        }
        LitColor lit = t.flat;
        if constexpr (kShading == Shading::Gouraud) {
          lit.ambient_diffuse = w.x * t.gouraud[0]->ambient_diffuse +
                                w.y * t.gouraud[1]->ambient_diffuse +
                                w.z * t.gouraud[2]->ambient_diffuse;
        } else if constexpr (kShading == Shading::Phong) {
          lit = shadePrepared(
              *t.shading, w.x * t.v[0]->world + w.y * t.v[1]->world + w.z * t.v[2]->world,
              safeNormalize(w.x * t.v[0]->normal + w.y * t.v[1]->normal + w.z * t.v[2]->normal));
        }
        double alt = 0.0;
        double light = 0.0;
        for (int c = 0; c < 3; ++c) {
          alt = std::max(alt, std::fabs(lit.ambient_diffuse[c] * range[c]));
          light = std::max(light, lit.ambient_diffuse[c]);
        }
        const double weight = t.pass->blend ? std::clamp(t.material->opacity, 0.0, 1.0) : 1.0;
        extra.dist = 0.0f;
        extra.alt = static_cast<float>(weight * (255.0 * alt + light));
      }
      t.line_lambda = lambda;
      return extra;
    };
    if (outline_dry_) {
      slack();
      outline_spread_.push_back({index, z_lo, z_hi, c_lo, c_hi});
      continue;
    }
    double spread_z = slack_px * z_per_px;
    if (const OutlineSpread* it = shared ? spread_at(index) : nullptr) {
      spread_z = std::max(spread_z,
                          std::max(z - it->z_lo, it->z_hi - z) * std::fabs(g.scale) * depth_steps_);
    }
    const double fragment_reach = depth_reach + spread_z + 1.0;
    t.line_lambda = lambda;
    if (trace_ != nullptr) {
      trace.t = s;
      trace.margin =
          segment ? segmentMargin(a, b, size, half_width, cx, cy) : pointMargin(a, size, cx, cy);
    }
    generalFragment<kShading>(
        t, g, p.x, p.y, index, z, static_cast<float>(uncertainty_ ? fragment_reach : 0.0),
        [&] { return bary_at(s); }, nullptr, nullptr, 0.0, slack);
  }
  t.line_lambda = std::numeric_limits<double>::quiet_NaN();
  trace = LineTrace{};
}

void Renderer::shadeLine(const std::vector<LinePixel>& pixels, const WindowVertex& a,
                         const WindowVertex& b, bool segment, double size, double depth_reach,
                         bool polygon_edge) {
  switch (scene_.state.shading) {
    case Shading::Flat:
      shadeLineFragments<Shading::Flat>(pixels, a, b, segment, size, depth_reach, polygon_edge);
      break;
    case Shading::Gouraud:
      shadeLineFragments<Shading::Gouraud>(pixels, a, b, segment, size, depth_reach, polygon_edge);
      break;
    case Shading::Phong:
      shadeLineFragments<Shading::Phong>(pixels, a, b, segment, size, depth_reach, polygon_edge);
      break;
  }
}

void Renderer::shadeFanGeneral(const TriangleContext& t, const TriangleCoverage& coverage,
                               const FragmentInterpolator& interp) {
  switch (scene_.state.shading) {
    case Shading::Flat:
      fillSpansGeneral<Shading::Flat>(t, coverage, interp);
      break;
    case Shading::Gouraud:
      fillSpansGeneral<Shading::Gouraud>(t, coverage, interp);
      break;
    case Shading::Phong:
      fillSpansGeneral<Shading::Phong>(t, coverage, interp);
      break;
  }
}

void Renderer::shadeFan(const TriangleContext& t, const TriangleCoverage& coverage,
                        const FragmentInterpolator& interp) {
  switch (depth_format_) {
    case DepthFormat::D16:
      shadeFanFormat<DepthFormat::D16>(t, coverage, interp);
      break;
    case DepthFormat::D24:
      shadeFanFormat<DepthFormat::D24>(t, coverage, interp);
      break;
    case DepthFormat::D32F:
      shadeFanFormat<DepthFormat::D32F>(t, coverage, interp);
      break;
  }
}

void Renderer::traceFan(const TriangleContext& t, const TriangleCoverage& coverage,
                        const FragmentInterpolator& interp) {
  switch (scene_.state.shading) {
    case Shading::Flat:
      traceSpans<Shading::Flat>(t, coverage, interp);
      break;
    case Shading::Gouraud:
      traceSpans<Shading::Gouraud>(t, coverage, interp);
      break;
    case Shading::Phong:
      traceSpans<Shading::Phong>(t, coverage, interp);
      break;
  }
}

// The fragment loop of tracePixel(): the same depth, test and writes as fillSpans() (the
// same expressions; FragmentInterpolator's per-pixel forms equal its row forms), with a
// FragmentTrace per fragment. The uncertainty channels are not computed when tracing.
template <Shading kShading>
void Renderer::traceSpans(const TriangleContext& t, const TriangleCoverage& coverage,
                          const FragmentInterpolator& interp) {
  const bool always = t.pass->depth_func == DepthFunc::Always;
  coverage.forEachSpan([&](int py, int x_begin, int x_end) {
    const double cy = py + 0.5;
    const std::size_t row =
        static_cast<std::size_t>(clip_.y1 - 1 - py) * static_cast<std::size_t>(fb_width_);
    for (int px = x_begin; px < x_end; ++px) {
      const double cx = px + 0.5;
      const std::size_t index = row + static_cast<std::size_t>(px - clip_.x0);
      const double z = clampDepth(interp.depth(cx, cy));
      const std::uint32_t key = depthKey(z, depth_format_);
      const std::uint32_t against = depth_[index];
      const bool pass = always || key < against;
      FragmentTrace f;
      f.primitive = t.prim->id;
      f.object = t.prim->object;
      f.barycentric = interp.barycentric(cx, cy);
      f.window_z = z;
      f.stored_z = storedDepth(key, depth_format_);
      f.depth_pass = pass;
      f.depth_against = storedDepth(against, depth_format_);
      const FragmentInterpolator::Row trace_row = interp.row(cy);
      const glm::dvec4 color = fragmentColor<kShading>(t, f.barycentric, &f.shading, nullptr,
                                                       &interp, &trace_row, interp.dx(cx));
      if (pass) {
        if (t.pass->depth_write) depth_[index] = key;
        if (t.pass->blend && defer_blends_) {
          kept_.push_back({static_cast<std::uint32_t>(index), blend_seq_, t.prim->id, 0.0f, z});
        } else {
          frame_.id[index] = t.prim->id;
        }
        writeColor(index, color, t.pass->blend);
      }
      f.color_written = storedColor(index);
      trace_->push_back(std::move(f));
    }
  });
}

}  // namespace rc::ref
