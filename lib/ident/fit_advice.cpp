#include "ident/fit_advice.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "ident/plausible_range.h"

namespace rths::ident {

namespace {

/// A model-file name split into its law and its part: "c0_b" -> ("c0", 'b'); "k0" -> ("k0", 0).
struct NameParts {
  std::string base;
  char part = 0;  ///< 'a', 'b', 'c' (the rate) or 0
};

NameParts Split(std::string_view name) {
  if (name != "eta_1_s" && name.size() > 2 && name[name.size() - 2] == '_') {
    const char t = name.back();
    if (t == 'a' || t == 'b' || t == 'c') return {std::string(name.substr(0, name.size() - 2)), t};
  }
  return {std::string(name), 0};
}

const char* Unit(const AdviceContext& c) { return c.voltage ? "V" : "A"; }

/// Where (at which input) a law's end or a coefficient is measured.
std::string Where(char part, const AdviceContext& c) {
  if (!c.any_input) return fmt::format("at {:g} A", c.current_A);
  if (part == 'a') return fmt::format("at the lowest input ({:g} {})", c.input_min, Unit(c));
  if (part == 'b')
    return fmt::format("at the highest input ({:g} {}) and, if the law has not saturated there, above it", c.input_max,
                       Unit(c));
  return "at every input";
}

/// The lowest level above the lowest (the records' design), or 0 if there is none.
double SecondLevel(const AdviceContext& c) { return c.levels.size() >= 2 ? c.levels[1] : 0.0; }

/// The value of a parameter of `status` by name, or NaN.
double ValueOf(const FitStatus& status, const std::string& name) {
  for (const auto& p : status.parameters)
    if (p.name == name) return p.value;
  return std::nan("");
}

std::string HoldHint(std::string_view name, const AdviceContext& c) {
  if (const auto r = PlausibleRangeOf(name, c.A, c.voltage))
    return fmt::format("or hold it at a value you trust: --hold {}=VALUE (plausible: {:.3g} to {:.3g} {})", name, r->lo,
                       r->hi, r->unit);
  return fmt::format("or hold it at a value you trust: --hold {}=VALUE", name);
}

/// `--hold NAME=VALUE` for a rate: the value that puts 95 % of the law's change `by` above the
/// lowest input, 3 / (by - lowest) (1 - e^-3 = 0.95).
std::string HoldRate(std::string_view name, double by, const AdviceContext& c) {
  return fmt::format("--hold {}={:.3g} (95 % of the change by {:g} {})", name, 3.0 / (by - c.input_min), by, Unit(c));
}

/// A rate on a bound (fit file comment).
std::string RateAdvice(const ParameterStatus& p, const NameParts& n, bool upper, const AdviceContext& c) {
  const char* u = Unit(c);
  if (upper) {
    const double l2 = SecondLevel(c);
    std::string o = fmt::format(
        "{} = {:.4g} 1/{} on its upper bound: {} makes all its change from {}_a to {}_b at the very start of the input "
        "range, below ",
        p.name, p.value, u, n.base, n.base, n.base);
    if (l2 > 0.0) {
      o += fmt::format(
          "the lowest level above {:g} {} that the records hold ({:g} {}), so they cannot say how fast. Records at "
          "inputs between {:g} and {:g} {} (e.g. {:.2g} and {:.2g} {}) would determine it; or hold it: {}",
          c.input_min, u, l2, u, c.input_min, l2, u, c.input_min + (l2 - c.input_min) / 3.0,
          c.input_min + 2.0 * (l2 - c.input_min) / 3.0, u, HoldRate(p.name, l2, c));
    } else {
      o += fmt::format(
          "any input the records dwell at, so they cannot say how fast. Records whose command dwells at low inputs, "
          "just above {:g} {}, would determine it; or hold it: --hold {}=VALUE",
          c.input_min, u, p.name);
    }
    return o;
  }
  return fmt::format(
      "{} = {:.4g} 1/{} on its lower bound: {} changes linearly over the inputs fitted and {}_b, its saturated value, "
      "lies far beyond them (an extrapolation). Records at higher inputs, toward the damper's saturation, would "
      "determine it; or hold it: {}, the highest input",
      p.name, p.value, u, n.base, n.base,
      c.input_max > c.input_min ? HoldRate(p.name, c.input_max, c) : "--hold " + p.name + "=VALUE");
}

}  // namespace

std::string WhatDetermines(std::string_view name, const AdviceContext& c) {
  const NameParts n = Split(name);
  const std::string where = Where(n.part, c);
  if (n.part == 'c')
    return fmt::format("{} sets how fast {} follows the input between its ends: records at more input levels, the low "
                       "ones (where the law changes most) included",
                       name, n.base);
  if (n.base == "alpha")
    return fmt::format("{} sets the yield force (alpha z_max, the force's plateau after a reversal): records whose "
                       "strokes go well past the pre-yield travel, {}",
                       name, where);
  if (n.base == "c0")
    return fmt::format("{} is the viscous damping at large velocities (Spencer et al. 1997), the slope of force "
                       "against velocity after the yield: records at higher velocities (amplitude x frequency), {}",
                       name, where);
  if (n.base == "c1")
    return fmt::format("{} produces the roll-off of the force at low velocities (Spencer et al. 1997): records with "
                       "slow velocity reversals (low frequencies), {}",
                       name, where);
  if (n.base == "k0")
    return fmt::format("{} is the stiffness at large velocities (Spencer et al. 1997): records at higher velocities "
                       "and frequencies, {}",
                       name, where);
  if (n.base == "k1")
    return "k1 is the accumulator's stiffness, the force in phase with displacement: slow, long-stroke records";
  if (n.base == "beta" || n.base == "gamma")
    return fmt::format("{} shapes the loop at the reversals (the pre-yield travel 1/sqrt(A (beta + gamma)) and the "
                       "unloading): records at several amplitudes, small ones (a few tenths of a mm to a few mm) "
                       "included, {}",
                       name, where);
  if (n.base == "eta_1_s")
    return "eta_1_s is the rate of the filter between command and force: records whose command steps or pulses while "
           "the damper moves (a constant command never shows it)";
  return fmt::format("{}: records at more inputs, velocities and amplitudes", name);
}

std::string BoundAdvice(const ParameterStatus& p, const AdviceContext& c) {
  const NameParts n = Split(p.name);
  const bool upper = std::abs(std::log(p.value / p.hi)) < std::abs(std::log(p.value / p.lo));
  if (n.part == 'c') return RateAdvice(p, n, upper, c);
  std::string o = fmt::format("{} = {:.4g} on its {} bound: the range, not the data, chose it. {}; ", p.name, p.value,
                              upper ? "upper" : "lower", WhatDetermines(p.name, c));
  if (n.base == "eta_1_s")
    return o + "or hold it: --hold eta_1_s=VALUE (the starts' 100 1/s, say), or leave the filter out: --filter none";
  return o + HoldHint(p.name, c);
}

std::string ImplausibleAdvice(const Implausible& p, const FitStatus& status, const AdviceContext& c) {
  const NameParts n = Split(p.name);
  std::string o = fmt::format("{}: {}", p.name, WhatDetermines(p.name, c));
  if (n.part == 'b' && c.any_input) {
    const double rate = ValueOf(status, n.base + "_c");
    const double span = c.input_max - c.input_min;
    if (rate > 0.0 && 3.0 / rate > span)
      o += fmt::format(" (with {}_c = {:.3g} 1/{} the law reaches 95 % of its way to {} only {:.3g} {} above the lowest "
                       "input, beyond the highest the records reach, {:g} {}: {} is an extrapolation)",
                       n.base, rate, Unit(c), p.name, 3.0 / rate, Unit(c), c.input_max, Unit(c), p.name);
  }
  if (n.base == "alpha" || n.base == "beta" || n.base == "gamma")
    o += "; alpha, beta and gamma trade with A (held): read alpha z_max and the pre-yield travel";
  if (n.part == 'c' && c.any_input && c.input_max > c.input_min) {
    // A rate too slow: the law is nearly linear over the records, so saturate it by the highest
    // input; too fast: by the second level the records hold (or the highest input).
    const double l2 = SecondLevel(c);
    const double by = p.value < p.lo || l2 <= c.input_min ? c.input_max : l2;
    return o + fmt::format("; or hold it: {} (plausible: {:.3g} to {:.3g} {})", HoldRate(p.name, by, c), p.lo, p.hi,
                           p.unit);
  }
  return o + "; " + HoldHint(p.name, c);
}

std::vector<std::string> FitAdvice(const FitStatus& status, const AdviceContext& c) {
  std::vector<std::string> out;
  for (const auto& p : status.parameters)
    if (p.state == ParameterState::kAtBound) out.push_back(BoundAdvice(p, c));
  if (!status.converged)
    out.push_back(fmt::format(
        "not converged in {} iterations: the cost is flat along some direction, parameters trading against each other "
        "(alpha against beta + gamma; a law's end against its rate). Hold one of them (--hold name=value), or add "
        "records that tell them apart",
        status.iterations));
  for (const auto& p : status.implausible) out.push_back(ImplausibleAdvice(p, status, c));
  if (!status.Ok())
    out.push_back("or take the model as it is: --accept-unconverged exits 0 (the file stays marked FIT FAILED)");
  return out;
}

}  // namespace rths::ident
