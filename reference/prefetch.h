// Software prefetch of frame rows for a triangle drawn a few triangles later.
//
// A soup of small triangles in random places (a scene's draw order is its own, never
// sorted) touches new frame rows on every triangle, and each triangle's work is short:
// the processor cannot look far enough ahead to start the next triangle's loads while
// the current one waits, so every triangle paid its rows' cache misses in sequence
// (docs/performance.md, "Why the hot code looks the way it does": 100k 2-px triangles drew
// in 30-43 ms at random places and ~10 ms in row order). The renderer asks for the rows of the
// triangle kAhead places further on; a prefetch is only a hint, so nothing it computes can change a
// bit of the output.
#pragma once

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

// Which triangles get their rows prefetched, and how far ahead.
struct PrefetchBox {
  static constexpr int kAhead = 8;        // triangles: 4 to 16 measured alike, 8 kept
  static constexpr int kMaxRows = 8;      // each row of each plane is its own miss
  static constexpr int kMaxColumns = 16;  // 16 px of RGBA float: four lines a row
  // Frames whose planes the fragments touch total less than this stay in the cache, where
  // the prefetches only cost instructions (100k 2-px triangles: at 200 x 200, 16.9-20.9 ms
  // without against 19.6-22.6 with; at 512 x 512, 25.2-31.4 without, 19.4-20.6 with).
  static constexpr std::size_t kMinFrameBytes = std::size_t{4} << 20;

  // The pixels a triangle with snapped vertices v[3] can cover within `clip`
  // (snappedPixelBox(), TriangleCoverage's box); false when that is empty or larger than is
  // worth prefetching (a larger triangle walks its rows in sequence, which the hardware
  // prefetcher follows). The vertices must be inside the clip volume (|coordinates| far
  // below 2^61, as drawTriangle()'s fast path has them).
  static bool worthPrefetching(const FixedVertex* v, int bits, const PixelRect& clip,
                               PixelBox& box) {
    box = snappedPixelBox(v[0], v[1], v[2], bits, clip);
    return !box.empty() && box.col_end - box.col_begin <= kMaxColumns &&
           box.row_end - box.row_begin <= kMaxRows;
  }
};

}  // namespace rc::ref
