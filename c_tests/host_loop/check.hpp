// The checks: CHECK and its counters (plain_check.hpp), and CHECK_OK (a call's status and
// first_failed).
#pragma once

#include <cstddef>
#include <cstdint>

#include "ampm.h"
#include "plain_check.hpp"

namespace {

#define CHECK_OK(call, n)                                                                  \
  do {                                                                                     \
    std::size_t ff_ = static_cast<std::size_t>(-1);                                        \
    const AmpmStatus st_ = (call)(&ff_);                                                   \
    CHECK(st_ == AMPM_OK && ff_ == (n), "status %d, first_failed %zu (n = %zu)", int(st_), \
          ff_, static_cast<std::size_t>(n));                                               \
  } while (0)

}  // namespace
