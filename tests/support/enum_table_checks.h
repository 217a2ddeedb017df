// Checks every enum <-> name table must pass (core/enum_names.h), applied to
// a table and the FromName/Name functions its module exposes over it.
#pragma once

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <string_view>

#include "core/enum_names.h"
#include "core/error.h"

namespace test_support {

// Round trips over every entry: FromName(entry name) is the entry's value;
// Name(value) is the value's first name and FromName of it gives the value
// back. An unknown name throws InputError naming the name, `what` and every
// entry as the table lists it.
template <typename E, size_t N, typename FromName, typename ToName>
void ExpectEnumTable(const core::EnumName<E> (&table)[N], FromName from_name, ToName to_name,
                     std::string_view what) {
  std::set<E> named;
  for (const core::EnumName<E>& e : table) {
    SCOPED_TRACE(std::string(e.name));
    EXPECT_EQ(from_name(std::string(e.name)), e.value);
    EXPECT_EQ(core::EnumFromName(table, e.name, "test", what), e.value);
    const std::string name(to_name(e.value));
    EXPECT_EQ(from_name(name), e.value);
    if (named.insert(e.value).second) {
      EXPECT_EQ(name, e.name);  // the first entry names it
    }
  }
  const std::string unknown = "no-such-" + std::string(what);
  try {
    from_name(unknown);
    ADD_FAILURE() << "accepted '" << unknown << "'";
  } catch (const core::InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("unknown " + std::string(what) + " '" + unknown + "' ("),
              std::string::npos)
        << message;
    for (const core::EnumName<E>& e : table) {
      const std::string_view listed = e.listed_as.empty() ? e.name : e.listed_as;
      EXPECT_NE(message.find(std::string(listed)), std::string::npos) << listed << ": " << message;
    }
  }
}

}  // namespace test_support
