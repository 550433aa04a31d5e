// What the reference renderer adds to the uncertainty channels per fan triangle and per
// fragment: the depth-reach plane, the shade, normal and texel reaches (the derivations are
// docs/tolerances.md's; uncertainty.h keeps the per-pixel planes they go into).
#include "reference/renderer_internal.h"

#include "reference/texture_sampling.h"

namespace rc::ref {
namespace {

// Gouraud and Phong fan triangles thinner than this (px, the smallest altitude of the
// unsnapped triangle) record shade_reach (gouraudReach(), phongReach()): their pixels may
// have no neighbour of the same primitive across the thin direction, which is where the
// neighbours' gradient fails (docs/tolerances.md (b)); in thicker ones it does not, and
// the channel's cost (more than the rest of a Gouraud fragment's uncertainty work) is not
// spent.
constexpr double kThinAltitudePx = 1.0;

// The smallest altitude (px) of the window triangle: twice its area over its longest edge
// (0 for a degenerate one; NaN where a coordinate is not finite).
inline double minAltitudePx(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
  const double area2 = std::fabs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
  const double longest =
      std::max({std::hypot(b.x - a.x, b.y - a.y), std::hypot(c.x - b.x, c.y - b.y),
                std::hypot(a.x - c.x, a.y - c.y)});
  return longest > 0.0 ? area2 / longest : 0.0;
}

// Whether the interpolated normal of a triangle with these vertex normals can be short
// against them (|n| < max_k |N_k| / 2 somewhere): a vertex normal under half the longest,
// or two at 60 degrees or more. Elsewhere normal_reach is below 1e-5 of the colour, far
// inside the relative term (docs/tolerances.md (a)), and is not computed. `longest`: the
// longest |N_k| (normalReach() needs it too).
inline bool canBeShort(const glm::dvec3& n0, const glm::dvec3& n1, const glm::dvec3& n2,
                       double& longest) {
  const double l[3] = {glm::length(n0), glm::length(n1), glm::length(n2)};
  longest = std::max({l[0], l[1], l[2]});
  if (!(std::min({l[0], l[1], l[2]}) >= 0.5 * longest)) return true;  // NaN too
  return glm::dot(n0, n1) < 0.5 * l[0] * l[1] || glm::dot(n1, n2) < 0.5 * l[1] * l[2] ||
         glm::dot(n2, n0) < 0.5 * l[2] * l[0];
}

// 16 ulps of float32: the error a driver's interpolated normal may carry, relative to the
// magnitudes its planes hold (as kTexelCoordinateReach for texture coordinates).
constexpr double kNormalReach = 0x1p-20;

// How much of a fragment's colour stays in the pixel: its opacity when its pass blends,
// else all of it (the weight of the texel and reach channels it adds).
inline double blendWeight(const TriangleContext& t) {
  return t.pass->blend ? std::clamp(t.material->opacity, 0.0, 1.0) : 1.0;
}

// A reach as the float its channel stores: NaN (nothing known) as +inf (anything allowed).
inline float reachChannel(double reach) {
  return std::isnan(reach) ? std::numeric_limits<float>::infinity() : static_cast<float>(reach);
}

// sum_k |b_k|: 1 inside the triangle, more where the centre lies outside it.
inline double baryMagnitude(const glm::dvec3& b) {
  return std::fabs(b.x) + std::fabs(b.y) + std::fabs(b.z);
}

}  // namespace

const glm::dvec4& Renderer::textureRangeOf(const Texture* texture) {
  for (const auto& [t, range] : texture_ranges_)
    if (t == texture) return range;
  texture_ranges_.emplace_back(texture, textureRange(*texture));
  return texture_ranges_.back().second;
}

void Renderer::setUpFanChannels(TriangleContext& t, const FragmentInterpolator& interp,
                                const WindowVertex* wv, const double* depth_reach, int i,
                                bool clipped) {
  t.depth_slope = static_cast<float>(interp.depthSlope() * depth_steps_);
  t.depth_reach.setup(wv[0], wv[i], wv[i + 1], depth_reach[0], depth_reach[i], depth_reach[i + 1]);
  // Not for the pieces of a clipped triangle: their clip vertices can lie 10^5 px away
  // (a near-plane cut), where the first-order bound grows to a tenth of the depth range
  // (docs/tolerances.md "Plane set-up": what is left uncovered there).
  if (!clipped) {
    // Its own set-up, or that of a piece a side clip leaves (an implementation's choice).
    const double setup =
        std::max(planeSetupError(wv[0], wv[i], wv[i + 1]),
                 sideClipSetupError(wv[0], wv[i], wv[i + 1], scene_.width, scene_.height));
    t.depth_reach.widen(setup * depth_steps_);
  }
  t.texel_choice = t.texture != nullptr;
  t.thin = scene_.state.shading != Shading::Flat &&
           !(minAltitudePx(wv[0], wv[i], wv[i + 1]) >= kThinAltitudePx);
  if (scene_.state.shading == Shading::Phong) {
    t.short_normals = canBeShort(t.v[0]->normal, t.v[1]->normal, t.v[2]->normal, t.n_len_max);
    if (t.short_normals) {
      t.n_max = 0.0;
      for (const WindowVertex* w : {&wv[0], &wv[i], &wv[i + 1]}) {
        const glm::dvec3 n =
            w->bary.x * t.v[0]->normal + w->bary.y * t.v[1]->normal + w->bary.z * t.v[2]->normal;
        t.n_max = std::max(t.n_max, glm::length(n) * std::fabs(w->inv_w));
      }
    }
  }
  if (t.thin && scene_.state.shading == Shading::Gouraud) {
    for (int c = 0; c < 3; ++c) {
      t.ad_grad[c] = glm::dvec2(0.0);
      t.sp_grad[c] = glm::dvec2(0.0);
      for (int k = 0; k < 3; ++k) {
        t.ad_grad[c] += t.gouraud[k]->ambient_diffuse[c] * interp.numeratorGradient(k);
        t.sp_grad[c] += t.gouraud[k]->specular[c] * interp.numeratorGradient(k);
      }
    }
    t.den_grad = interp.denominatorGradient();
  }
  if (t.texel_choice && magFilter(scene_.state) == TextureFilter::Linear)
    t.texture_range = textureRangeOf(t.texture);
  if (t.texel_choice) {
    t.uq_max = glm::dvec2(0.0);
    for (const WindowVertex* w : {&wv[0], &wv[i], &wv[i + 1]}) {
      const glm::dvec2 uv =
          w->bary.x * t.v[0]->uv + w->bary.y * t.v[1]->uv + w->bary.z * t.v[2]->uv;
      t.uq_max = glm::max(t.uq_max, glm::abs(uv * w->inv_w));
    }
  }
}

// (TriangleContext::thin; docs/tolerances.md (b)): its colour T * AD + S
// follows planes through the triangle's vertices (AD and S interpolated; T, the texture,
// has its own channels). Another implementation's planes go through its snapped vertices:
// with each moved by up to d px, the plane's value at the pixel moves, to first order, by
// grad C . sum_k b_k delta_k, at most |grad C| * sum_k |b_k| * d (b the pixel's
// barycentrics: sum |b_k| = 1 inside the triangle, more where the centre is covered only by
// the snapped triangle, as at a sliver's edge). The largest channel's |grad C| * sum |b_k|
// in 8-bit units per px, weighted by alpha when the fragment is blended; infinite where it
// is not a number.
float Renderer::gouraudReach(const TriangleContext& t, const glm::dvec3& b, const LitColor& lit,
                             const glm::dvec3& tex, const FragmentInterpolator& interp,
                             const FragmentInterpolator::Row& row, double dx) const {
  // grad v = (sum_k a_k grad N_k - v grad D) / D for v = AD_c and S_c (the sums per
  // triangle: TriangleContext::ad_grad, sp_grad).
  const double inv = 1.0 / interp.invWAt(row, dx);
  double worst2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec2 ad = (t.ad_grad[c] - lit.ambient_diffuse[c] * t.den_grad) * inv;
    const glm::dvec2 sp = (t.sp_grad[c] - lit.specular[c] * t.den_grad) * inv;
    const glm::dvec2 g = tex[c] * ad + sp;
    const double g2 = g.x * g.x + g.y * g.y;
    if (!(g2 <= worst2)) worst2 = g2;  // NaN kept (infinite below)
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * std::sqrt(worst2) * baryMagnitude(b) * weight;
  return reachChannel(reach);
}

// normal_reach of a Phong fragment whose interpolated normal can be short
// (TriangleContext::short_normals; docs/tolerances.md (a)), where it is shorter than half
// the longest vertex normal (0 elsewhere). A driver interpolates n = sum
// b_k N_k in float32 with an error e per component of some ulps of the magnitudes its
// planes hold: kNormalReach * (largest |N_k / w_k| / |1 / w| + |grad n| * image size),
// |e| <= sqrt(3) times that. Normalising moves the direction by at most 2 |e| / |n| (2 when
// |e| >= |n|). Each light's diffuse term moves by kd L att times that, its specular term by
// ks L att s times it (Blinn; Phong's reflected vector moves 4 times as much), s at least 1.
// 8-bit units, the largest channel, weighted by alpha when blended.
float Renderer::normalReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& p,
                            const FragmentInterpolator& interp,
                            const FragmentInterpolator::Row& row, double dx) const {
  const glm::dvec3 n = b.x * t.v[0]->normal + b.y * t.v[1]->normal + b.z * t.v[2]->normal;
  const double len = glm::length(n);
  // As long as the normal from planes is (at least half) as long as its vertices', the
  // relative term (a) covers its rounding; beyond, it grows as 1 / |n|.
  if (len >= 0.5 * t.n_len_max) return 0.0f;
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  double gradient = 0.0;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec3 nc(t.v[0]->normal[c], t.v[1]->normal[c], t.v[2]->normal[c]);
    gradient = std::max(gradient, std::hypot(glm::dot(db[0], nc), glm::dot(db[1], nc)));
  }
  const double q = std::fabs(interp.invWAt(row, dx));
  const double image = std::max(scene_.width, scene_.height);
  const double e = std::sqrt(3.0) * kNormalReach * (t.n_max / q + gradient * image);
  const double direction = len > e ? 2.0 * e / len : 2.0;
  const PreparedShading& s = *t.shading;
  const double spec = std::max(s.shininess, 1.0) * (s.blinn ? 1.0 : 4.0);
  glm::dvec3 k(0.0);
  for (const PreparedLight& light : s.lights) {
    double att = 1.0;
    if (light.attenuated) {
      const double r = glm::length(light.position - p);
      att = s.attenuation == Attenuation::Inverse ? 1.0 / r : 1.0 / (r * r);
    }
    k += glm::abs(light.radiance) * att * (glm::abs(s.kd) + spec * glm::abs(s.ks));
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * direction * std::max({k.x, k.y, k.z}) * weight;
  return reachChannel(reach);
}

