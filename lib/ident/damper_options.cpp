#include "ident/damper_options.h"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::ident {

bool DamperFitOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (current_A && (!(*current_A >= 0.0) || !std::isfinite(*current_A)))
    return fail(fmt::format("current_A = {} A: must be >= 0", *current_A));
  if (!(A > 0.0) || !std::isfinite(A)) return fail(fmt::format("A = {}: must be > 0", A));
  if (!(velocity_cutoff_hz >= 0.0) || !std::isfinite(velocity_cutoff_hz))
    return fail(fmt::format("velocity_cutoff_hz = {}: must be >= 0 (0: from the record's band)", velocity_cutoff_hz));
  if (start_iterations && *start_iterations < 1)
    return fail(fmt::format("start_iterations = {}: must be >= 1", *start_iterations));
  if (max_iterations && *max_iterations < 1) return fail(fmt::format("max_iterations = {}: must be >= 1", *max_iterations));
  if (!(current_tolerance_A >= 0.0))
    return fail(fmt::format("current_tolerance_A = {}: must be >= 0", current_tolerance_A));
  if (!(eta_start_1_s > 0.0) || !std::isfinite(eta_start_1_s))
    return fail(fmt::format("eta_start_1_s = {}: must be > 0", eta_start_1_s));
  if (threads < 0) return fail(fmt::format("threads = {}: must be >= 0", threads));
  for (const auto& [name, value] : hold)
    if (name.empty() || !(value > 0.0) || !std::isfinite(value))
      return fail(fmt::format("hold {} = {}: needs a parameter's name and a value > 0", name, value));
  return true;
}

std::pair<std::string, double> ParseHold(const std::string& text) {
  const auto eq = text.find('=');
  const std::string name = eq == std::string::npos ? "" : text.substr(0, eq);
  const std::string number = eq == std::string::npos ? "" : text.substr(eq + 1);
  char* end = nullptr;
  const double value = number.empty() ? 0.0 : std::strtod(number.c_str(), &end);
  if (name.empty() || number.empty() || *end != '\0' || !(value > 0.0) || !std::isfinite(value))
    throw Error("--hold", fmt::format("\"{}\": expected NAME=VALUE with a value > 0 in the model file's units, "
                                      "e.g. alpha_c=6 (docs/identification.md \"When a fit fails\")",
                                      text));
  return {name, value};
}

int HeldIndex(const std::pair<std::string, double>& hold, const std::vector<std::string>& names,
              const std::vector<double>& lo, const std::vector<double>& hi) {
  const auto& [name, value] = hold;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] != name) continue;
    if (!(value >= lo[i] && value <= hi[i]))
      throw Error("--hold", fmt::format("{} = {:g}: outside the fit's range for it, {:g} to {:g}", name, value, lo[i],
                                        hi[i]));
    return static_cast<int>(i);
  }
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw Error("--hold", fmt::format("\"{}\": not a parameter of this fit; it has {}", name, all));
}

}  // namespace rths::ident
