#include "core/parse_number.h"

#include <algorithm>
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

std::optional<std::vector<double>> ParseNumberList(std::string_view text, char separator) {
  std::vector<double> values;
  for (size_t start = 0;;) {
    const size_t end = std::min(text.find(separator, start), text.size());
    const std::optional<double> value = ParseFiniteNumber(text.substr(start, end - start));
    if (!value) return std::nullopt;
    values.push_back(*value);
    if (end == text.size()) return values;
    start = end + 1;
  }
}

}  // namespace core
