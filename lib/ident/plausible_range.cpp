#include "ident/plausible_range.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rths::ident {

namespace {

/// A parameter's range at A = kPlausibleRangeA (docs/identification.md "Plausible ranges": the
/// smallest published value / 10 to the largest x 10, rounded; 0 where a damper may lack the term).
struct Row {
  std::string_view name;
  double lo, hi;
  std::string_view unit;
  bool scales_with_A;  ///< alpha, beta, gamma (file comment of plausible_range.h)
};

constexpr std::array<Row, 8> kRows = {{
    {"alpha", 2e-4, 5.5, "kN/mm", true},      // 0.0022 (UTFSM 0 A) .. 0.55 (Table 3, 2.5 A)
    {"c0", 1e-4, 3.2, "kN s/mm", false},      // 0.0010 (UTFSM 0 A) .. 0.32 (Table 3)
    {"c1", 1.8e-3, 150.0, "kN s/mm", false},  // 0.018 (UTFSM 0 A) .. 15 (Table 3)
    {"k0", 0.0, 0.047, "kN/mm", false},       // 0 (Table 3, UTFSM) .. 0.0047 (Spencer et al. 1997)
    {"k1", 0.0, 0.0091, "kN/mm", false},      // 0 (Table 3) .. 0.00091 (UTFSM 0 A)
    {"beta", 0.0, 36.0, "1/mm^2", true},      // 0 (UTFSM) .. 3.63 (Spencer et al. 1997)
    {"gamma", 2e-4, 36.0, "1/mm^2", true},    // 0.0020 (Table 3, 2.5 A) .. 3.63 (Spencer et al. 1997)
    {"eta_1_s", 0.31, 1900.0, "1/s", false},  // pi (Eq. 40's pole) .. 190 (Spencer et al. 1997)
}};
/// The rates p_c per A: Table 3's 1.0 .. 5.2 1/A.
constexpr double kRateLo = 0.1, kRateHi = 52.0;

bool EndsWith(std::string_view s, std::string_view tail) {
  return s.size() > tail.size() && s.substr(s.size() - tail.size()) == tail;
}

}  // namespace

std::optional<PlausibleRange> PlausibleRangeOf(std::string_view name, double A, bool voltage) {
  std::string_view base = name;
  bool rate = false;
  if (name != "eta_1_s") {
    for (std::string_view tail : {"_a", "_b", "_c"}) {
      if (!EndsWith(name, tail)) continue;
      base = name.substr(0, name.size() - 2);
      rate = tail == "_c";
    }
  }
  for (const Row& r : kRows) {
    if (r.name != base) continue;
    if (rate) {
      if (voltage || r.name == "k0" || r.name == "k1" || r.name == "eta_1_s") return std::nullopt;
      return PlausibleRange{kRateLo, kRateHi, "1/A"};
    }
    const double s = r.scales_with_A ? kPlausibleRangeA / A : 1.0;
    return PlausibleRange{r.lo * s, r.hi * s, std::string(r.unit)};
  }
  return std::nullopt;
}

std::vector<Implausible> CheckPlausible(const std::vector<std::pair<std::string, double>>& values, double A,
                                        bool voltage) {
  std::vector<Implausible> out;
  for (const auto& [name, value] : values) {
    const auto r = PlausibleRangeOf(name, A, voltage);
    if (!r || (value >= r->lo && value <= r->hi)) continue;
    out.push_back({name, value, r->lo, r->hi, r->unit});
  }
  return out;
}

namespace {

/// A rate "p_c" of `status` whose law is flat: its ends p_a, p_b both at zero, or equal within
/// 0.1 %; the rate then changes nothing (as fit_status.h's "irrelevant", for a rate off its bounds).
bool FlatLaw(const FitStatus& status, const std::string& rate) {
  if (!EndsWith(rate, "_c") || rate == "eta_1_s") return false;
  const std::string base = rate.substr(0, rate.size() - 2);
  const ParameterStatus *a = nullptr, *b = nullptr;
  for (const auto& p : status.parameters) {
    if (p.name == base + "_a") a = &p;
    if (p.name == base + "_b") b = &p;
  }
  if (!a || !b) return false;
  return (a->state == ParameterState::kAtZero && b->state == ParameterState::kAtZero) ||
         std::abs(a->value - b->value) <= 1e-3 * std::max(a->value, b->value);
}

}  // namespace

std::vector<std::pair<std::string, double>> FittedValues(const FitStatus& status,
                                                         std::vector<std::pair<std::string, double>> extra) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& p : status.parameters)
    if (p.state == ParameterState::kFree && !FlatLaw(status, p.name)) out.emplace_back(p.name, p.value);
  out.insert(out.end(), extra.begin(), extra.end());
  return out;
}

}  // namespace rths::ident
