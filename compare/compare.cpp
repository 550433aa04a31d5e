// The per-pixel comparison: see compare.h; formulas and their derivation in
// docs/tolerances.md. One pass over the rows; the common pixel (same id, small errors)
// takes a short branch-light path, everything unusual goes to out-of-line helpers.
#include "compare/compare.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <fmt/format.h>

#include "compare/pair_tolerances.h"
#include "compare/slopes.h"
#include "fixtures/big_buffer.h"
#include "fixtures/errors.h"
#include "fixtures/multisample.h"

namespace rc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

inline bool isNonFinite(float f) {
  return (std::bit_cast<std::uint32_t>(f) & 0x7f800000u) == 0x7f800000u;
}

std::string metaString(const Frame& f, const char* key) {
  const auto it = f.meta.find(key);
  return it != f.meta.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string frameLabel(const Frame& f, const char* role) {
  const std::string backend = metaString(f, "backend");
  return backend.empty() ? std::string(role) : fmt::format("{} ({})", role, backend);
}

int subpixelBits(const Frame& f, const char* role) {
  const auto it = f.meta.find("subpixel_bits");
  if (it == f.meta.end() || it->is_null()) return 8;
  if (!it->is_number_integer() || it->get<long long>() < 0 || it->get<long long>() > 24)
    throw InputError(
        fmt::format("{}: frame.json: subpixel_bits must be an integer in [0, 24], "
                    "got {}",
                    frameLabel(f, role), it->dump()));
  return it->get<int>();
}

void checkBuffers(const Frame& f, const char* role, bool need_color) {
  if (f.width < 0 || f.height < 0 || static_cast<long long>(f.width) * f.height > (1LL << 31))
    throw InputError(
        fmt::format("{}: unusable frame size {}x{}", frameLabel(f, role), f.width, f.height));
  const std::size_t n = f.pixelCount();
  if ((need_color && f.color.size() != n * 4) || f.depth.size() != n || f.id.size() != n)
    throw InputError(fmt::format("{}: frame buffers do not match its size {}x{}",
                                 frameLabel(f, role), f.width, f.height));
  const bool unc = f.hasUncertainty();
  for (int c = 0; c < kUncertaintyChannels; ++c) {
    if (f.uncertainty()[c]->size() != (unc ? n : 0))
      throw InputError(fmt::format("{}: {} does not match its size", frameLabel(f, role),
                                   kUncertaintyChannelInfo[c].name));
  }
  checkSamplePlanes(f, frameLabel(f, role));
}

// Four pixels at a time with GCC/Clang vector extensions: portable, and 128-bit so that
// x86-64's SSE2 baseline runs every operation as one instruction.
using V4f = float __attribute__((vector_size(16)));
using V4i = std::int32_t __attribute__((vector_size(16)));
using V4u = std::uint32_t __attribute__((vector_size(16)));
using V2d = double __attribute__((vector_size(16)));
using V2l = std::int64_t __attribute__((vector_size(16)));

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

// Small errors are by far the most common. Counting them in four interleaved tables (one
// per pixel of a chunk) keeps back-to-back increments of one bin from waiting on each
// other's store; the tables go into the ErrorHistogram at the end.
class HotBins {
 public:
  static constexpr int kBins = 256;  // <= ErrorHistogram::kLinearBins
  explicit HotBins(ErrorHistogram& h)
      : h_(h),
        inverse_quantum_(1.0 / h.quantum()),
        inverse_quantum_f_(static_cast<float>(inverse_quantum_)),
        counts_(static_cast<std::size_t>(4 * kBins), 0) {}
  void add(int lane, double value) {
    const double u = value * inverse_quantum_;
    if (u < kBins) {
      ++counts_[lane * kBins + static_cast<int>(u)];  // values are >= 0
    } else {
      h_.add(value);
    }
  }
  // Four values that the caller knows are below `limit()`, one per table; the same bins
  // as add() because the quantum is a power of two (value / quantum is exact in float).
  void add4InRange(V4f values) {
    const V4i bin = __builtin_convertvector(values * inverse_quantum_f_, V4i);
    ++counts_[bin[0]];
    ++counts_[kBins + bin[1]];
    ++counts_[2 * kBins + bin[2]];
    ++counts_[3 * kBins + bin[3]];
  }
  // Four doubles (two pairs) that the caller knows are below `limit()`.
  void add4InRange(V2d lo, V2d hi) {
    const V2d q = {inverse_quantum_, inverse_quantum_};
#if defined(__SSE2__)
    const V4i bin = reinterpret_cast<V4i>(
        _mm_unpacklo_epi64(_mm_cvttpd_epi32(reinterpret_cast<__m128d>(lo * q)),
                           _mm_cvttpd_epi32(reinterpret_cast<__m128d>(hi * q))));
#else
    const V2d ul = lo * q;
    const V2d uh = hi * q;
    const V4i bin = {static_cast<int>(ul[0]), static_cast<int>(ul[1]), static_cast<int>(uh[0]),
                     static_cast<int>(uh[1])};
#endif
    ++counts_[bin[0]];
    ++counts_[kBins + bin[1]];
    ++counts_[2 * kBins + bin[2]];
    ++counts_[3 * kBins + bin[3]];
  }
  // Values at or above this leave the small tables (one quantum below the first such).
  double limit() const { return (kBins - 1) / inverse_quantum_; }
  void flush() {
    for (int b = 0; b < kBins; ++b) {
      const std::uint64_t n = std::uint64_t{counts_[b]} + counts_[kBins + b] +
                              counts_[2 * kBins + b] + counts_[3 * kBins + b];
      if (n) h_.addToLinearBin(b, n);
    }
    std::fill(counts_.begin(), counts_.end(), 0u);
  }

 private:
  ErrorHistogram& h_;
  double inverse_quantum_;
  float inverse_quantum_f_;
  std::vector<std::uint32_t> counts_;  // frames hold < 2^31 pixels: no overflow
};

void tally(float v, int channel, NonFiniteCounts& counts) {
  if (std::isnan(v))
    ++counts.nan[channel];
  else if (std::isinf(v))
    ++counts.inf[channel];
}

// A candidate for a class's "worst" pixel. The vector path, the general path and the
// deferred pixels meet candidates in different orders, so the choice must not depend on
// it: the largest key wins, then the first pixel in row order.
struct WorstPixel {
  bool any = false;
  double key = 0.0;
  std::size_t index = 0;
  double value = 0.0;      // the error there
  double allowance = 0.0;  // its allowance there
  void offer(double k, std::size_t i, double v, double allow) {
    if (any && !(k > key) && !(k == key && i < index)) return;
    any = true;
    key = k;
    index = i;
    value = v;
    allowance = allow;
  }
};

class Comparator {
 public:
  Comparator(const Frame& e, const Frame& a, const Frame& u, const Tolerances& tol, PairResult& r)
      : e_(e), a_(a), u_(u), tol_(tol), r_(r) {
    scale_ = {depthStepsPerUnit(tol.depth_format), tol.depth_format != DepthFormat::D32F};
    quantized_color_ = tol.color_format == ColorFormat::RGBA8;
    have_uncertainty_ = u.hasUncertainty();
    band_ = r.visibility.band_px;
    depth_slope_band_ = tol.depth_slope_factor * r.depth.band_px;
    shade_slope_band_ = tol.shading_slope_factor * r.depth.band_px;
    texel_band_ = r.depth.band_px;
    shade_relative_units_ = 255.0 * tol.shading_relative;
    have_sample_uncertainty_ = have_uncertainty_ && u.multisampled() && u.samples == e.samples;
  }

  void run(ClassMaps* maps) {
    maps_ = maps;
    if (e_.multisampled()) {
      allocateMaps();
      for (int y = 0; y < e_.height; ++y) runMultisampleRow(y);
      finish();
      return;
    }
    allocateMaps();
    for (int y = 0; y < e_.height; ++y) {
      if (maps) {
        scale_.quantized ? (quantized_color_ ? runRowFast<true, true, true>(y)
                                             : runRowFast<true, false, true>(y))
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

 private:
  // 8-bit error of one channel; rgba8 compares the stored 8-bit values.
  float colorError(float a, float b) const {
    if (!quantized_color_) return std::fabs(a - b) * 255.0f;
    constexpr float kMagic = 12582912.0f;  // 1.5 * 2^23: round to nearest in float
    return std::fabs(((a * 255.0f + kMagic) - kMagic) - ((b * 255.0f + kMagic) - kMagic));
  }

  // The general path: any pixel, NaN/Inf. Pixels [x0, x1) of row y.
  template <bool kMaps>
  void runRange(int y, int x0, int x1) {
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
      if (a == 0) continue;  // background on both sides
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
      if (!color_finite) {
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
  // checked for NaN/Inf; any other chunk, and the row's tail, takes runRange. Both paths
  // compute every per-pixel value with the same operations, so results agree exactly
  // (sums up to their order of addition).
  template <bool kQuantizedDepth, bool kQuantizedColor, bool kMaps>
  void runRowFast(int y) {
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
        if (any(bad) || any(drawn | ~same)) runRange<kMaps>(y, x, x + 4);
        continue;  // else background on both sides
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
          d[k] = absf(((c_a[k] * 255.0f + kMagicF) - kMagicF) -
                      ((c_b[k] * 255.0f + kMagicF) - kMagicF));
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

  void allocateMaps() {
    if (maps_) reserveMaps(*maps_, e_.width, e_.height);
  }

  // Whether sample s of pixel i may legally belong to another primitive (ids a, b).
  bool sampleAmbiguous(std::size_t i, int s, std::uint32_t a, std::uint32_t b, bool& by_gap,
                       double& edge) const {
    by_gap = false;
    edge = have_sample_uncertainty_ ? static_cast<double>(u_.sample_edge_dist[u_.sampleIndex(s, i)])
                                    : kInf;
    if (edge <= band_) return true;
    if (!have_uncertainty_) return false;
    by_gap = ambiguousByDepth(i, a, b);
    return by_gap;
  }

  void runMultisampleRow(int y) {
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
        const PixelClass cls =
            record(i, e_.sample_id[k], a_.sample_id[k], false, false, first_edge);
        if (maps_) maps_->pixel_class[i] = cls;
        continue;
      }
      if (first_diff >= 0) {
        const std::size_t k = e_.sampleIndex(first_diff, i);
        const PixelClass cls =
            record(i, e_.sample_id[k], a_.sample_id[k], true, first_gap, first_edge);
        if (maps_) maps_->pixel_class[i] = cls;
      } else if (!any_primitive) {
        continue;  // background on both sides
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
      if (!color_finite) {
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

  // ---- Depth: slope allowance (docs/tolerances.md) ----

  // The depth slope (steps/px) the reference recorded for the fragment whose depth it
  // stored at pixel i; 0 without uncertainty channels (nothing is excused then).
  double depthSlope(std::size_t i) const {
    const double s = have_uncertainty_ ? static_cast<double>(u_.depth_slope[i]) : 0.0;
    return std::isnan(s) ? 0.0 : s;
  }

  // How far float32 vertex transforms may move the window depth of pixel i's fragments
  // (steps, the reference's depth_reach); 0 without uncertainty channels, NaN excuses nothing.
  double depthReach(std::size_t i) const {
    const double r = have_uncertainty_ ? static_cast<double>(u_.depth_reach[i]) : 0.0;
    return std::isnan(r) ? 0.0 : r;
  }

  // The depth allowance of pixel i on top of the warn or fail threshold, for a fragment of
  // depth gradient `slope` (steps/px): where snapping moves its plane, plus its vertices'
  // float32 reach (docs/tolerances.md section 2).
  double depthAllowance(std::size_t i, double slope) const {
    return depth_slope_band_ * slope + depthReach(i);
  }

  // Whether the reference's depth comparisons at pixel i could legally go the other way,
  // so that the driver shows id b where the reference shows a. Each fragment's stored
  // depth may be off by its tolerance (fail + allowance) in either direction; two
  // fragments closer than the sum may swap. The slope is the steeper fragment's of the
  // comparisons that decided the pixel (gap_slope). Against the clear depth (missing,
  // extra: primitive or background), only the fragment's own tolerance: the clear value
  // is exact on both sides.
  bool ambiguousByDepth(std::size_t i, std::uint32_t a, std::uint32_t b) const {
    return a != 0 && b != 0 ? static_cast<double>(u_.depth_gap[i]) <=
                                  2.0 * (tol_.depth.fail + depthAllowance(i, u_.gap_slope[i]))
                            : static_cast<double>(u_.clear_gap[i]) <=
                                  tol_.depth.fail + depthAllowance(i, u_.clear_slope[i]);
  }

  // Whether the fragments blended under the top one at pixel i may legally differ: a
  // blended pixel near a polygon edge (another fragment may or may not cover it) or with
  // a blended fragment's depth test within the tolerance of flipping. Its depth and colour
  // are then not held to their tolerances (docs/tolerances.md, "Blended pixels"). `k` is
  // describing(x, y, i): driver against driver, where the reference shows another
  // primitive at i, its channels there describe that primitive's fragments, not the blend
  // under the expected one; those at k, where it shows the expected primitive, do.
  bool blendUncertain(std::size_t i, std::size_t k) const {
    return blendUncertainAt(i) || (k != i && blendUncertainAt(k));
  }
  bool blendUncertainAt(std::size_t i) const {
    if (!have_uncertainty_ || !(u_.blend_count[i] > 0.0f)) return false;
    return static_cast<double>(u_.edge_dist[i]) <= band_ ||
           static_cast<double>(u_.blend_gap[i]) <=
               2.0 * (tol_.depth.fail + depthAllowance(i, u_.blend_slope[i]));
  }

  // The pixel whose uncertainty channels describe the expected frame's fragment at pixel
  // (x, y), index i: i itself, unless the uncertainty frame is another frame (driver
  // against driver) that shows another primitive there. Then a neighbour (8-connected)
  // where it shows the expected primitive: a primitive's depth slope is one plane's
  // gradient, the same at every pixel it covers, and its vertices' reach changes by a
  // fraction of a step across a pixel. i when no neighbour shows it (no allowance is known).
  std::size_t describing(int x, int y, std::size_t i) const {
    if (!have_uncertainty_ || &u_ == &e_ || u_.id[i] == e_.id[i]) return i;
    const std::uint32_t want = e_.id[i];
    std::size_t found = i;
    detail::forEachNeighbour(e_, x, y, [&](std::size_t j, int, int) {
      if (u_.id[j] != want) return true;
      found = j;
      return false;
    });
    return found;
  }

  // dz is over warn: check it against the pixel's slope allowance.
  __attribute__((noinline)) void depthOverBase(int x, int y, std::size_t i, double dz) {
    DepthStats& d = r_.depth;
    const std::size_t k = describing(x, y, i);
    const double slope = depthSlope(k);  // NaN excuses nothing
    const double allow = depthAllowance(k, slope);
    const Thresholds at = tol_.depth.raisedBy(allow);
    if (maps_) maps_->depth_tolerance[i] = static_cast<float>(at.warn);
    d.max_slope = std::max(d.max_slope, slope);
    const double excess = dz - at.warn;
    if (excess <= 0.0) return;
    if (blendUncertain(i, k)) {
      ++d.blend_uncertain;
      return;
    }
    ++d.over_tolerance;
    if (at.verdict(dz) == Status::Fail) ++d.over_fail;  // dz is finite here
    depth_worst_.offer(excess, i, dz, allow);
  }

  __attribute__((noinline)) void depthNonFinite(std::size_t i) {
    ++r_.depth.nonfinite;
    ++r_.depth.over_tolerance;
    ++r_.depth.over_fail;
    depth_worst_.offer(kInf, i, std::numeric_limits<double>::quiet_NaN(), 0.0);
  }

  // ---- Shading: relative, gradient and texture allowances (docs/tolerances.md) ----

  struct ShadingExcess {
    double excess = -kInf;                // max over channels of error - allowance
    int channel = 0;                      // the channel that gives it
    double allowance = 0.0;               // that channel's allowance
    double excess_without_texel = -kInf;  // the same without the texel-choice term
    std::array<double, 4> allowances{};
  };
  // With `neighbourhood` false, only the terms that need no neighbours (a lower bound).
  ShadingExcess shadingExcess(int x, int y, std::size_t i, const float* d,
                              bool neighbourhood) const {
    const float* pa = &e_.color[i * 4];
    const float* pb = &a_.color[i * 4];
    detail::ColourNeighbourhood around;
    if (neighbourhood) {
      around = detail::colourNeighbourhood(e_, x, y);
      // Driver against driver: the surface's colour gradient is also what the uncertainty
      // frame (the reference) shows around the pixel, where it shows the same primitive.
      // A driver's own neighbourhood can miss it: where its ids differ from the reference's
      // around the pixel (legal, ambiguous edges), it finds fewer same-primitive neighbours
      // and a flatter gradient, so an allowance the comparison with the reference gives
      // would be missing here. The larger of the two per channel.
      if (have_uncertainty_ && &u_ != &e_ && u_.id[i] == e_.id[i] && !u_.color.empty()) {
        const detail::ColourNeighbourhood reference = detail::colourNeighbourhood(u_, x, y);
        for (int c = 0; c < 4; ++c)
          around.gradient[c] = std::max(around.gradient[c], reference.gradient[c]);
      }
    }
    ShadingExcess out;
    // The colour's own sensitivity to its vertices' positions (shade_reach, units per px,
    // from the reference's attribute planes): where the neighbours show a flatter gradient
    // than the surface has, as around a sliver whose pixels have no same-primitive
    // neighbour, it is the gradient the slope band moves (docs/tolerances.md (b)).
    double plane = 0.0;
    // And how far float32 interpolation may turn a short interpolated normal
    // (normal_reach, units; docs/tolerances.md (a)).
    double normal = 0.0;
    if (have_uncertainty_ && u_.id[i] == e_.id[i]) {
      const double r = u_.shade_reach[i];
      plane = std::isnan(r) ? 0.0 : r;
      const double n = u_.normal_reach[i];
      normal = std::isnan(n) ? 0.0 : n;
    }
    // What the reference knows at the pixel: with nearest filtering, a sample within the
    // band of a texel boundary may take the texel across it (texel_alt, RGB only); in
    // rgba8 every blended fragment may round differently (blend_count).
    double texel = 0.0;
    double filtering = 0.0;
    double blends = 0.0;
    if (have_uncertainty_) {
      if (tol_.texel_choice > 0.0 && static_cast<double>(u_.texel_dist[i]) <= texel_band_)
        texel = tol_.texel_choice * u_.texel_alt[i];
      // Linear filtering: quantised weights, and a sample moved by float32 interpolation
      // (texel_reach, texels), move the value by a fraction of the colour range of the
      // footprints it may read (texel_alt); the 8-bit filtered texel by a unit times its
      // light. (NaN reach: excuses nothing.)
      const double reach = std::isnan(u_.texel_reach[i]) ? 0.0 : u_.texel_reach[i];
      filtering = (tol_.texture_weight_error + std::min(1.0, reach)) * u_.texel_alt[i] +
                  tol_.texture_rounding_units * u_.texel_gain[i];
      blends = tol_.blend_rounding_units * u_.blend_count[i];
    }
    for (int c = 0; c < 4; ++c) {
      const double m = std::max(std::fabs(pa[c]), std::fabs(pb[c]));
      const double gradient =
          c < 3 ? std::max(static_cast<double>(around.gradient[c]), plane) : around.gradient[c];
      out.allowances[c] = shade_relative_units_ * m + shade_slope_band_ * gradient + blends +
                          (c < 3 ? texel + filtering + normal : 0.0) + coverage_allowance_;
    }
    for (int c = 0; c < 4; ++c) {
      const double excess = d[c] - out.allowances[c];
      if (excess > out.excess) {
        out.excess = excess;
        out.channel = c;
        out.allowance = out.allowances[c];
      }
      const double without = excess + (c < 3 ? texel : 0.0);
      out.excess_without_texel = std::max(out.excess_without_texel, without);
    }
    return out;
  }

  // The pixel's largest channel error is over warn: check it against its allowance.
  __attribute__((noinline)) void shadingOver(int x, int y, std::size_t i, const float* d) {
    const double warn = tol_.shading.warn;
    // The terms without neighbours are a lower bound of the allowance: often enough (unless
    // the texel term is needed: then whether the rest covers it decides the count).
    if (!maps_) {
      const ShadingExcess lower = shadingExcess(x, y, i, d, false);
      if (lower.excess <= warn && lower.excess_without_texel <= warn) return;
    }
    const ShadingExcess s = shadingExcess(x, y, i, d, true);
    if (maps_) {
      // The threshold the pixel's largest channel error is held to: exceeding it by k is
      // exceeding warn by k in the deciding channel (the channels' allowances differ).
      const float e = std::max(std::max(d[0], d[1]), std::max(d[2], d[3]));
      maps_->shading_tolerance[i] = static_cast<float>(tol_.shading.raisedBy(e - s.excess).warn);
      if (i == maps_->describe_pixel) maps_->describe_allowances = s.allowances;
    }
    // The excess is already net of the channel's allowance: the base thresholds judge it
    // (never NaN: a NaN channel excess is never the largest).
    const Status verdict = tol_.shading.verdict(s.excess);
    if (verdict == Status::Pass) {
      if (s.excess_without_texel > warn) ++r_.shading.texel_choice;
      return;
    }
    if (blendUncertain(i, describing(x, y, i))) {
      ++r_.shading.blend_uncertain;
      return;
    }
    ++r_.shading.over_tolerance;
    if (verdict == Status::Fail) ++r_.shading.over_fail;
    shade_worst_.offer(s.excess, i, d[s.channel], s.allowance);
  }

  __attribute__((noinline)) void shadingNonFinite(std::size_t i) {
    ++r_.shading.nonfinite;
    ++r_.shading.over_tolerance;
    ++r_.shading.over_fail;
    shade_worst_.offer(kInf, i, std::numeric_limits<double>::quiet_NaN(), 0.0);
  }

  // ---- Visibility ----

  __attribute__((noinline)) PixelClass classifyMismatch(int, int, std::size_t i, std::uint32_t a,
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

  PixelClass record(std::size_t i, std::uint32_t a, std::uint32_t b, bool ambiguous, bool by_gap,
                    double edge) {
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

  PixelRef pixelAt(std::size_t i) const {
    return {static_cast<int>(i % e_.width), static_cast<int>(i / e_.width)};
  }

  void finish() {
    depth_hot_.flush();
    shade_hot_.flush();

    VisibilityStats& v = r_.visibility;
    auto count = [&](PixelClass c) { return class_counts_[static_cast<int>(c)]; };
    v.missing = count(PixelClass::MissingAmbiguous) + count(PixelClass::MissingHard);
    v.extra = count(PixelClass::ExtraAmbiguous) + count(PixelClass::ExtraHard);
    v.wrong_primitive = count(PixelClass::WrongAmbiguous) + count(PixelClass::WrongHard);
    v.missing_hard = count(PixelClass::MissingHard);
    v.extra_hard = count(PixelClass::ExtraHard);
    v.wrong_primitive_hard = count(PixelClass::WrongHard);
    v.hard = v.missing_hard + v.extra_hard + v.wrong_primitive_hard;
    v.mismatched = v.missing + v.extra + v.wrong_primitive;
    v.ambiguous = v.mismatched - v.hard;
    v.uncertainty_available = have_uncertainty_;
    v.samples = e_.samples;
    v.mismatched_samples = sample_mismatches_;
    v.status = tol_.visibility.verdict(static_cast<double>(v.hard));
    if (vis_worst_.any) {
      v.worst = pixelAt(vis_worst_.index);
      v.worst_edge_dist = vis_worst_.value;
    }

    DepthStats& d = r_.depth;
    d.compared = vis_match_;
    const std::uint64_t depth_finite = d.compared - d.nonfinite;
    d.max_steps = depth_max_;
    d.mean_steps = depth_finite ? depth_sum_ / static_cast<double>(depth_finite) : 0.0;
    d.p99_steps = d.histogram.percentile(0.99, depth_max_);
    if (depth_worst_.any) {
      d.worst = pixelAt(depth_worst_.index);
      d.worst_steps = depth_worst_.value;
      d.worst_allowance = depth_worst_.allowance;
    } else if (depth_max_ > 0.0) {  // all equal: no worst pixel
      d.worst = pixelAt(depth_max_at_);
      d.worst_steps = depth_max_;
      d.worst_allowance = depthAllowance(depth_max_at_, depthSlope(depth_max_at_));
    }
    d.status = d.over_fail ? Status::Fail : d.over_tolerance ? Status::Warn : Status::Pass;

    ShadingStats& s = r_.shading;
    s.compared = e_.multisampled() ? shade_compared_ + s.nonfinite : vis_match_;
    s.depth_tied = shade_skipped_;
    const std::uint64_t shade_finite = s.compared - s.nonfinite;
    s.max_abs = shade_max_;
    for (int c = 0; c < 4; ++c) s.max_abs_rgba[c] = shade_max_rgba_[c];
    if (shade_finite > 0) {
      const double values = 4.0 * static_cast<double>(shade_finite);
      s.mean_abs = shade_sum_ / values;
      s.rmse = std::sqrt(shade_sq_ / values);
    }
    s.psnr_db = s.rmse > 0.0 ? std::min(kPsnrCapDb, 20.0 * std::log10(255.0 / s.rmse)) : kPsnrCapDb;
    s.p99_abs = s.histogram.percentile(0.99, shade_max_);
    if (shade_worst_.any) {
      s.worst = pixelAt(shade_worst_.index);
      s.worst_abs = shade_worst_.value;
      s.worst_allowance = shade_worst_.allowance;
    } else if (shade_max_ > 0.0f) {
      s.worst = pixelAt(shade_max_at_);
      float dk[4];
      for (int c = 0; c < 4; ++c)
        dk[c] = colorError(e_.color[shade_max_at_ * 4 + c], a_.color[shade_max_at_ * 4 + c]);
      const int c = static_cast<int>(std::max_element(dk, dk + 4) - dk);
      s.worst_abs = dk[c];
      s.worst_allowance =
          shadingExcess(s.worst.x, s.worst.y, shade_max_at_, dk, true).allowances[c];
    }
    s.status = s.over_fail ? Status::Fail : s.over_tolerance ? Status::Warn : Status::Pass;

    r_.status = worse(v.status, worse(d.status, s.status));
  }

  const Frame& e_;
  const Frame& a_;
  const Frame& u_;
  const Tolerances& tol_;
  PairResult& r_;
  detail::DepthScale scale_;
  bool quantized_color_ = false;
  bool have_uncertainty_ = false;
  double band_ = 0.0;
  double depth_slope_band_ = 0.0;  // depth_slope_factor * slope band
  double shade_slope_band_ = 0.0;  // shading_slope_factor * slope band
  double texel_band_ = 0.0;        // the slope band: how far a texture sample may move (px)
  double shade_relative_units_ = 0.0;
  // Multisampled frames: per-sample edge distances and sample_alt are available.
  bool have_sample_uncertainty_ = false;
  std::uint64_t sample_mismatches_ = 0;
  std::uint64_t shade_skipped_ = 0;   // multisampled: depth-tied pixels (not shading-compared)
  std::uint64_t shade_compared_ = 0;  // multisampled: pixels shading-compared
  double coverage_allowance_ = 0.0;   // units, of the pixel being compared (multisampled)

  std::uint64_t class_counts_[kPixelClassCount] = {};
  std::uint64_t vis_match_ = 0;
  WorstPixel vis_worst_;

  double depth_sum_ = 0.0;
  double depth_max_ = 0.0;
  std::size_t depth_max_at_ = 0;
  WorstPixel depth_worst_;

  double shade_sum_ = 0.0;
  double shade_sq_ = 0.0;
  float shade_max_ = 0.0f;
  std::size_t shade_max_at_ = 0;
  float shade_max_rgba_[4] = {};
  WorstPixel shade_worst_;
  HotBins depth_hot_{r_.depth.histogram};
  HotBins shade_hot_{r_.shading.histogram};

  ClassMaps* maps_ = nullptr;
};

}  // namespace

namespace {
Thresholds heldTo(const Thresholds& base, const std::vector<float>& recorded, std::size_t i) {
  // The map holds the raised warn only where the error exceeded the base warn (0
  // elsewhere); within it the pixel passes whatever its allowance, and the base applies.
  const double warn_at = std::max<double>(recorded[i], base.warn);
  return base.raisedBy(warn_at - base.warn);
}
}  // namespace

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

Thresholds depthThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances) {
  return heldTo(tolerances.depth, maps.depth_tolerance, i);
}

Thresholds shadingThresholdsAt(const ClassMaps& maps, std::size_t i, const Tolerances& tolerances) {
  return heldTo(tolerances.shading, maps.shading_tolerance, i);
}

std::uint64_t NonFiniteCounts::total() const {
  std::uint64_t t = 0;
  for (std::size_t c = 0; c < nan.size(); ++c) t += nan[c] + inf[c];
  return t;
}

PairResult errorResult(std::string fixture, std::string expected, std::string actual,
                       std::string message) {
  PairResult r;
  r.fixture = std::move(fixture);
  r.expected = std::move(expected);
  r.actual = std::move(actual);
  r.status = Status::Error;
  r.error = std::move(message);
  return r;
}

PairResult notSupportedResult(std::string fixture, std::string expected, std::string actual,
                              std::string reason) {
  PairResult r =
      errorResult(std::move(fixture), std::move(expected), std::move(actual), std::move(reason));
  r.status = Status::NotSupported;
  return r;
}

std::optional<std::string> notSupportedReason(const std::string& message) {
  constexpr std::string_view kMarker = "not supported: ";
  const std::size_t at = message.find(kMarker);
  if (at == std::string::npos) return std::nullopt;
  return message.substr(at + kMarker.size());
}

PairResult compareFrames(const Frame& expected, const Frame& actual, const Frame& uncertainty,
                         const Tolerances& tolerances, ClassMaps* maps) {
  const auto start = std::chrono::steady_clock::now();
  checkBuffers(expected, "expected", true);
  checkBuffers(actual, "actual", true);
  const bool separate_uncertainty = &uncertainty != &expected;
  if (separate_uncertainty) checkBuffers(uncertainty, "uncertainty", false);
  if (expected.width != actual.width || expected.height != actual.height)
    throw InputError(fmt::format("frames differ in size: {} is {}x{}, {} is {}x{}",
                                 frameLabel(expected, "expected"), expected.width, expected.height,
                                 frameLabel(actual, "actual"), actual.width, actual.height));
  if (expected.samples != actual.samples)
    throw InputError(fmt::format("frames differ in samples per pixel: {} has {}, {} has {}",
                                 frameLabel(expected, "expected"), expected.samples,
                                 frameLabel(actual, "actual"), actual.samples));
  if (uncertainty.width != expected.width || uncertainty.height != expected.height)
    throw InputError(fmt::format("frames differ in size: {} is {}x{}, {} is {}x{}",
                                 frameLabel(expected, "expected"), expected.width, expected.height,
                                 frameLabel(uncertainty, "uncertainty"), uncertainty.width,
                                 uncertainty.height));

  PairResult r;
  r.fixture = metaString(expected, "fixture");
  if (r.fixture.empty()) r.fixture = metaString(actual, "fixture");
  r.expected = metaString(expected, "backend");
  r.actual = metaString(actual, "backend");
  for (const Frame* f : {&expected, &actual}) {
    const auto st = f->meta.find("state");
    if (st != f->meta.end() && st->is_object()) {
      r.state = *st;
      break;
    }
  }
  r.actual_driver = metaString(actual, "gl_version");
  r.width = expected.width;
  r.height = expected.height;
  r.pixels = expected.pixelCount();
  r.expected_subpixel_bits = subpixelBits(expected, "expected");
  r.actual_subpixel_bits = subpixelBits(actual, "actual");
  r.tolerances = tolerances;
  BandInputs band;
  band.expected_bits = r.expected_subpixel_bits;
  band.actual_bits = r.actual_subpixel_bits;
  band.width = expected.width;
  band.height = expected.height;
  r.visibility.band_px = snapBandPx(tolerances, band);
  r.depth.band_px = slopeBandPx(tolerances, band);

  // Quantized formats have integer errors: exact percentiles (histogram.h).
  const bool int_depth = tolerances.depth_format != DepthFormat::D32F;
  const bool int_color = tolerances.color_format == ColorFormat::RGBA8;
  r.depth.histogram = ErrorHistogram(int_depth ? 1.0 : 1.0 / 64.0, int_depth);
  r.shading.histogram = ErrorHistogram(int_color ? 1.0 : 1.0 / 4096.0, int_color);
  Comparator(expected, actual, uncertainty, tolerances, r).run(maps);
  r.oit = compareOit(expected, actual, tolerances);
  r.ciede2000 = deltaE2000Frames(expected, actual);  // cheap: only differing pixels
  if ((maps && maps->want_flip) || tolerances.flip_mean_fail) {
    r.flip = flipFrames(expected, actual, tolerances, maps ? &maps->flip : nullptr);
    r.status = worse(r.status, r.flip->status);
  } else if (maps) {
    maps->flip.clear();  // no stale map from an earlier comparison
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Tolerances tolerancesForFrames(const Frame& expected, const Frame& actual) {
  const DrawFacts& e = expected.drawn;
  const DrawFacts& a = actual.drawn;
  if (e.depth_format && a.depth_format && *e.depth_format != *a.depth_format)
    throw InputError(fmt::format("{} has depth_format {}, {} has {}",
                                 frameLabel(expected, "expected"), toString(*e.depth_format),
                                 frameLabel(actual, "actual"), toString(*a.depth_format)));
  if (e.color_format && a.color_format && *e.color_format != *a.color_format)
    throw InputError(fmt::format("{} has color_format {}, {} has {}",
                                 frameLabel(expected, "expected"), toString(*e.color_format),
                                 frameLabel(actual, "actual"), toString(*a.color_format)));
  const DepthFormat depth = e.depth_format.value_or(a.depth_format.value_or(DepthFormat::D24));
  const ColorFormat color = e.color_format.value_or(a.color_format.value_or(ColorFormat::RGBA32F));
  DrawnWith drawn;
  drawn.linear_textures = e.linearTextures() || a.linearTextures();
  return defaultTolerances(depth, color, drawn);
}

PairResult compareFrames(const Frame& expected, const Frame& actual) {
  return compareFrames(expected, actual, expected,
                       pairTolerances(expected, actual, fixtureTolerance(expected, actual)));
}

void checkSameSize(const Frame& expected, const Frame& actual,
                   const std::filesystem::path& expected_dir,
                   const std::filesystem::path& actual_dir) {
  if (expected.width != actual.width || expected.height != actual.height)
    throw InputError(fmt::format("{} ({}x{}) and {} ({}x{}) differ in size", expected_dir.string(),
                                 expected.width, expected.height, actual_dir.string(), actual.width,
                                 actual.height));
}

}  // namespace rc