// The shadow lookup's freedoms (docs/tolerances.md "Shadow maps"): the driver's fragment
// sees the surface kMapBandPx away at most (its snapped vertices move the attribute planes),
// its float32 matrix product moves (s, t, r) by kShadowCoordUlps units of 2^-24 of the
// magnitudes summed, and its stored map may differ within ShadowMapData::lo, hi.
namespace {
constexpr double kShadowBandPx = 0.1;
constexpr double kShadowCoordUlps = 16.0;
}  // namespace

float Renderer::shadowReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                            const FragmentInterpolator* interp,
                            const FragmentInterpolator::Row* row, double dx) const {
  const PreparedShading& s = *t.shading;
  const glm::dvec3 p = b.x * t.v[0]->world + b.y * t.v[1]->world + b.z * t.v[2]->world;
  const glm::dvec3 n =
      safeNormalize(b.x * t.v[0]->normal + b.y * t.v[1]->normal + b.z * t.v[2]->normal);
  glm::dvec3 dp[2] = {glm::dvec3(0.0), glm::dvec3(0.0)};
  if (interp != nullptr && row != nullptr) {
    glm::dvec3 db[2];
    interp->barycentricGradient(*row, dx, b, db);
    for (int a = 0; a < 2; ++a)
      dp[a] = db[a].x * t.v[0]->world + db[a].y * t.v[1]->world + db[a].z * t.v[2]->world;
  }
  ShadingTerms terms;
  shadePrepared(s, p, n, &terms, false);  // each light's terms before its lookup
  double reach = 0.0;
  for (std::size_t i = 0; i < s.lights.size(); ++i) {
    const ShadowLookup* lookup = s.lights[i].shadow;
    if (lookup == nullptr) continue;
    const ShadowMapData& map = *lookup->data;
    const ShadowCoord c = shadowCoord(*lookup, p);
    if (!c.in_front) continue;
    // Per px of the fragment's position, and the float32 error of the product.
    glm::dvec3 move(0.0);
    for (const glm::dvec3& d : dp) {
      const ShadowCoord q = shadowCoord(*lookup, p + d);
      if (!q.in_front) continue;
      move += glm::abs(glm::dvec3(q.s - c.s, q.t - c.t, q.r - c.r)) * kShadowBandPx;
    }
    const glm::dvec4 h(p, 1.0);
    const glm::dvec4 m = glm::abs(map.matrix[0] * h.x) + glm::abs(map.matrix[1] * h.y) +
                         glm::abs(map.matrix[2] * h.z) + glm::abs(map.matrix[3]);
    const double w = std::fabs((map.matrix * h).w);
    const double ulp = kShadowCoordUlps * std::ldexp(1.0, -24);
    const double es = ulp * (m.x + std::fabs(c.s) * m.w) / w;
    const double et = ulp * (m.y + std::fabs(c.t) * m.w) / w;
    const double er = ulp * (m.z + std::fabs(c.r + lookup->bias) * m.w) / w;
    const ShadowRange range =
        shadowRange(*lookup, p, (move.x + es) * map.width, (move.y + et) * map.height, move.z + er);
    const double f = shadowFactor(*lookup, p);
    const double spread = std::max(range.hi - f, f - range.lo);
    if (!(spread > 0.0)) continue;
    const glm::dvec3 light = terms.lights[i].diffuse * tex + terms.lights[i].specular;
    reach += spread * std::max({light.x, light.y, light.z});
  }
  return reachChannel(255.0 * reach * blendWeight(t));
}

