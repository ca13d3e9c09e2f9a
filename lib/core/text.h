#pragma once
/// @file Text helpers shared by the file and argument readers.
#include <string_view>

namespace rths {

/// Every character std::isspace accepts in the "C" locale: space, tab, LF, VT, FF, CR (signal files).
inline constexpr std::string_view kWhitespace = " \t\n\v\f\r";
/// TOML's whitespace (space and tab): the --set overrides, which are TOML text.
inline constexpr std::string_view kTomlWhitespace = " \t";
/// Space, tab and a CR/LF line end: the rig-record and UTFSM readers (VT and FF are kept as data).
inline constexpr std::string_view kLineWhitespace = " \t\r\n";

/// `s` without the leading and trailing characters found in `strip` ("" if nothing else is left).
/// The view points into `s`: copy it (std::string) before `s` goes away.
constexpr std::string_view Trim(std::string_view s, std::string_view strip = kWhitespace) {
  const auto first = s.find_first_not_of(strip);
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(strip);
  return s.substr(first, last - first + 1);
}

}  // namespace rths
