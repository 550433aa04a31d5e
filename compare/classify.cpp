// The pass over a pair's pixels (Comparator::run): each pixel's class and its depth and
// colour errors, row by row. The common pixel (same id, small errors) takes a short
// branch-light path; the unusual ones go to out-of-line helpers (allowances.cpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "compare/compare_internal.h"
#include "fixtures/big_buffer.h"

namespace rc {

void reserveMaps(ClassMaps& maps, int width, int height) {
  maps.width = width;
  maps.height = height;
  const std::size_t n = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
  assignBig(maps.pixel_class, n, PixelClass::Background);
  assignBig(maps.depth_steps, n, 0.0f);
  assignBig(maps.depth_tolerance, n, 0.0f);
  assignBig(maps.shading_abs, n, 0.0f);
  assignBig(maps.shading_tolerance, n, 0.0f);
}

}  // namespace rc

namespace rc::detail {
namespace {

template <typename V, typename T>
inline V load(const T* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <typename V, typename T>
inline void store(T* p, V v) {
  std::memcpy(p, &v, sizeof v);
}

// Lane masks are 0 or -1. x86 reads the four sign bits at once (movmskps); elsewhere the
// lanes are combined.
inline int signBits(V4i m) {
#if defined(__SSE__)
  return __builtin_ia32_movmskps(reinterpret_cast<V4f>(m));
#else
  return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
}
inline bool any(V4i m) { return signBits(m) != 0; }
inline bool all(V4i m) { return signBits(m) == 15; }

inline V4f absf(V4f v) { return reinterpret_cast<V4f>(reinterpret_cast<V4i>(v) & 0x7fffffff); }
inline V2d absd(V2d v) {
  return reinterpret_cast<V2d>(reinterpret_cast<V2l>(v) & 0x7fffffffffffffffLL);
}
// a > b ? a : b per lane (maxps on x86; the inputs are never NaN here).
inline V4f maxf(V4f a, V4f b) { return a > b ? a : b; }
inline V4i nonFiniteLanes(V4f v) { return (reinterpret_cast<V4i>(v) & 0x7f800000) == 0x7f800000; }
// Largest lane (one pixel's R G B A).
inline float lanesMax(V4f v) {
  const V4f s1 = maxf(v, __builtin_shufflevector(v, v, 1, 0, 3, 2));
  const V4f s2 = maxf(s1, __builtin_shufflevector(s1, s1, 2, 3, 0, 1));
  return s2[0];
}
inline bool any2(V2l m) {
#if defined(__SSE2__)
  return __builtin_ia32_movmskpd(reinterpret_cast<V2d>(m)) != 0;
#else
  return (m[0] | m[1]) != 0;
#endif
}
// Two pairs of doubles as four floats.
inline V4f join(V2d lo, V2d hi) {
#if defined(__SSE2__)
  return reinterpret_cast<V4f>(_mm_movelh_ps(_mm_cvtpd_ps(reinterpret_cast<__m128d>(lo)),
                                             _mm_cvtpd_ps(reinterpret_cast<__m128d>(hi))));
#else
  using V2f = float __attribute__((vector_size(8)));
  return __builtin_shufflevector(__builtin_convertvector(lo, V2f), __builtin_convertvector(hi, V2f),
                                 0, 1, 2, 3);
#endif
}
inline V2d maxd(V2d a, V2d b) { return a > b ? a : b; }
// Largest lane of each of four vectors, as one vector: [max d0, max d1, max d2, max d3].
inline V4f pixelMaxima(const V4f* d) {
  const V4f m01 = maxf(__builtin_shufflevector(d[0], d[1], 0, 1, 4, 5),
                       __builtin_shufflevector(d[0], d[1], 2, 3, 6, 7));
  const V4f m23 = maxf(__builtin_shufflevector(d[2], d[3], 0, 1, 4, 5),
                       __builtin_shufflevector(d[2], d[3], 2, 3, 6, 7));
  return maxf(__builtin_shufflevector(m01, m23, 0, 2, 4, 6),
              __builtin_shufflevector(m01, m23, 1, 3, 5, 7));
}
// float <-> double lanes. GCC scalarises the generic form of the high half, so x86 gets
// the two-instruction intrinsic sequences.
inline V2d lowHalf(V4f v) {
#if defined(__SSE2__)
  return reinterpret_cast<V2d>(_mm_cvtps_pd(reinterpret_cast<__m128>(v)));
#else
  return __builtin_convertvector(__builtin_shufflevector(v, v, 0, 1), V2d);
#endif
}
inline V2d highHalf(V4f v) {
#if defined(__SSE2__)
  const __m128 m = reinterpret_cast<__m128>(v);
  return reinterpret_cast<V2d>(_mm_cvtps_pd(_mm_movehl_ps(m, m)));
#else
  return __builtin_convertvector(__builtin_shufflevector(v, v, 2, 3), V2d);
#endif
}

void tally(float v, int channel, NonFiniteCounts& counts) {
  if (std::isnan(v))
    ++counts.nan[channel];
  else if (std::isinf(v))
    ++counts.inf[channel];
}

}  // namespace

void Comparator::run(ClassMaps* maps) {
  maps_ = maps;
  compareStencil();
  if (e_.multisampled()) {
    allocateMaps();
    for (int y = 0; y < e_.height; ++y) runMultisampleRow(y);
    finish();
    return;
  }
  allocateMaps();
  for (int y = 0; y < e_.height; ++y) {
    if (maps) {
      scale_.quantized
          ? (quantized_color_ ? runRowFast<true, true, true>(y) : runRowFast<true, false, true>(y))
          : (quantized_color_ ? runRowFast<false, true, true>(y)
                              : runRowFast<false, false, true>(y));
    } else if (scale_.quantized) {
      quantized_color_ ? runRowFast<true, true, false>(y) : runRowFast<true, false, false>(y);
    } else {
      quantized_color_ ? runRowFast<false, true, false>(y) : runRowFast<false, false, false>(y);
    }
  }
  finish();
}

// The general path, and the definition of each pixel's class, errors and allowances: any
// pixel, NaN/Inf, one at a time. Pixels [x0, x1) of row y. runRowFast() below is held to it
// (FastPathTest.VectorAndGeneralPathsAgree; the general path runs alone when maps are asked).
template <bool kMaps>
void Comparator::runRange(int y, int x0, int x1) {
  ClassMaps* maps = maps_;
  const std::size_t row = static_cast<std::size_t>(y) * e_.width;
  const std::uint32_t* ida = &e_.id[row];
  const std::uint32_t* idb = &a_.id[row];
  const float* za = &e_.depth[row];
  const float* zb = &a_.depth[row];
  const float* ca = &e_.color[row * 4];
  const float* cb = &a_.color[row * 4];
  const double depth_warn = tol_.depth.warn;
  const float shade_warn = static_cast<float>(tol_.shading.warn);
  double shade_sum = 0.0;
  double shade_sq = 0.0;
  double depth_sum = 0.0;
  for (int x = x0; x < x1; ++x) {
    const std::uint32_t a = ida[x];
    const std::uint32_t b = idb[x];
    const std::size_t i = row + x;
    const float* pa = ca + static_cast<std::ptrdiff_t>(x) * 4;
    const float* pb = cb + static_cast<std::ptrdiff_t>(x) * 4;
    bool depth_finite = !isNonFinite(za[x]) && !isNonFinite(zb[x]);
    bool color_finite = true;
    for (int c = 0; c < 4; ++c)
      color_finite = color_finite && !isNonFinite(pa[c]) && !isNonFinite(pb[c]);
    if (!depth_finite || !color_finite) {
      for (int c = 0; c < 4; ++c) {
        tally(pa[c], c, r_.nonfinite_expected);
        tally(pb[c], c, r_.nonfinite_actual);
      }
      tally(za[x], 4, r_.nonfinite_expected);
      tally(zb[x], 4, r_.nonfinite_actual);
    }
    if (a != b) {
      const PixelClass cls = classifyMismatch(x, y, i, a, b);
      if (kMaps) maps->pixel_class[i] = cls;
      continue;
    }
    if (a == 0) {  // background on both sides: the clear values
      clearedPixel(i, true, za[x], zb[x], pa, pb);
      continue;
    }
    ++vis_match_;
    if (kMaps) maps->pixel_class[i] = PixelClass::Match;

    // Depth.
    if (!depth_finite) {
      depthNonFinite(i);
      if (kMaps) maps->depth_steps[i] = std::numeric_limits<float>::quiet_NaN();
    } else {
      const double dz = std::fabs(scale_(za[x]) - scale_(zb[x]));
      depth_sum += dz;
      r_.depth.histogram.add(dz);
      if (dz > depth_max_) {
        depth_max_ = dz;
        depth_max_at_ = i;
      }
      if (dz > depth_warn) depthOverBase(x, y, i, dz);
      if (kMaps) maps->depth_steps[i] = static_cast<float>(dz);
    }

    // Shading.
    if (!colorsComparable(pa, pb)) {
      shadingNonFinite(i);
      if (kMaps) maps->shading_abs[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    float d[4];
    for (int c = 0; c < 4; ++c) d[c] = colorError(pa[c], pb[c]);
    const float e = std::max(std::max(d[0], d[1]), std::max(d[2], d[3]));
    shade_sum += (d[0] + d[1]) + (d[2] + d[3]);
    shade_sq += (d[0] * d[0] + d[1] * d[1]) + (d[2] * d[2] + d[3] * d[3]);
    for (int c = 0; c < 4; ++c) shade_max_rgba_[c] = std::max(shade_max_rgba_[c], d[c]);
    r_.shading.histogram.add(e);
    if (e > shade_max_) {
      shade_max_ = e;
      shade_max_at_ = i;
    }
    if (e > shade_warn) shadingOver(x, y, i, d);
    if (kMaps) maps->shading_abs[i] = e;
  }
  shade_sum_ += shade_sum;
  shade_sq_ += shade_sq;
  depth_sum_ += depth_sum;
}

// The fast path for a row: chunks of four pixels that all show the same primitive on
// both sides with finite values go through vector code; background chunks are only
// checked for NaN/Inf; any other chunk, and the row's tail, takes runRange, the definition.
// Both paths compute every per-pixel value with the same operations, so results agree
// exactly (sums up to their order of addition).
template <bool kQuantizedDepth, bool kQuantizedColor, bool kMaps>
void Comparator::runRowFast(int y) {
  ClassMaps* maps = maps_;
  const int w = e_.width;
  const std::size_t row = static_cast<std::size_t>(y) * w;
  const std::uint32_t* ida = &e_.id[row];
  const std::uint32_t* idb = &a_.id[row];
  const float* za = &e_.depth[row];
  const float* zb = &a_.depth[row];
  const float* ca = &e_.color[row * 4];
  const float* cb = &a_.color[row * 4];
  const double depth_warn = tol_.depth.warn;
  const float shade_warn = static_cast<float>(tol_.shading.warn);
  const double scale = scale_.steps_per_unit;
  const double depth_limit = depth_hot_.limit();
  const auto shade_limit = static_cast<float>(shade_hot_.limit());
  constexpr double kMagic = 6755399441055744.0;
  constexpr float kMagicF = 12582912.0f;
  V2d depth_sum = {};
  V2d shade_sum = {};
  V2d shade_sq = {};
  V4f color_sum = {};  // per channel, over at most 16 pixels, then into the doubles
  V4f color_sq = {};
  int summed = 0;
  auto flushColorSums = [&] {
    shade_sum += lowHalf(color_sum) + highHalf(color_sum);
    shade_sq += lowHalf(color_sq) + highHalf(color_sq);
    color_sum = V4f{};
    color_sq = V4f{};
    summed = 0;
  };
  V4f channel_max = {};
  std::uint64_t matched = 0;
  int x = 0;
  for (; x + 4 <= w; x += 4) {
    const V4u a = load<V4u>(ida + x);
    const V4u b = load<V4u>(idb + x);
    const V4f z_a = load<V4f>(za + x);
    const V4f z_b = load<V4f>(zb + x);
    V4f c_a[4];
    V4f c_b[4];
    for (int k = 0; k < 4; ++k) {
      c_a[k] = load<V4f>(ca + static_cast<std::ptrdiff_t>(x + k) * 4);
      c_b[k] = load<V4f>(cb + static_cast<std::ptrdiff_t>(x + k) * 4);
    }
    // A NaN or Inf on either side makes a difference NaN or Inf, and then times 0 NaN
    // (so does an overflow of huge finite values: conservative, the general path
    // sorts them out). No fast-math, so x * 0 is not folded to 0.
    const V4f probe = ((c_a[0] - c_b[0]) + (c_a[1] - c_b[1])) +
                      ((c_a[2] - c_b[2]) + (c_a[3] - c_b[3])) + (z_a - z_b);
    const V4i bad = (probe * 0.0f) != 0.0f;
    const V4i same = reinterpret_cast<V4i>(a == b);
    const V4i drawn = reinterpret_cast<V4i>(a != 0u);
    if (any(bad) || !all(same & drawn)) {
      if (any(bad) || any(drawn | ~same)) {
        runRange<kMaps>(y, x, x + 4);
        continue;
      }
      // Background on both sides: bit-identical clear values pass at once, anything else
      // goes through clearedPixel().
      bool identical = all(reinterpret_cast<V4i>(z_a) == reinterpret_cast<V4i>(z_b));
      for (int k = 0; k < 4; ++k)
        identical =
            identical && all(reinterpret_cast<V4i>(c_a[k]) == reinterpret_cast<V4i>(c_b[k]));
      if (identical) {
        r_.depth.cleared_checked += 4;
        r_.shading.cleared_checked += 4;
      } else {
        runRange<kMaps>(y, x, x + 4);
      }
      continue;
    }
    matched += 4;
    if (kMaps) std::memset(&maps->pixel_class[row + x], static_cast<int>(PixelClass::Match), 4);

    // Depth, in double like runRange.
    V2d sa[2] = {lowHalf(z_a) * scale, highHalf(z_a) * scale};
    V2d sb[2] = {lowHalf(z_b) * scale, highHalf(z_b) * scale};
    if (kQuantizedDepth) {
      for (int h = 0; h < 2; ++h) {
        sa[h] = (sa[h] + kMagic) - kMagic;
        sb[h] = (sb[h] + kMagic) - kMagic;
      }
    }
    const V2d dz01 = absd(sa[0] - sb[0]);
    const V2d dz23 = absd(sa[1] - sb[1]);
    depth_sum += dz01 + dz23;
    if (kMaps) store(&maps->depth_steps[row + x], join(dz01, dz23));
    // One test for the rare cases: a new maximum, over warn, beyond the small bins.
    const double depth_rare = std::min(std::min(depth_max_, depth_warn), depth_limit);
    if (!any2(maxd(dz01, dz23) > V2d{depth_rare, depth_rare})) {
      depth_hot_.add4InRange(dz01, dz23);
    } else {
      const double d[4] = {dz01[0], dz01[1], dz23[0], dz23[1]};
      for (int l = 0; l < 4; ++l) {
        depth_hot_.add(l, d[l]);
        if (d[l] > depth_max_) {
          depth_max_ = d[l];
          depth_max_at_ = row + x + l;
        }
        if (d[l] > depth_warn) depthOverBase(x + l, y, row + x + l, d[l]);
      }
    }

    // Shading: one pixel's R G B A per vector; e = each pixel's largest channel.
    V4f d[4];
    for (int k = 0; k < 4; ++k) {
      if (kQuantizedColor) {
        d[k] =
            absf(((c_a[k] * 255.0f + kMagicF) - kMagicF) - ((c_b[k] * 255.0f + kMagicF) - kMagicF));
      } else {
        d[k] = absf(c_a[k] - c_b[k]) * 255.0f;
      }
      color_sum += d[k];
      color_sq += d[k] * d[k];
    }
    channel_max = maxf(channel_max, maxf(maxf(d[0], d[1]), maxf(d[2], d[3])));
    const V4f e = pixelMaxima(d);
    if (kMaps) store(&maps->shading_abs[row + x], e);
    const float shade_rare = std::min(std::min(shade_max_, shade_warn), shade_limit);
    if (!any(e > V4f{shade_rare, shade_rare, shade_rare, shade_rare})) {
      shade_hot_.add4InRange(e);
    } else {
      for (int k = 0; k < 4; ++k) {
        shade_hot_.add(k, e[k]);
        if (e[k] > shade_max_) {
          shade_max_ = e[k];
          shade_max_at_ = row + x + k;
        }
        if (e[k] > shade_warn) {
          const float dk[4] = {d[k][0], d[k][1], d[k][2], d[k][3]};
          shadingOver(x + k, y, row + x + k, dk);
        }
      }
    }
    if ((summed += 4) == 16) flushColorSums();
  }
  flushColorSums();
  vis_match_ += matched;
  depth_sum_ += depth_sum[0] + depth_sum[1];
  shade_sum_ += shade_sum[0] + shade_sum[1];
  shade_sq_ += shade_sq[0] + shade_sq[1];
  for (int c = 0; c < 4; ++c) shade_max_rgba_[c] = std::max(shade_max_rgba_[c], channel_max[c]);
  if (x < w) runRange<kMaps>(y, x, w);
}

void Comparator::clearedPixel(std::size_t i, bool depth, float za, float zb, const float* pa,
                              const float* pb) {
  DepthStats& d = r_.depth;
  if (depth) {
    ++d.cleared_checked;
    const double dz = std::fabs(scale_(za) - scale_(zb));
    const double depth_rounding = scale_.quantized ? 1.0 : 0.0;
    if (!(dz <= depth_rounding)) {  // NaN too
      ++d.cleared_mismatched;
      ++d.over_tolerance;
      ++d.over_fail;
      depth_worst_.offer(std::isnan(dz) ? kInf : dz - depth_rounding, i, dz, depth_rounding);
    }
  }
  ShadingStats& s = r_.shading;
  ++s.cleared_checked;
  const float color_rounding = quantized_color_ ? 1.0f : 0.0f;
  float worst = 0.0f;
  for (int c = 0; c < 4; ++c) {
    const float e = colorError(pa[c], pb[c]);
    if (!(e <= worst)) worst = e;  // NaN wins
  }
  if (!(worst <= color_rounding)) {
    ++s.cleared_mismatched;
    ++s.over_tolerance;
    ++s.over_fail;
    shade_worst_.offer(std::isnan(worst) ? kInf : worst - color_rounding, i, worst, color_rounding);
  }
}

void Comparator::compareStencil() {
  StencilStats& st = r_.depth.stencil;
  const std::size_t n = e_.pixelCount();
  if (e_.stencil.size() != n || a_.stencil.size() != n) return;
  st.compared = true;
  st.pixels = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (e_.stencil[i] == a_.stencil[i]) continue;
    ++st.mismatched;
    // A fragment there may go either way: near an edge, or a depth test (against another
    // fragment or the clear depth) within its tolerance.
    const bool ambiguous =
        have_uncertainty_ && (static_cast<double>(u_.edge_dist[i]) <= band_ ||
                              ambiguousByDepth(i, 1, 1) || ambiguousByDepth(i, 0, 1));
    if (ambiguous) {
      ++st.ambiguous;
      continue;
    }
    ++st.hard;
    ++r_.depth.over_tolerance;
    ++r_.depth.over_fail;
    if (!st.worst.valid()) {
      st.worst = pixelAt(i);
      st.worst_expected = static_cast<int>(e_.stencil[i]);
      st.worst_actual = static_cast<int>(a_.stencil[i]);
    }
  }
}

// ---- Multisampled frames (docs/tolerances.md "Multisampling") ----
// Per pixel: the samples are compared one by one. A sample whose id differs is a
// coverage difference; it is ambiguous when the reference's edge_dist at that sample is
// within the snap band (or, between two primitives, depth_gap within the depth
// tolerance; against the background, clear_gap), else hard. A pixel with any hard
// sample is a hard visibility mismatch (its class from the first hard sample's ids) and
// nothing else is compared there; a pixel whose differing samples are all ambiguous is
// an ambiguous mismatch, and its depth (over the samples both sides give the same
// primitive) and resolved colour are still compared, the colour with an allowance of
// sample_alt / samples per differing sample. A pixel whose samples all agree and show
// a primitive somewhere is a match: depth over its non-background samples, resolved
// colour.

void Comparator::allocateMaps() {
  if (maps_) reserveMaps(*maps_, e_.width, e_.height);
}

// Whether sample s of pixel i may legally belong to another primitive (ids a, b).
bool Comparator::sampleAmbiguous(std::size_t i, int s, std::uint32_t a, std::uint32_t b,
                                 bool& by_gap, double& edge) const {
  by_gap = false;
  edge = have_sample_uncertainty_ ? static_cast<double>(u_.sample_edge_dist[u_.sampleIndex(s, i)])
                                  : kInf;
  if (edge <= band_) return true;
  if (!have_uncertainty_) return false;
  by_gap = ambiguousByDepth(i, a, b);
  return by_gap;
}

void Comparator::runMultisampleRow(int y) {
  const int samples = e_.samples;
  for (int x = 0; x < e_.width; ++x) {
    const std::size_t i = static_cast<std::size_t>(y) * e_.width + x;
    const float* pa = &e_.color[i * 4];
    const float* pb = &a_.color[i * 4];
    bool color_finite = true;
    for (int c = 0; c < 4; ++c)
      color_finite = color_finite && !isNonFinite(pa[c]) && !isNonFinite(pb[c]);
    bool depth_finite = true;
    int differing = 0;
    int first_hard = -1;
    int first_diff = -1;
    bool any_primitive = false;
    double dz_max = 0.0;
    bool first_gap = false;
    bool any_gap = false;  // a differing sample excused by a depth tie, not by an edge
    double first_edge = kInf;
    for (int s = 0; s < samples; ++s) {
      const std::size_t k = e_.sampleIndex(s, i);
      const std::uint32_t a = e_.sample_id[k];
      const std::uint32_t b = a_.sample_id[k];
      if (a != b) {
        ++differing;
        bool by_gap = false;
        double edge = kInf;
        const bool ambiguous = sampleAmbiguous(i, s, a, b, by_gap, edge);
        any_gap = any_gap || by_gap;
        if (first_diff < 0) {
          first_diff = s;
          first_gap = by_gap;
          first_edge = edge;
        }
        if (!ambiguous && first_hard < 0) {
          first_hard = s;
          first_edge = edge;
        }
        continue;
      }
      if (a == 0) continue;
      any_primitive = true;
      const float za = e_.sample_depth[k];
      const float zb = a_.sample_depth[k];
      if (isNonFinite(za) || isNonFinite(zb)) {
        depth_finite = false;
        continue;
      }
      dz_max = std::max(dz_max, std::fabs(scale_(za) - scale_(zb)));
    }
    sample_mismatches_ += static_cast<std::uint64_t>(differing);
    if (!depth_finite || !color_finite) {
      for (int c = 0; c < 4; ++c) {
        tally(pa[c], c, r_.nonfinite_expected);
        tally(pb[c], c, r_.nonfinite_actual);
      }
      tally(e_.depth[i], 4, r_.nonfinite_expected);
      tally(a_.depth[i], 4, r_.nonfinite_actual);
    }
    if (first_hard >= 0) {
      const std::size_t k = e_.sampleIndex(first_hard, i);
      const PixelClass cls = record(i, e_.sample_id[k], a_.sample_id[k], false, false, first_edge);
      if (maps_) maps_->pixel_class[i] = cls;
      continue;
    }
    if (first_diff >= 0) {
      const std::size_t k = e_.sampleIndex(first_diff, i);
      const PixelClass cls =
          record(i, e_.sample_id[k], a_.sample_id[k], true, first_gap, first_edge);
      if (maps_) maps_->pixel_class[i] = cls;
    } else if (!any_primitive) {
      // Background on both sides. Only the colour: a multisampled GL frame's depth comes
      // through a shader's float arithmetic (docs/gl_backend.md), not exact near 1.
      clearedPixel(i, false, e_.depth[i], a_.depth[i], pa, pb);
      continue;
    } else if (maps_) {
      maps_->pixel_class[i] = PixelClass::Match;
    }
    if (!any_primitive) continue;
    ++vis_match_;
    if (!depth_finite) {
      depthNonFinite(i);
      if (maps_) maps_->depth_steps[i] = std::numeric_limits<float>::quiet_NaN();
    } else {
      depth_sum_ += dz_max;
      r_.depth.histogram.add(dz_max);
      if (dz_max > depth_max_) {
        depth_max_ = dz_max;
        depth_max_at_ = i;
      }
      if (dz_max > tol_.depth.warn) depthOverBase(x, y, i, dz_max);
      if (maps_) maps_->depth_steps[i] = static_cast<float>(dz_max);
    }
    // A sample that may legally show another primitive by a depth tie may carry the colour
    // of a fragment that lost its depth test in the reference: no sample colour the
    // reference keeps bounds it, so the resolved colour is not compared (as the colour of
    // a single-sample pixel whose primitive differs is not).
    if (any_gap) {
      ++shade_skipped_;
      continue;
    }
    if (!colorsComparable(pa, pb)) {
      shadingNonFinite(i);
      if (maps_) maps_->shading_abs[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    float d[4];
    for (int c = 0; c < 4; ++c) d[c] = colorError(pa[c], pb[c]);
    const float e = std::max(std::max(d[0], d[1]), std::max(d[2], d[3]));
    ++shade_compared_;
    shade_sum_ += (d[0] + d[1]) + (d[2] + d[3]);
    shade_sq_ += (d[0] * d[0] + d[1] * d[1]) + (d[2] * d[2] + d[3] * d[3]);
    for (int c = 0; c < 4; ++c) shade_max_rgba_[c] = std::max(shade_max_rgba_[c], d[c]);
    r_.shading.histogram.add(e);
    if (e > shade_max_) {
      shade_max_ = e;
      shade_max_at_ = i;
    }
    // Each differing (ambiguous) sample may carry the colour of the other primitive: up to
    // the colour range around the pixel, weighted 1 / samples in the resolve.
    coverage_allowance_ = differing > 0 && have_sample_uncertainty_
                              ? static_cast<double>(differing) * u_.sample_alt[i] / samples
                              : 0.0;
    if (e > tol_.shading.warn) shadingOver(x, y, i, d);
    coverage_allowance_ = 0.0;
    if (maps_) maps_->shading_abs[i] = e;
  }
}

// ---- Visibility ----

__attribute__((noinline)) PixelClass Comparator::classifyMismatch(int, int, std::size_t i,
                                                                  std::uint32_t a,
                                                                  std::uint32_t b) {
  const double edge = have_uncertainty_ ? static_cast<double>(u_.edge_dist[i]) : kInf;
  bool ambiguous = edge <= band_;  // false for NaN
  bool by_gap = false;
  if (!ambiguous && have_uncertainty_) {
    by_gap = ambiguousByDepth(i, a, b);
    ambiguous = by_gap;
  }
  return record(i, a, b, ambiguous, by_gap, edge);
}

PixelClass Comparator::record(std::size_t i, std::uint32_t a, std::uint32_t b, bool ambiguous,
                              bool by_gap, double edge) {
  PixelClass cls;
  if (b == 0)
    cls = ambiguous ? PixelClass::MissingAmbiguous : PixelClass::MissingHard;
  else if (a == 0)
    cls = ambiguous ? PixelClass::ExtraAmbiguous : PixelClass::ExtraHard;
  else
    cls = ambiguous ? PixelClass::WrongAmbiguous : PixelClass::WrongHard;
  ++class_counts_[static_cast<int>(cls)];
  if (by_gap) ++r_.visibility.ambiguous_by_depth_gap;
  // The hard mismatch farthest from any edge is the least excusable.
  if (!ambiguous) vis_worst_.offer(std::isnan(edge) ? -1.0 : edge, i, edge, 0.0);
  return cls;
}

}  // namespace rc::detail