// shade_reach of a Phong fragment of a fan triangle thinner than kThinAltitudePx
// (TriangleContext::thin):
// the same first-order bound as gouraudReach(), sum |b_k| * |grad C|, with C = T * AD + S
// lit from the interpolated position and normal, which is not linear in them: grad C by
// forward differences along the barycentrics' screen derivatives, with a step that moves
// them by 1e-6 (the quotient is then within about 1e-6 of the derivative, relative, where
// the lighting is smooth; far inside what the bound is used for). The texture stays T (its
// change has the texel terms). 8-bit units per px, weighted by alpha when blended.
float Renderer::phongReach(const TriangleContext& t, const glm::dvec3& b, const glm::dvec3& tex,
                           const LitColor& lit, const FragmentInterpolator& interp,
                           const FragmentInterpolator::Row& row, double dx) const {
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  auto colour = [&](const glm::dvec3& q) {
    const glm::dvec3 p = q.x * t.v[0]->world + q.y * t.v[1]->world + q.z * t.v[2]->world;
    const glm::dvec3 n =
        safeNormalize(q.x * t.v[0]->normal + q.y * t.v[1]->normal + q.z * t.v[2]->normal);
    const LitColor l = shadePrepared(*t.shading, p, n);
    return l.ambient_diffuse * tex + l.specular;
  };
  const glm::dvec3 c0 = lit.ambient_diffuse * tex + lit.specular;
  glm::dvec3 g[2];
  for (int a = 0; a < 2; ++a) {
    const double scale = std::max({std::fabs(db[a].x), std::fabs(db[a].y), std::fabs(db[a].z)});
    if (!(scale > 0.0)) {  // no change along this axis (or NaN: below)
      g[a] =
          std::isnan(scale) ? glm::dvec3(std::numeric_limits<double>::infinity()) : glm::dvec3(0.0);
      continue;
    }
    const double h = 1e-6 / scale;  // px
    g[a] = (colour(b + h * db[a]) - c0) / h;
  }
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double n = std::sqrt(g[0][c] * g[0][c] + g[1][c] * g[1][c]);
    if (!(n <= worst)) worst = n;  // NaN kept (infinite below)
  }
  const double weight = blendWeight(t);
  const double reach = 255.0 * worst * baryMagnitude(b) * weight;
  return reachChannel(reach);
}

