// A test that cannot run on this machine (no tmpfs mount, no h5py) says so and returns: the line
// "SKIPPED: <why>" on stdout makes ctest report the test as skipped (SKIP_REGULAR_EXPRESSION in
// tests/CMakeLists.txt), never as passed with nothing checked.
#pragma once

#include <catch2/catch.hpp>

#include <cstdio>
#include <sstream>
#include <string>

#define GRASPSIM_SKIP(why)                                         \
  do {                                                             \
    std::ostringstream graspsim_skip_reason;                       \
    graspsim_skip_reason << why;                                   \
    std::printf("SKIPPED: %s\n", graspsim_skip_reason.str().c_str()); \
    std::fflush(stdout);                                           \
    WARN("SKIPPED: " << graspsim_skip_reason.str());               \
    return;                                                        \
  } while (false)
