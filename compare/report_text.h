// Inside compare/: the sentences reports use for each class (report.cpp), shared by the
// JUnit and HTML writers so that every output says the same thing in the same words.
#pragma once

#include <string>
#include <string_view>

#include "compare/compare.h"

namespace rc {

// "(x,y) window (x,H-1-y)", or "(none)".
std::string where(const PixelRef& p, int height);
// One sentence per class: status, counts, thresholds, worst pixel.
std::string visibilityText(const PairResult& r);
std::string depthText(const PairResult& r);
std::string shadingText(const PairResult& r);
// Text made safe for HTML element content and attribute values (& < > " ').
std::string htmlEscape(std::string_view text);
// The shading allowance formula with the pair's numbers filled in.
std::string shadingAllowanceText(const Tolerances& t, double slope_band_px);

}  // namespace rc
