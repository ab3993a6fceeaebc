/*
 * Header check: include/ampm.h must compile, warning-free, as strict C99 (this file) and as
 * C++17 (header_check.cpp includes this file). Run by ctest as `header_c99` and
 * `header_cxx17` with -Wall -Wextra -Wpedantic -Werror.
 *
 * Besides parsing, it pins the ABI the tests rely on: the include guard works, the status
 * codes have their documented values, and each of the 28 kernel entry points has exactly
 * the prototype below (initialising a typed function pointer from a function of another
 * type is a constraint violation in C and an error in C++, so a changed signature fails).
 */
#include "ampm.h"
#include "ampm.h" /* the include guard must make a second inclusion harmless */

#include <stddef.h>

/* Compile-time assertions without C11's _Static_assert: a negative array size is an error. */
#define AMPM_CHECK(name, cond) typedef char ampm_check_##name[(cond) ? 1 : -1]
AMPM_CHECK(ok, AMPM_OK == 0);
AMPM_CHECK(null_pointer, AMPM_ERR_NULL_POINTER == 1);
AMPM_CHECK(non_finite, AMPM_ERR_NON_FINITE == 2);
AMPM_CHECK(non_positive_j, AMPM_ERR_NON_POSITIVE_J == 3);
AMPM_CHECK(overflow, AMPM_ERR_OVERFLOW == 4);
AMPM_CHECK(invalid_argument, AMPM_ERR_INVALID_ARGUMENT == 5);
AMPM_CHECK(not_converged, AMPM_ERR_NOT_CONVERGED == 6);
AMPM_CHECK(internal, AMPM_ERR_INTERNAL == 7);
AMPM_CHECK(not_prepared, AMPM_ERR_NOT_PREPARED == 8);

/* Prototypes of one scalar type T, suffix S, for both dimensions. */
#define AMPM_TABLE_MEMBERS(T, S)                                                              \
  AmpmStatus (*b_z_2d_##S)(const T *, const T *, T *);                                        \
  AmpmStatus (*b_z_3d_##S)(const T *, const T *, T *);                                        \
  AmpmStatus (*z_b_2d_##S)(const T *, const T *, T *);                                        \
  AmpmStatus (*z_b_3d_##S)(const T *, const T *, T *);                                        \
  AmpmStatus (*energy_hat_2d_##S)(T, const T *, T *);                                         \
  AmpmStatus (*energy_hat_3d_##S)(T, const T *, T *);                                         \
  AmpmStatus (*ahat_2d_##S)(T, const T *, T *);                                               \
  AmpmStatus (*ahat_3d_##S)(T, const T *, T *);                                               \
  AmpmStatus (*chat_z_2d_##S)(T, const T *, const T *, T *);                                  \
  AmpmStatus (*chat_z_3d_##S)(T, const T *, const T *, T *);                                  \
  AmpmStatus (*ahat_batch_2d_##S)(size_t, const T *, const T *, T *, size_t *);               \
  AmpmStatus (*ahat_batch_3d_##S)(size_t, const T *, const T *, T *, size_t *);               \
  AmpmStatus (*chat_z_batch_2d_##S)(size_t, const T *, const T *, const T *, T *, size_t *);  \
  AmpmStatus (*chat_z_batch_3d_##S)(size_t, const T *, const T *, const T *, T *, size_t *);

#define AMPM_TABLE_INIT(S)                                                                    \
  ampm_b_z_2d_##S, ampm_b_z_3d_##S, ampm_z_b_2d_##S, ampm_z_b_3d_##S,                         \
      ampm_energy_hat_2d_##S, ampm_energy_hat_3d_##S, ampm_ahat_2d_##S, ampm_ahat_3d_##S,     \
      ampm_chat_z_2d_##S, ampm_chat_z_3d_##S, ampm_ahat_batch_2d_##S, ampm_ahat_batch_3d_##S, \
      ampm_chat_z_batch_2d_##S, ampm_chat_z_batch_3d_##S

struct ampm_abi_table {
  AMPM_TABLE_MEMBERS(float, f32)
  AMPM_TABLE_MEMBERS(double, f64)
};

/* External linkage (also in C++, where a const object would otherwise be internal and could
 * draw an unused-variable warning). */
extern const struct ampm_abi_table ampm_abi_table_instance;
const struct ampm_abi_table ampm_abi_table_instance = {AMPM_TABLE_INIT(f32),
                                                       AMPM_TABLE_INIT(f64)};
