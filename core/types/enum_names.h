#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>

namespace stcalib {

// A table of an enum's values and their flag names (`--scene=urban`, `--loss=tukey`).
template <typename Enum, size_t N>
using EnumNames = std::array<std::pair<Enum, const char*>, N>;

// The value named `name`; false (and `value` untouched) for an unknown name.
template <typename Enum, size_t N>
bool ParseEnumName(const EnumNames<Enum, N>& names, const std::string& name, Enum* value) {
  for (const auto& [v, n] : names) {
    if (name == n) {
      *value = v;
      return true;
    }
  }
  return false;
}

template <typename Enum, size_t N>
std::string EnumName(const EnumNames<Enum, N>& names, Enum value) {
  for (const auto& [v, n] : names) {
    if (v == value) return n;
  }
  return "?";
}

// The table's names for a message: "a, b or c".
template <typename Enum, size_t N>
std::string EnumNameChoices(const EnumNames<Enum, N>& names) {
  std::string text;
  for (size_t i = 0; i < N; ++i) {
    if (i > 0) text += i + 1 < N ? ", " : " or ";
    text += names[i].second;
  }
  return text;
}

}  // namespace stcalib
