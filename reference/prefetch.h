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
#include <cstdint>

#include "reference/rasterizer.h"

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

// The pixels a triangle with snapped vertices v[3] (subpixel units, `bits` fractional bits,
// as TriangleCoverage takes them) can cover: its snapped bounding box's pixel centres,
// TriangleCoverage::setup()'s box, clipped to [x0, x1) x [y0, y1). set() is false when that
// is empty or larger than is worth prefetching (a larger triangle walks its rows in
// sequence, which the hardware prefetcher follows). The vertices must be inside the clip
// volume (|coordinates| far below 2^61, as drawTriangle()'s fast path has them).
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
  bool set(const FixedVertex* v, int bits, int x0, int x1, int y0, int y1) {
    const std::int64_t lo_x = std::min(v[0].x, std::min(v[1].x, v[2].x));
    const std::int64_t hi_x = std::max(v[0].x, std::max(v[1].x, v[2].x));
    const std::int64_t lo_y = std::min(v[0].y, std::min(v[1].y, v[2].y));
    const std::int64_t hi_y = std::max(v[0].y, std::max(v[1].y, v[2].y));
    if ((hi_x - lo_x) >> bits >= kMaxColumns || (hi_y - lo_y) >> bits >= kMaxRows) return false;
    // ceil(n / 2^bits) is -((-n) >> bits) and floor is n >> bits (TriangleCoverage::setup()).
    col_begin = clamp(-((-lo_x) >> bits), x0, x1);
    col_end = clamp((hi_x >> bits) + 1, x0, x1);
    row_begin = clamp(-((-lo_y) >> bits), y0, y1);
    row_end = clamp((hi_y >> bits) + 1, y0, y1);
    return col_begin < col_end && row_begin < row_end;
  }

 private:
  static int clamp(std::int64_t n, int lo, int hi) {
    return static_cast<int>(n < lo ? lo : n > hi ? hi : n);
  }
};

}  // namespace rc::ref
