// Checks of the catalog itself, without GL: the expectations file is valid (and its
// validator catches each kind of mistake), every required tag is covered, and
// fixtures/README.md is what `rastercheck list --markdown` makes of the catalog today.
#include <gtest/gtest.h>

#include "tests/conformance/conformance_support.h"

using namespace rc;
using namespace rc::conformance;

TEST(Expectations, FileIsValid) {
  const Expectations& e = expectations();
  std::string all;
  for (const std::string& line : e.errors) all += "\n  " + line;
  EXPECT_TRUE(e.errors.empty()) << expectationsFile().string() << ":" << all;
}
