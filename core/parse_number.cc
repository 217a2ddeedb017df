#include "core/parse_number.h"

#include <cmath>
#include <exception>
#include <string>

namespace core {

std::optional<double> ParseFiniteNumber(std::string_view text) {
  const std::string s(text);
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(s, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (s.empty() || used != s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace core
