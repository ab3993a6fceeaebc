// Checks for the tests that use neither Eigen nor common.hpp (the host loop, the ampm.hpp
// particle wrappers, the threads): counters of checks and failures, and CHECK(cond, printf
// format, args...), which counts the check and on failure prints file:line, the condition and
// the details. main() prints the counters and returns g_failures == 0 ? 0 : 1.
#pragma once

#include <cstdio>

namespace {

long g_checks = 0, g_failures = 0;

#define CHECK(cond, ...)                                                   \
  do {                                                                     \
    ++g_checks;                                                            \
    if (!(cond)) {                                                         \
      ++g_failures;                                                        \
      std::fprintf(stderr, "%s:%d: FAIL %s: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                                   \
      std::fputc('\n', stderr);                                            \
    }                                                                      \
  } while (0)

}  // namespace