// The texel channels of a textured fragment (docs/tolerances.md (c), (d), (e)), in 8-bit
// units weighted by alpha when the fragment is blended: the gain (how much a texel unit
// moves the colour: the ambient and diffuse light on the texture); with linear filtering
// how far float rounding may move the sample (texels) and the colour range of every
// footprint within that reach; with nearest filtering how far (px) the sample is from a
// texel boundary beyond float rounding and how much the colour would change with the
// texel(s) across it.
TexelNote Renderer::texelNote(const TriangleContext& t, const glm::dvec2& uv, const glm::dvec3& b,
                              const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                              const FragmentInterpolator::Row& row, double dx) const {
  const double weight = blendWeight(t);
  TexelNote note;
  note.gain = static_cast<float>(
      weight * std::max({ambient_diffuse.x, ambient_diffuse.y, ambient_diffuse.z, 0.0}));
  glm::dvec3 db[2];
  interp.barycentricGradient(row, dx, b, db);
  const glm::dvec3 u(t.v[0]->uv.x, t.v[1]->uv.x, t.v[2]->uv.x);
  const glm::dvec3 v(t.v[0]->uv.y, t.v[1]->uv.y, t.v[2]->uv.y);
  const double w = t.texture->width;
  const double h = t.texture->height;
  const double q = interp.invWAt(row, dx);
  const double image = std::max(scene_.width, scene_.height);
  TexelAxis s;
  s.coord = uv.x * w;
  s.gradient = w * std::hypot(glm::dot(db[0], u), glm::dot(db[1], u));
  s.reach = kTexelCoordinateReach *
            (w * std::max(std::fabs(uv.x), t.uq_max.x / std::fabs(q)) + s.gradient * image);
  TexelAxis tt;
  tt.coord = uv.y * h;
  tt.gradient = h * std::hypot(glm::dot(db[0], v), glm::dot(db[1], v));
  tt.reach = kTexelCoordinateReach *
             (h * std::max(std::fabs(uv.y), t.uq_max.y / std::fabs(q)) + tt.gradient * image);
  if (t.chain != nullptr) {
    // Level of detail: the colour range over every lambda and sample position a legal
    // implementation may use (lodNote()), always within reach (texel_dist 0).
    TexelNote lod =
        lodNote(t, uv, ambient_diffuse, interp, row, dx, s.reach + kSnapDisagreementPx * s.gradient,
                tt.reach + kSnapDisagreementPx * tt.gradient);
    lod.gain = note.gain;
    return lod;
  }
  if (magFilter(scene_.state) == TextureFilter::Linear) {
    // Where float32 interpolation may move the sample (reach, texels), the filter may
    // read any footprint within it: the colour range over all of them.
    const glm::dvec4 range = linearReachRange(*t.texture, uv, scene_.state.texture_wrap, s.reach,
                                              tt.reach, t.texture_range);
    double alt = 0.0;
    for (int c = 0; c < 3; ++c) alt = std::max(alt, std::fabs(ambient_diffuse[c] * range[c]));
    note.alt = static_cast<float>(255.0 * alt * weight);
    const double reach = s.reach + tt.reach;
    note.reach = reachChannel(reach);
    return note;
  }
  const TexelChoice choice = nearestTexelChoice(*t.texture, s, tt, scene_.state.texture_wrap, 1.0);
  note.dist = static_cast<float>(choice.dist_px);
  double alt = 0.0;
  for (int k = 0; k < choice.alternatives; ++k)
    for (int c = 0; c < 3; ++c)
      alt = std::max(alt, std::fabs(ambient_diffuse[c] * (choice.alt[k][c] - choice.chosen[c])));
  note.alt = static_cast<float>(255.0 * alt * weight);
  return note;
}

}  // namespace rc::ref

