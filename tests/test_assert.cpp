// The programmer-error tier (voxfield/detail/assert.h): in checking builds (debug, asan-ubsan) a
// broken invariant stops the process naming the condition and the place; in optimised builds the
// condition is compiled but never evaluated.
#include <gtest/gtest.h>

#include "voxfield/detail/assert.h"

namespace {
int evaluations = 0;
bool counted(bool value) {
  ++evaluations;
  return value;
}
}  // namespace

#ifdef VOXFIELD_ENABLE_ASSERTS
TEST(InternalAssert, ABrokenInvariantStopsWithItsConditionAndPlace) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(VOXFIELD_ASSERT(counted(1 + 1 == 3)),
               "internal invariant broken: counted\\(1 \\+ 1 == 3\\) \\(.*test_assert.cpp:[0-9]+");
  evaluations = 0;
  VOXFIELD_ASSERT(counted(true));
  EXPECT_EQ(evaluations, 1);  // evaluated exactly once
}
#else
TEST(InternalAssert, CompiledOutOfOptimisedBuilds) {
  evaluations = 0;
  VOXFIELD_ASSERT(counted(false));  // would stop a checking build
  EXPECT_EQ(evaluations, 0);
}
#endif
