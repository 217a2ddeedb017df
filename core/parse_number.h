// One number from text, as every reader of user text needs it: the whole
// string is one finite number ("1.5", "-2e3"), or nothing ("", "1.5x",
// "nan", "1e999"). std::stod alone accepts a prefix and throws on the rest.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

namespace core {

std::optional<double> ParseFiniteNumber(std::string_view text);

// "1,2.5,-3": the whole text is finite numbers with `separator` between
// them (no empty field); nothing otherwise.
std::optional<std::vector<double>> ParseNumberList(std::string_view text, char separator = ',');

}  // namespace core
