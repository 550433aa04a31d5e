// Inside compare/: the Comparator that compareFrames runs on one pair, shared by the files
// that define its parts: the pass over the pixels (classify.cpp), the allowances an error
// is held to (allowances.cpp), the statistics and verdicts at the end (statistics.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "compare/compare.h"
#include "compare/histogram.h"
#include "compare/pixel_class.h"
#include "compare/slopes.h"
#include "compare/tolerances.h"
#include "fixtures/frame.h"

namespace rc::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

inline bool isNonFinite(float f) {
  return (std::bit_cast<std::uint32_t>(f) & 0x7f800000u) == 0x7f800000u;
}

// Whether both sides' colours can be compared channel by channel: finite, or the same
// infinity on both sides (rgba32f keeps what blending computes: an overflow the reference
// predicts, as repeated dst_color blends give, is agreement, not an error). NaN never is.
inline bool colorsComparable(const float* a, const float* b) {
  for (int c = 0; c < 4; ++c) {
    const bool both_finite = !isNonFinite(a[c]) && !isNonFinite(b[c]);
    if (!both_finite && !(std::isinf(a[c]) && a[c] == b[c])) return false;
  }
  return true;
}

// Four pixels at a time with GCC/Clang vector extensions: portable, and 128-bit so that
// x86-64's SSE2 baseline runs every operation as one instruction.
using V4f = float __attribute__((vector_size(16)));
using V4i = std::int32_t __attribute__((vector_size(16)));
using V4u = std::uint32_t __attribute__((vector_size(16)));
using V2d = double __attribute__((vector_size(16)));
using V2l = std::int64_t __attribute__((vector_size(16)));

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

// The comparison of one pair (compareFrames): run() passes over the pixels once, then
// finish() sets the statistics and verdicts of each class.
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
    const nlohmann::json& meta = e.meta.contains("clear_depth") ? e.meta : u.meta;
    if (meta.contains("clear_depth") && meta["clear_depth"].is_number())
      clear_steps_ = scale_(meta["clear_depth"].get<float>());
  }

  void run(ClassMaps* maps);

 private:
  // 8-bit error of one channel; rgba8 compares the stored 8-bit values.
  float colorError(float a, float b) const {
    if (a == b) return 0.0f;  // also the same infinity on both sides (colorsComparable())
    if (!quantized_color_) return std::fabs(a - b) * 255.0f;
    constexpr float kMagic = 12582912.0f;  // 1.5 * 2^23: round to nearest in float
    return std::fabs(((a * 255.0f + kMagic) - kMagic) - ((b * 255.0f + kMagic) - kMagic));
  }

  // ---- The pass over the pixels (classify.cpp) ----

  template <bool kMaps>
  void runRange(int y, int x0, int x1);
  template <bool kQuantizedDepth, bool kQuantizedColor, bool kMaps>
  void runRowFast(int y);
  void allocateMaps();
  bool sampleAmbiguous(std::size_t i, int s, std::uint32_t a, std::uint32_t b, bool& by_gap,
                       double& edge) const;
  void runMultisampleRow(int y);
  __attribute__((noinline)) PixelClass classifyMismatch(int, int, std::size_t i, std::uint32_t a,
                                                        std::uint32_t b);
  PixelClass record(std::size_t i, std::uint32_t a, std::uint32_t b, bool ambiguous, bool by_gap,
                    double edge);

  // A pixel where neither side drew anything (classify.cpp); its depth only with `depth`.
  void clearedPixel(std::size_t i, bool depth, float za, float zb, const float* pa,
                    const float* pb);
  // The stencil planes, after the pass over the pixels (classify.cpp).
  void compareStencil();

  // ---- Allowances: depth slope, shading (allowances.cpp) ----

  double depthSlope(std::size_t i) const;
  double depthReach(std::size_t i) const;
  double depthAllowance(std::size_t i, double slope) const;
  bool ambiguousByDepth(std::size_t i, std::uint32_t a, std::uint32_t b) const;
  bool blendUncertain(std::size_t i, std::size_t k) const;
  bool blendUncertainAt(std::size_t i) const;
  bool optionalFragmentLeftOut(std::size_t i, std::size_t k) const;
  std::size_t describing(int x, int y, std::size_t i) const;
  __attribute__((noinline)) void depthOverBase(int x, int y, std::size_t i, double dz);
  __attribute__((noinline)) void depthNonFinite(std::size_t i);

  struct ShadingExcess {
    double excess = -kInf;                // max over channels of error - allowance
    int channel = 0;                      // the channel that gives it
    double allowance = 0.0;               // that channel's allowance
    double excess_without_texel = -kInf;  // the same without the texel-choice term
    std::array<double, 4> allowances{};
  };
  ShadingExcess shadingExcess(int x, int y, std::size_t i, const float* d,
                              bool neighbourhood) const;
  __attribute__((noinline)) void shadingOver(int x, int y, std::size_t i, const float* d);
  __attribute__((noinline)) void shadingNonFinite(std::size_t i);

  // ---- Statistics and verdicts (statistics.cpp) ----

  PixelRef pixelAt(std::size_t i) const;
  void finish();

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
  // The clear depth in steps (frame.json clear_depth), NaN where the frames do not say.
  double clear_steps_ = std::numeric_limits<double>::quiet_NaN();
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

}  // namespace rc::detail
