// Software prefetch of frame rows for a triangle drawn a few triangles later.
//
// A soup of small triangles in random places (a scene's draw order is its own, never
// sorted) touches new frame rows on every triangle, and each triangle's work is short:
// the processor cannot look far enough ahead to start the next triangle's loads while
// the current one waits, so every triangle paid its rows' cache misses in sequence
// (docs/performance.md, eleventh pass: 100k 2-px triangles drew in ~31 ms at random
// places and ~10 ms in row order). The renderer asks for the rows of the triangle kAhead
// places further on; a prefetch is only a hint, so nothing it computes can change a bit
// of the output.
#pragma once

#include <algorithm>
#include <cstddef>

namespace rc::ref {

// Cache lines of plane[begin, end) (elements, end > begin), for writing: the first and
// the last byte's lines and every line between (a line may be asked for twice; no
// rounding to line starts, which cost more instructions than the rare repeat).
template <class T>
[[gnu::always_inline]] inline void prefetchSpan(const T* plane, std::size_t begin,
                                                std::size_t end) {
  constexpr std::ptrdiff_t kLine = 64;
  const char* p = reinterpret_cast<const char*>(plane + begin);
  const char* last = reinterpret_cast<const char*>(plane + end) - 1;
  __builtin_prefetch(p, 1, 3);
  for (p += kLine; p < last; p += kLine) __builtin_prefetch(p, 1, 3);
  __builtin_prefetch(last, 1, 3);
  // GCC counts a prefetch as no effect at all: a function that only loads and prefetches
  // is found pure and its calls are deleted (Renderer::prefetchRows() compiled to nothing).
  // An empty volatile asm is an effect; it emits no instruction and clobbers nothing.
  asm volatile("");
}

// The pixels whose centres can be covered by a triangle with window positions x[3], y[3]
// that the rasterizer moves by at most `margin` px (snapping: half a subpixel step; a
// multisample pass adds its sample offset), clipped to [x0, x1) x [y0, y1); set() is false
// when that is empty or larger than is worth prefetching (a larger triangle walks its rows
// in sequence, which the hardware prefetcher follows).
struct PrefetchBox {
  static constexpr int kAhead = 8;        // triangles: 4 to 16 measured alike, 8 kept
  static constexpr int kMaxRows = 8;      // each row of each plane is its own miss
  static constexpr int kMaxColumns = 16;  // 16 px of RGBA float: four lines a row
  // Frames whose planes the fragments touch total less than this stay in the cache, where
  // the prefetches only cost instructions (100k 2-px triangles: at 200 x 200, 16.9-20.9 ms
  // without against 19.6-22.6 with; at 512 x 512, 25.2-31.4 without, 19.4-20.6 with).
  static constexpr std::size_t kMinFrameBytes = std::size_t{4} << 20;
  int col_begin;
  int col_end;
  int row_begin;
  int row_end;
  bool set(const double* x, const double* y, double margin, int x0, int x1, int y0, int y1) {
    // std::min/max: one instruction each (ternaries became branches, unpredictable in a
    // soup). NaN fails the tests below.
    const double lo_x = std::min(x[0], std::min(x[1], x[2])) - 0.5 - margin;
    const double hi_x = std::max(x[0], std::max(x[1], x[2])) - 0.5 + margin;
    const double lo_y = std::min(y[0], std::min(y[1], y[2])) - 0.5 - margin;
    const double hi_y = std::max(y[0], std::max(y[1], y[2])) - 0.5 + margin;
    // Comparisons first, so that NaN and far positions never reach a conversion.
    if (!(hi_x - lo_x < kMaxColumns && hi_y - lo_y < kMaxRows)) return false;
    if (!(lo_x >= x0 - 2.0 && hi_x <= x1 + 1.0 && lo_y >= y0 - 2.0 && hi_y <= y1 + 1.0))
      return false;
    // Pixel px is covered only if its centre px + 0.5 lies in [lo, hi] + 0.5.
    col_begin = clampInt(ceilInt(lo_x), x0, x1);
    col_end = clampInt(floorInt(hi_x) + 1, x0, x1);
    row_begin = clampInt(ceilInt(lo_y), y0, y1);
    row_end = clampInt(floorInt(hi_y) + 1, y0, y1);
    return col_begin < col_end && row_begin < row_end;
  }

 private:
  static int clampInt(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }
  // floor and ceil for v >= -8 (clip rectangles start at >= 0, and set() tests the rest):
  // truncation of a positive number (std::floor is a library call on x86-64's baseline).
  static int floorInt(double v) { return static_cast<int>(v + 8.0) - 8; }
  static int ceilInt(double v) {
    const int f = floorInt(v);
    return f + (f < v ? 1 : 0);
  }
};

}  // namespace rc::ref
