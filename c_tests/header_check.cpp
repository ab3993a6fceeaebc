// Header check, C++17: the same translation unit as header_check.c, compiled as C++ (see
// there). Also checks that the declarations have C linkage inside `extern "C"`.
#include "header_check.c"

#include <type_traits>

static_assert(std::is_enum<AmpmStatus>::value, "AmpmStatus is an enum");
static_assert(sizeof(AmpmStatus) == sizeof(int), "AmpmStatus has the size of a C int");
