// Four doubles per vector: the lane type of the reference's batched fragment loops
// (shading_lanes.h, FragmentInterpolator::barycentricAt4). Every operation is the scalar
// IEEE operation in each lane, correctly rounded per lane, so a lane's result has the bits
// of the scalar code on the same operands whatever instructions carry it (two SSE2 halves
// on x86-64's baseline, one AVX register where the caller is compiled for it; neither has
// FMA to contract into, and the build forbids contraction anyway).
#pragma once

#include <emmintrin.h>

#include <cstdint>
#include <type_traits>

namespace rc::ref {

// Lane4 values never cross a call (everything is always_inline), so the ABI note of
// -Wpsabi about passing 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// GCC/Clang vector extensions: element-wise + - * / and comparisons (all-ones lanes where
// true), `mask ? a : b` per lane (selectLanes(), which Lane8 also has).
using Lane4 = double __attribute__((vector_size(32)));
using Mask4 = std::int64_t __attribute__((vector_size(32)));

// Eight lanes as two Lane4 halves, each operation written out as the operation on each
// half: the two halves are independent chains in program order, which lets the processor
// overlap them (the Phong quads of shadePhongQuad(): the chain of divisions and square
// roots of one quad is long). A 64-byte vector-extension type would do the same on paper,
// but GCC lowers its compares and selects to scalar code without AVX-512.
struct Mask8 {
  Mask4 lo;
  Mask4 hi;
};
struct Lane8 {
  Lane4 lo;
  Lane4 hi;
  double operator[](int k) const { return k < 4 ? lo[k] : hi[k - 4]; }
};
// Lane k of v set to x (Lane8's halves are not one subscriptable vector).
[[gnu::always_inline]] inline void setLane(Lane4& v, int k, double x) { v[k] = x; }
[[gnu::always_inline]] inline void setLane(Lane8& v, int k, double x) {
  if (k < 4) {
    v.lo[k] = x;
  } else {
    v.hi[k - 4] = x;
  }
}
[[gnu::always_inline]] inline Lane8 operator+(Lane8 a, Lane8 b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
[[gnu::always_inline]] inline Lane8 operator-(Lane8 a, Lane8 b) {
  return {a.lo - b.lo, a.hi - b.hi};
}
[[gnu::always_inline]] inline Lane8 operator*(Lane8 a, Lane8 b) {
  return {a.lo * b.lo, a.hi * b.hi};
}
[[gnu::always_inline]] inline Lane8 operator/(Lane8 a, Lane8 b) {
  return {a.lo / b.lo, a.hi / b.hi};
}
[[gnu::always_inline]] inline Lane8& operator*=(Lane8& a, Lane8 b) { return a = a * b; }
[[gnu::always_inline]] inline Mask8 operator<(Lane8 a, Lane8 b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
[[gnu::always_inline]] inline Mask8 operator>(Lane8 a, Lane8 b) {
  return {a.lo > b.lo, a.hi > b.hi};
}
[[gnu::always_inline]] inline Mask8 operator==(Lane8 a, Lane8 b) {
  return {a.lo == b.lo, a.hi == b.hi};
}
[[gnu::always_inline]] inline Mask8 operator!=(Lane8 a, Lane8 b) {
  return {a.lo != b.lo, a.hi != b.hi};
}
[[gnu::always_inline]] inline Mask8 operator&(Mask8 a, Mask8 b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
[[gnu::always_inline]] inline Mask8& operator&=(Mask8& a, Mask8 b) { return a = a & b; }
[[gnu::always_inline]] inline Mask8 operator~(Mask8 a) { return {~a.lo, ~a.hi}; }

template <class V>
inline constexpr int kLaneCount = static_cast<int>(sizeof(V) / sizeof(double));
template <class V>
using MaskOf = decltype(V{} < V{});

// Everything here is inlined into its caller, so that it is compiled for the caller's
// instruction set (no 32-byte vector crosses a call).
template <class V>
[[gnu::always_inline]] inline V splatAs(double v) {
  if constexpr (std::is_same_v<V, Lane8>) {
    return Lane8{Lane4{v, v, v, v}, Lane4{v, v, v, v}};
  } else {
    return V{v, v, v, v};
  }
}
[[gnu::always_inline]] inline Lane4 splat4(double v) { return splatAs<Lane4>(v); }
// `m ? a : b` per lane.
[[gnu::always_inline]] inline Lane4 selectLanes(Mask4 m, Lane4 a, Lane4 b) { return m ? a : b; }
[[gnu::always_inline]] inline Lane8 selectLanes(Mask8 m, Lane8 a, Lane8 b) {
  return {m.lo ? a.lo : b.lo, m.hi ? a.hi : b.hi};
}
// Lanes below `count` (a lane number < count).
template <class V>
[[gnu::always_inline]] inline MaskOf<V> lanesBelow(int count) {
  const Mask4 c = {count, count, count, count};
  if constexpr (std::is_same_v<V, Lane8>) {
    return Mask8{Mask4{0, 1, 2, 3} < c, Mask4{4, 5, 6, 7} < c};
  } else {
    return Mask4{0, 1, 2, 3} < c;
  }
}
// Square roots: sqrtpd on each pair of lanes (SSE2 has no wider form; under AVX the pairs
// are VEX-encoded and cost about what the wider square roots do).
[[gnu::always_inline]] inline Lane4 sqrt4(Lane4 v) {
  const __m128d lo = _mm_sqrt_pd(__m128d{v[0], v[1]});
  const __m128d hi = _mm_sqrt_pd(__m128d{v[2], v[3]});
  return Lane4{lo[0], lo[1], hi[0], hi[1]};
}
[[gnu::always_inline]] inline Lane4 sqrtLanes(Lane4 v) { return sqrt4(v); }
[[gnu::always_inline]] inline Lane8 sqrtLanes(Lane8 v) { return {sqrt4(v.lo), sqrt4(v.hi)}; }
// std::max(0.0, x) per lane: (0 < x) ? x : 0 (NaN and -0 give +0).
template <class V>
[[gnu::always_inline]] inline V maxZeroLanes(V x) {
  return selectLanes(x > splatAs<V>(0.0), x, splatAs<V>(0.0));
}

#pragma GCC diagnostic pop

}  // namespace rc::ref
