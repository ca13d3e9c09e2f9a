// SpencerFitResult::Report and SpencerModelToml of ident/spencer_fit.h: the fit's text and its
// model file.
#include <fmt/format.h>

#include "ident/spencer_fit.h"

namespace rths::ident {

std::string SpencerFitResult::Report() const {
  const char* unit = voltage ? "V" : "A";
  const auto& p = params;
  std::string o = fmt::format("Spencer MR damper model, current-dependent (Eqs. 32-39, n = 2, A held at {}), input in {}:\n",
                              p.A, voltage ? "volts" : "amperes");
  if (filter == ControlFilter::kFirstOrder)
    o += fmt::format("  control filter u' = -eta (u - v): eta = {:.5g} 1/s (time constant {:.4g} ms)\n", driver.eta_1_s,
                     1000.0 / driver.eta_1_s);
  else
    o += fmt::format("  control filter: {}\n", filter == ControlFilter::kEq40 ? "Eq. 40 + 75 Hz low-pass (fixed)"
                                                                              : "none (the command is the input)");
  o += fmt::format("  p(u) = p_b + (p_a - p_b) exp(-p_c u):        p_a            p_b            p_c [1/{}]\n", unit);
  const std::pair<const char*, const double*> laws[] = {{"alpha [kN/mm]", &p.alpha_a}, {"c0 [kN s/mm]", &p.c0_a},
                                                        {"c1 [kN s/mm]", &p.c1_a},     {"beta [1/mm^2]", &p.beta_a},
                                                        {"gamma [1/mm^2]", &p.gamma_a}};
  for (const auto& [name, v] : laws)
    o += fmt::format("    {:<40} {:<14.6g} {:<14.6g} {:.6g}\n", name, v[0], v[1], v[2]);
  o += fmt::format("  k0 = {:.6g} kN/mm   k1 = {:.6g} kN/mm   x0 = {:.6g} mm\n", p.k0, p.k1, p.x0);
  if (force_offset_kN != 0.0)
    o += fmt::format("  force offset (the load cell's zero; k1 = 0) = {:.6g} kN\n", force_offset_kN);
  for (double in : {input_min, input_max}) {
    const auto c = models::CoefficientsAt(p, in);
    o += fmt::format("  at {:.4g} {}: alpha {:.4g}, c0 {:.4g}, c1 {:.4g}, beta {:.4g}, gamma {:.4g}\n", in, unit, c.alpha,
                     c.c0, c.c1, c.beta, c.gamma);
  }
  o += fmt::format("  Levenberg-Marquardt: start {} of {} won, {} iterations, {}; cost J = {:.6g}; {:.1f} s\n",
                   best_start + 1, start_costs.size(), iterations, converged ? "converged" : "not converged (iteration limit)",
                   cost, seconds);
  o += status.Details("  ");
  o += "  force error per record (Eq. 31 on f):\n";
  for (const auto& r : records)
    o += fmt::format("    {:<40} {:7d} samples at {:g} s, velocity cut-off {:.0f} Hz, peak {:.4g} kN: {:.3f} %\n",
                     r.source, r.samples, r.dt_s, r.velocity_cutoff_hz, r.peak_force_kN, r.nrmse_f_pct);
  return o;
}

std::string SpencerModelToml(const SpencerFitResult& fit, const std::string& title) {
  const auto& p = fit.params;
  std::string o = fmt::format("# {}\n", title);
  o += fmt::format("# Spencer MR damper (Eqs. 32-39, n = 2) fitted on inputs {:g} to {:g} {}{}.\n", fit.input_min,
                   fit.input_max, fit.voltage ? "V" : "A",
                   fit.voltage ? " (a VOLTAGE: the rates p_c are per V, and the damper command of a run is in V)" : "");
  o += "# Force error (Eq. 31 on f) per training record:\n";
  for (const auto& r : fit.records) o += fmt::format("#   {}: {:.3f} %\n", r.source, r.nrmse_f_pct);
  for (const auto& w : fit.warnings) o += "# warning: " + w + "\n";
  o += ForceOffsetComment(fit.force_offset_kN);
  o += fit.status.Comment();
  o += fmt::format("\n[plant]\ncurrent_dynamics = {}\n", fit.filter == ControlFilter::kNone ? "false" : "true");
  o += "\n" + DamperTable(p);
  if (fit.filter != ControlFilter::kNone) {
    o += "\n[plant.current_driver]\n";
    if (fit.filter == ControlFilter::kFirstOrder)
      o += fmt::format("kind = \"first_order\"\neta_1_s = {}\n", TomlFloat(fit.driver.eta_1_s));
    else
      o += "kind = \"eq40\"\n";
  }
  o += "\n" + fit.status.TomlTable() + ForceOffsetKey(fit.force_offset_kN);
  return o;
}

}  // namespace rths::ident
