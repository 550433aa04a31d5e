// The pixel class table: see pixel_class.h.
#include "compare/pixel_class.h"

namespace rc {
namespace {

// In code order (PixelClass values are the indices).
constexpr PixelClassInfo kTable[kPixelClassCount] = {
    {PixelClass::Background, "background", "background", {0, 0, 0}, false},
    {PixelClass::Match, "match", "match", {96, 96, 96}, false},
    {PixelClass::MissingAmbiguous,
     "missing_ambiguous",
     "missing (ambiguous)",
     {255, 170, 170},
     true},
    {PixelClass::MissingHard, "missing_hard", "missing", {230, 20, 20}, false},
    {PixelClass::ExtraAmbiguous, "extra_ambiguous", "extra (ambiguous)", {160, 200, 255}, true},
    {PixelClass::ExtraHard, "extra_hard", "extra", {30, 110, 255}, false},
    {PixelClass::WrongAmbiguous,
     "wrong_primitive_ambiguous",
     "wrong_primitive (ambiguous)",
     {255, 240, 150},
     true},
    {PixelClass::WrongHard, "wrong_primitive_hard", "wrong_primitive", {255, 200, 0}, false},
};

constexpr bool inCodeOrder() {
  for (int k = 0; k < kPixelClassCount; ++k)
    if (static_cast<int>(kTable[k].value) != k) return false;
  return true;
}
static_assert(inCodeOrder(), "kTable rows must be in PixelClass code order");

// An out-of-range code (a corrupt map) gets a row of its own rather than a crash.
constexpr PixelClassInfo kUnknown = {PixelClass::Background, "?", "?", {255, 0, 255}, false};

}  // namespace

const PixelClassInfo& pixelClassInfo(PixelClass c) {
  const auto code = static_cast<int>(c);
  return code < kPixelClassCount ? kTable[code] : kUnknown;
}

const char* toString(PixelClass c) { return pixelClassInfo(c).label; }

}  // namespace rc
