// Invariant checks: the "broken invariant" error channel (ARCHITECTURE.md,
// "Error channels"). A failed CHECK prints the expression, both operands and the location, then
// aborts. Bad *input* never reaches a CHECK: it raises core::InputError.
#pragma once

#include <cstdlib>
#include <sstream>
#include <string>

namespace core::internal {

[[noreturn]] void CheckFailed(const char* file, int line, const char* expr,
                              const std::string& detail);

template <typename A, typename B>
std::string FormatOperands(const A& a, const B& b) {
  std::ostringstream os;
  os << "(" << a << " vs. " << b << ")";
  return os.str();
}

}  // namespace core::internal

#define IBR_CHECK(cond)                                                        \
  do {                                                                         \
    if (!(cond)) ::core::internal::CheckFailed(__FILE__, __LINE__, #cond, ""); \
  } while (false)

#define IBR_CHECK_OP_(a, b, op)                                                                    \
  do {                                                                                             \
    const auto& ibr_check_a_ = (a);                                                                \
    const auto& ibr_check_b_ = (b);                                                                \
    if (!(ibr_check_a_ op ibr_check_b_))                                                           \
      ::core::internal::CheckFailed(__FILE__, __LINE__, #a " " #op " " #b,                         \
                                    ::core::internal::FormatOperands(ibr_check_a_, ibr_check_b_)); \
  } while (false)

#define IBR_CHECK_EQ(a, b) IBR_CHECK_OP_(a, b, ==)
#define IBR_CHECK_NE(a, b) IBR_CHECK_OP_(a, b, !=)
#define IBR_CHECK_LT(a, b) IBR_CHECK_OP_(a, b, <)
#define IBR_CHECK_LE(a, b) IBR_CHECK_OP_(a, b, <=)
#define IBR_CHECK_GT(a, b) IBR_CHECK_OP_(a, b, >)
#define IBR_CHECK_GE(a, b) IBR_CHECK_OP_(a, b, >=)