namespace rc::ref {

// The freedom GL gives level-of-detail sampling, as a colour range (docs/tolerances.md
// "Level of detail"): the scale factor may be any f with max(mu, mv) <= f <= mu + mv (mu,
// mv the largest |derivative| of u and of v), from derivatives a driver may take anywhere
// in its 2x2 quad (a finite difference across a pixel is the derivative somewhere within
// it: the fragment's and its eight neighbours' exact derivatives bound them), lambda to 0.09
// either way (an approximated log2), and the sample may move by its float32 reach and by a
// filter weight quantised to 8 bits (1/256 texel of the coarsest level read). The note's
// texel_alt is the lit colour range over that lambda interval and those positions
// (lodRange()) plus a unit for the 8-bit filtered texel; texel_dist 0 (always within).
std::pair<double, double> Renderer::lodInterval(const TriangleContext& t,
                                                const FragmentInterpolator& interp,
                                                const FragmentInterpolator::Row& row,
                                                double dx) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr int kLodReachPx = 1;            // a quad's finite differences: within a pixel
  double lo[4] = {kInf, kInf, kInf, kInf};  // |ux|, |vx|, |uy|, |vy|
  double hi[4] = {0.0, 0.0, 0.0, 0.0};
  for (int oy = -kLodReachPx; oy <= kLodReachPx; ++oy) {
    const FragmentInterpolator::Row r = oy == 0 ? row : interp.shiftedRow(row, oy);
    for (int ox = -kLodReachPx; ox <= kLodReachPx; ++ox) {
      const glm::dvec3 bb = interp.barycentricAt(r, dx + ox);
      glm::dvec2 d_dx;
      glm::dvec2 d_dy;
      uvDerivatives(t, interp, r, dx + ox, bb, d_dx, d_dy);
      const double v[4] = {std::fabs(d_dx.x), std::fabs(d_dx.y), std::fabs(d_dy.x),
                           std::fabs(d_dy.y)};
      for (int k = 0; k < 4; ++k) {
        if (std::isnan(v[k])) continue;
        lo[k] = std::min(lo[k], v[k]);
        hi[k] = std::max(hi[k], v[k]);
      }
    }
  }
  const double rho_lo = std::max(std::max(lo[0], lo[2]), std::max(lo[1], lo[3]));
  const double rho_hi = std::max(hi[0], hi[2]) + std::max(hi[1], hi[3]);
  // llvmpipe takes log2 by a piecewise-linear approximation (gallivm's lp_build_fast_log2:
  // log2(1 + m) ~ m, up to 0.0861 off; half that where it squares rho first): campaign
  // s20261296 scenes 00237 and 00705 (mipmap profile) on llvmpipe and zink lie up to 0.066
  // below the exact lambda.
  constexpr double kLodPrecision = 0.09;
  const double bias = std::clamp(lod_state_.bias, -kMaxLodBias, kMaxLodBias);
  auto clampLod = [&](double l) {
    if (std::isnan(l)) l = lod_state_.min_lod;
    return std::clamp(l, lod_state_.min_lod, lod_state_.max_lod);
  };
  // The precision applies after the clamps too: a lambda clamped to max_lod = 3.5 sits on
  // a nearest-mip boundary that llvmpipe rounds up (level 4) where the spec's formula
  // gives level 3 (campaign s20261295 scene 00165, mipmap profile).
  return {clampLod(std::log2(rho_lo) + bias) - kLodPrecision,
          clampLod(std::log2(rho_hi) + bias) + kLodPrecision};
}

