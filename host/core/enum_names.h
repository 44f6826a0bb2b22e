// enum_names.h: an enumeration's names as files and messages spell them, listed once per
// enumeration as (name, value) pairs; every lookup in either direction goes through the list.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace narval {

template <typename E>
using EnumNames = std::vector<std::pair<const char*, E>>;

// The name of `value`; std::logic_error for a value the list lacks (a list out of date).
template <typename E>
const char* enumName(const EnumNames<E>& names, E value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  throw std::logic_error("enumName: a value with no name in its list");
}

// The value called `name`; false (out untouched) for a name the list lacks.
template <typename E>
bool enumFromName(const EnumNames<E>& names, const std::string& name, E* out) {
  for (const auto& [n, v] : names)
    if (name == n) {
      *out = v;
      return true;
    }
  return false;
}

// "a, b, c": the names in order, for messages.
template <typename E>
std::string enumNameList(const EnumNames<E>& names) {
  std::string out;
  for (const auto& [name, value] : names) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

}  // namespace narval
