// Per-fragment operations: see fragment_ops.h.
#include "reference/fragment_ops.h"

#include <bit>

namespace rc::ref {

double depthStepsPerUnit(DepthFormat format) {
  switch (format) {
    case DepthFormat::D16:
      return 65535.0;
    case DepthFormat::D24:
      return 16777215.0;
    case DepthFormat::D32F:
      break;
  }
  return 16777216.0;  // one step = 2^-24 (a float ulp just below 1 is 2^-24)
}

double storedDepth(std::uint32_t key, DepthFormat format) {
  if (format == DepthFormat::D32F) {
    return std::bit_cast<float>(key);
  }
  return key / depthStepsPerUnit(format);
}

}  // namespace rc::ref