TexelNote Renderer::lodNote(const TriangleContext& t, const glm::dvec2& uv,
                            const glm::dvec3& ambient_diffuse, const FragmentInterpolator& interp,
                            const FragmentInterpolator::Row& row, double dx, double reach_s,
                            double reach_t) const {
  const auto [lambda_lo, lambda_hi] = lodInterval(t, interp, row, dx);
  const std::vector<const Texture*>& chain = *t.chain;
  const int q = static_cast<int>(chain.size()) - 1;
  const int coarsest = std::clamp(static_cast<int>(std::ceil(lambda_hi)), 0, q);
  const glm::dvec2 shift(
      reach_s / chain[0]->width + 1.0 / (256.0 * chain[static_cast<std::size_t>(coarsest)]->width),
      reach_t / chain[0]->height +
          1.0 / (256.0 * chain[static_cast<std::size_t>(coarsest)]->height));
  const glm::dvec4 range = lodRange(chain, uv, lambda_lo, lambda_hi, shift, lod_state_);
  const double weight = blendWeight(t);
  double alt = 0.0;
  double light = 0.0;
  for (int c = 0; c < 3; ++c) {
    alt = std::max(alt, std::fabs(ambient_diffuse[c] * range[c]));
    light = std::max(light, ambient_diffuse[c]);
  }
  TexelNote note;
  note.dist = 0.0f;
  note.alt = static_cast<float>(weight * (255.0 * alt + light));
  return note;
}

}  // namespace rc::ref
