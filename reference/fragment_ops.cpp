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

void storedDepthPlane(const std::uint32_t* keys, std::size_t count, DepthFormat format,
                      float* out) {
  if (format == DepthFormat::D32F) {
    for (std::size_t i = 0; i < count; ++i) out[i] = std::bit_cast<float>(keys[i]);
    return;
  }
  const double per_step = 1.0 / depthStepsPerUnit(format);
  // Integer keys are below 2^24: through int32 the conversion vectorizes (cvtdq2pd).
  for (std::size_t i = 0; i < count; ++i)
    out[i] = static_cast<float>(static_cast<std::int32_t>(keys[i]) * per_step);
}

}  // namespace rc::ref
