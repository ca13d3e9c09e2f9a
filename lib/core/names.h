#pragma once
/// @file Names of enumerations as they appear in scenario files and outputs: each enum that a
/// scenario sets declares, beside it, one table `{value, "name"}`; the scenario reader parses
/// the name once, and the components compare enum values only.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"

namespace rths {

/// One value of an enumeration and its name in files.
template <typename E>
struct Named {
  E value;
  std::string_view name;
};

/// The name of `value` in `table` ("" if it has none).
template <typename E, std::size_t N>
constexpr std::string_view NameOf(const std::array<Named<E>, N>& table, E value) {
  for (const Named<E>& n : table)
    if (n.value == value) return n.name;
  return {};
}

/// The value called `name` in `table`, or nullopt.
template <typename E, std::size_t N>
constexpr std::optional<E> ValueOf(const std::array<Named<E>, N>& table, std::string_view name) {
  for (const Named<E>& n : table)
    if (n.name == name) return n.value;
  return std::nullopt;
}

/// "\"a\", \"b\", \"c\"": the allowed names, for error messages.
template <typename E, std::size_t N>
std::string QuotedNames(const std::array<Named<E>, N>& table) {
  std::string out;
  for (const Named<E>& n : table) {
    if (!out.empty()) out += ", ";
    out += '"';
    out += n.name;
    out += '"';
  }
  return out;
}

/// The value called `name`; throws rths::Error(where, "\"x\" is not allowed (allowed: ...)").
template <typename E, std::size_t N>
E ParseName(const std::array<Named<E>, N>& table, std::string_view name, const std::string& where) {
  if (const std::optional<E> v = ValueOf(table, name)) return *v;
  throw Error(where, "\"" + std::string(name) + "\" is not allowed (allowed: " + QuotedNames(table) + ")");
}

}  // namespace rths
