// Enum <-> name tables: one constexpr table per enum, one generic lookup in
// each direction, one "unknown ..." message. An enum that a user names (a CLI
// flag, a scene key) declares its table beside the enum:
//
//   inline constexpr core::EnumName<CutMode> kCutModeNames[] = {
//       {CutMode::kNone, "none"}, {CutMode::kHollow, "hollow"}, ...};
//   static_assert(core::EnumNamesUnique(kCutModeNames));
//
// and its FromName/Name functions are one line each over it:
//   EnumFromName(kCutModeNames, name, "CutModeFromName", "cut") throws
//   InputError("CutModeFromName: unknown cut 'foo' (none, hollow, solid, thick:T)");
//   EnumToName(kCutModeNames, CutMode::kSolid) == "solid".
// A table may hold aliases: later entries with a value already named; the
// first entry of a value is its name.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"

namespace core {

template <typename E>
struct EnumName {
  E value;
  std::string_view name;
  // How an "unknown" message lists this entry, when not as `name` (e.g.
  // "thick:T" for a name that takes a parameter after a colon).
  std::string_view listed_as = {};
};

// True when no name appears twice (for a static_assert beside each table).
template <typename E, size_t N>
constexpr bool EnumNamesUnique(const EnumName<E> (&table)[N]) {
  for (size_t i = 0; i < N; ++i) {
    if (table[i].name.empty()) return false;
    for (size_t j = i + 1; j < N; ++j) {
      if (table[i].name == table[j].name) return false;
    }
  }
  return true;
}

// The value named `name`, or nullopt.
template <typename E, size_t N>
constexpr std::optional<E> FindEnum(const EnumName<E> (&table)[N], std::string_view name) {
  for (const EnumName<E>& e : table) {
    if (e.name == name) return e.value;
  }
  return std::nullopt;
}

// The first name of `value` in the table; "unknown" for a value the table
// lacks (a cast from an out-of-range integer).
template <typename E, size_t N>
constexpr std::string_view EnumToName(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& e : table) {
    if (e.value == value) return e.name;
  }
  return "unknown";
}

// Every entry as an error lists it, in table order: "a, b, c".
template <typename E, size_t N>
std::string EnumNameList(const EnumName<E> (&table)[N]) {
  std::string list;
  for (const EnumName<E>& e : table) {
    if (!list.empty()) list += ", ";
    list += e.listed_as.empty() ? e.name : e.listed_as;
  }
  return list;
}

// The value named `name`; otherwise throws
// InputError("where: unknown what 'name' (a, b, c)").
template <typename E, size_t N>
E EnumFromName(const EnumName<E> (&table)[N], std::string_view name, std::string_view where,
               std::string_view what) {
  if (const std::optional<E> value = FindEnum(table, name)) return *value;
  ThrowInputError(where, "unknown {} '{}' ({})", what, name, EnumNameList(table));
}

}  // namespace core
