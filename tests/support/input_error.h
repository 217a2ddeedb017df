// The message of the core::InputError a call throws ("" when it throws none):
// tests compare whole error lines.
#pragma once

#include <functional>
#include <string>

#include "core/error.h"

namespace test_support {

inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace test_support
