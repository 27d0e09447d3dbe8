// Tests that cannot run in a sanitized build of the package (scripts/sanitize.sh) skip there,
// saying why: VIPER_SKIP_IN_SANITIZED_BUILD("reason") at the start of the test.
#pragma once

#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VIPER_SKIP_IN_SANITIZED_BUILD(why) GTEST_SKIP() << (why)
#else
#define VIPER_SKIP_IN_SANITIZED_BUILD(why) (void)0
#endif
