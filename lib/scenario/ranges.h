#pragma once
/// @file Internal to lib/scenario: allowed values (ranges) and the checks that name the file and key.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "scenario/toml_section.h"

namespace rths::scenario::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// An interval of allowed values; `note` explains a computed bound.
struct Range {
  double lo;
  double hi;
  bool lo_open;
  bool hi_open;
  std::string note = {};
};
inline Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Range OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }
inline Range ClosedOpen(double lo, double hi) { return {lo, hi, false, true}; }
inline Range Open(double lo, double hi) { return {lo, hi, true, true}; }
/// Any value (a seed, a flag): the type is the only check.
inline const Range kAny{-kInf, kInf, false, false};

/// Range and choice checks whose failures name "<file>: <key>".
class Check {
 public:
  explicit Check(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(std::string_view key, std::string problem) const {
    throw Error(fmt::format("{}: {}", file_, key), std::move(problem));
  }

  const std::string& file() const { return file_; }

  void InRange(std::string_view key, double v, const Range& r) const {
    const bool above_lo = r.lo_open ? v > r.lo : v >= r.lo;
    const bool below_hi = r.hi_open ? v < r.hi : v <= r.hi;
    if (std::isfinite(v) && above_lo && below_hi) return;
    std::string problem = fmt::format("{} is out of range {}{}, {}{}", v, r.lo_open ? '(' : '[', r.lo, r.hi,
                                      r.hi_open ? ')' : ']');
    if (!r.note.empty()) problem += " (" + r.note + ")";
    Fail(key, problem);
  }

  void OneOf(std::string_view key, const std::string& v, const std::vector<std::string_view>& allowed) const {
    if (std::find(allowed.begin(), allowed.end(), v) != allowed.end()) return;
    Fail(key, fmt::format("\"{}\" is not allowed (allowed: {})", v, JoinList(allowed, "\"")));
  }

 private:
  std::string file_;
};

/// What a range may depend on besides the table's own fields.
struct Context {
  double dt_s;
  std::int64_t steps;
};

}  // namespace rths::scenario::detail
