#include "ident/damper_options.h"

#include <cmath>

#include <fmt/format.h>

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
  return true;
}

}  // namespace rths::ident
