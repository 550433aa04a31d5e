#pragma once
// How GoogleTest prints the project's enums as test parameters: by name. Without a
// printer it dumps their bytes, and gtest_discover_tests puts that dump into the ctest
// name ("... # GetParam() = 4-byte object <01-00 00-00>").

#include <ostream>

#include "fixtures/scene.h"
#include "gl_backend/gl_testing.h"

namespace rc {

inline void PrintTo(DepthFormat v, std::ostream* os) { *os << toString(v); }
inline void PrintTo(ColorFormat v, std::ostream* os) { *os << toString(v); }

}  // namespace rc

namespace rc::gl::testing {

inline void PrintTo(Faults::Blend v, std::ostream* os) {
  *os << (v == Faults::Blend::One ? "one" : v == Faults::Blend::Swapped ? "swapped" : "correct");
}

}  // namespace rc::gl::testing
