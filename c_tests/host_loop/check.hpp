// The checks: counters of checks and failures, CHECK (a condition, printf details on failure)
// and CHECK_OK (a call's status and first_failed).
#pragma once

#include <cstddef>
#include <cstdint>

#include "ampm.h"

#include <cstdio>

namespace {

long g_checks = 0, g_failures = 0;

#define CHECK(cond, ...)                                                        \
  do {                                                                          \
    ++g_checks;                                                                 \
    if (!(cond)) {                                                              \
      ++g_failures;                                                             \
      std::fprintf(stderr, "%s:%d: FAIL %s: ", __FILE__, __LINE__, #cond);      \
      std::fprintf(stderr, __VA_ARGS__);                                        \
      std::fputc('\n', stderr);                                                 \
    }                                                                           \
  } while (0)

#define CHECK_OK(call, n)                                                                  \
  do {                                                                                     \
    std::size_t ff_ = static_cast<std::size_t>(-1);                                        \
    const AmpmStatus st_ = (call)(&ff_);                                                   \
    CHECK(st_ == AMPM_OK && ff_ == (n), "status %d, first_failed %zu (n = %zu)", int(st_), \
          ff_, static_cast<std::size_t>(n));                                               \
  } while (0)

}  // namespace
