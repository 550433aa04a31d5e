// The per-pixel visibility classes of the comparison and their one table of names: the
// code ClassMaps and diff.exr's id_class store, the stable key of `explain --json`, the
// label people read (reports, summaries) and the colour of visibility.png.
#pragma once

#include <array>
#include <cstdint>

namespace rc {

// Per-pixel visibility class (a = expected id, b = actual id).
enum class PixelClass : std::uint8_t {
  Background = 0,        // a = b = 0
  Match = 1,             // a = b != 0: depth and shading are compared here
  MissingAmbiguous = 2,  // a != 0, b = 0, within the band
  MissingHard = 3,
  ExtraAmbiguous = 4,  // a = 0, b != 0
  ExtraHard = 5,
  WrongAmbiguous = 6,  // a, b != 0, a != b: within the band or a depth tie
  WrongHard = 7,
};
inline constexpr int kPixelClassCount = 8;

struct PixelClassInfo {
  PixelClass value;
  const char* key;                    // stable, for JSON: "missing_ambiguous"
  const char* label;                  // for people: "missing (ambiguous)"
  std::array<std::uint8_t, 3> color;  // visibility.png (docs/reports.md)
  bool ambiguous;                     // a mismatch the reference says may go either way
};

// The row of `c` (every PixelClass has one; kPixelClassInfo[code] is the class `code`).
const PixelClassInfo& pixelClassInfo(PixelClass c);
// pixelClassInfo(c).label.
const char* toString(PixelClass c);

}  // namespace rc
