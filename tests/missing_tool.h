#pragma once
// GoogleTest's form of tests/missing-tool: a test that cannot run because a tool or data package is
// not installed is skipped, but fails with CI=true, where every test must run (CI installs everything
// with scripts/setup, so a missing one there is a broken setup that a skip would hide).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string_view>

#define PRIZMA_MISSING_TOOL(what)                                                                        \
  do {                                                                                                   \
    if (const char* prizma_ci = std::getenv("CI"); prizma_ci != nullptr && std::string_view(prizma_ci) == "true") \
      FAIL() << (what) << " is missing (CI=true: a missing tool fails the test instead of skipping it)"; \
    GTEST_SKIP() << (what) << " is missing";                                                            \
  } while (false)
