#include "control/design.h"

#include <cmath>
#include <complex>
#include <numbers>

#include <fmt/format.h>

namespace rths::control {

namespace {

constexpr double kFrequencies[] = {1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0};

nlohmann::json Complex(const Eigen::VectorXcd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back({v(i).real(), v(i).imag()});
  return a;
}

template <typename V>
std::vector<double> Std(const V& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

std::string Vec(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{:.6g}", i ? ", " : "", v[i]);
  return s + "]";
}

/// z-plane pole as text: value, modulus, equivalent s-plane frequency and damping (s = ln z / dt).
std::string Pole(std::complex<double> z, double dt) {
  const std::complex<double> s = std::log(z) / dt;
  const double wn = std::abs(s);
  return fmt::format("{:+.6f}{:+.6f}j  |z| = {:.6f}  f_n = {:8.2f} Hz  zeta = {:.3f}", z.real(), z.imag(),
                     std::abs(z), wn / (2.0 * std::numbers::pi), wn > 0 ? -s.real() / wn : 1.0);
}

std::string ModelText(const models::ServoModel3& m) {
  return fmt::format("{} (K = {:.6g}, p = {:.6g}, b = {:.6g}, c = {:.6g})", m.name, m.K, m.p, m.b, m.c);
}

nlohmann::json ModelJson(const models::ServoModel3& m) {
  return {{"name", m.name}, {"K", m.K}, {"p", m.p}, {"b", m.b}, {"c", m.c}};
}

nlohmann::json SosJson(const signal::Sos& sos) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& q : sos.sections) a.push_back({{"b", {q.b0, q.b1, q.b2}}, {"a", {1.0, q.a1, q.a2}}});
  return a;
}

std::string TfText(const DiscreteTf& h) {
  std::string b, a;
  for (std::size_t i = 0; i < h.b.size(); ++i) b += fmt::format("{}{:.15g}", i ? ", " : "", h.b[i]);
  for (std::size_t i = 0; i < h.a.size(); ++i) a += fmt::format("{}{:.15g}", i ? ", " : "", h.a[i]);
  return fmt::format("b = [{}], a = [{}]", b, a);
}

nlohmann::json LtiPartJson(const LtiPart& p) {
  nlohmann::json poles = nlohmann::json::array();
  for (const auto z : p.discrete.Poles()) poles.push_back({z.real(), z.imag()});
  nlohmann::json j = {{"given", p.given},
                      {"b", p.discrete.b},
                      {"a", p.discrete.a},
                      {"poles_z", poles},
                      {"integrators", p.stability.integrators},
                      {"unstable_poles", p.stability.unstable},
                      {"dc_gain", p.stability.integrators > 0 ? nlohmann::json(nullptr)
                                                              : nlohmann::json(p.discrete.Response(0.0).real())}};
  if (p.given) j["coefficients"] = {{"num", p.coefficients.num}, {"den", p.coefficients.den}};
  return j;
}

}  // namespace

DesignSummary DesignController(const control::ControllerConfig& cfg, double dt_s,
                               const std::vector<DesignPlant>& extra) {
  const auto controller = MakeTrackingController(cfg, dt_s);
  DesignSummary s;
  s.config = cfg;
  s.dt_s = dt_s;
  const TrackingController* c = controller.get();
  if (const auto* p = dynamic_cast<const ModelFeedforward*>(c)) s.feedforward = p->coefficients();
  if (const auto* p = dynamic_cast<const PolynomialExtrapolation*>(c)) s.poly3 = p->design();
  if (const auto* p = dynamic_cast<const LeadCompensator*>(c)) s.lead = p->design();
  if (const auto* p = dynamic_cast<const InverseLowpass*>(c)) s.lowpass = {p->design()};
  if (const auto* p = dynamic_cast<const BumplessInverseLowpass*>(c)) s.lowpass = {p->low(), p->high()};
  if (const auto* p = dynamic_cast<const FeedforwardLqg*>(c)) s.feedforward = p->feedforward(), s.lqg = p->design();
  if (const auto* p = dynamic_cast<const LtiController*>(c)) s.lti = p->design();

  struct Candidate {
    PlantCheck check;
    DiscreteSs g;
  };
  std::vector<Candidate> plants;
  auto servo = [&](const models::ServoModel3& m, double current) {
    plants.push_back({{m.name, m, current, {}, std::nullopt}, ServoZoh(m, dt_s)});
  };
  const bool uses_model = cfg.kind == control::ControllerKind::kFf || cfg.kind == control::ControllerKind::kFfLp ||
                          cfg.kind == control::ControllerKind::kFfLqg || cfg.kind == control::ControllerKind::kLti;
  if (uses_model && cfg.model.name == "custom") servo(cfg.model, 0.0);
  for (const DesignPlant& p : extra) plants.push_back({{p.name, std::nullopt, 0.0, {}, std::nullopt}, p.g});
  if (extra.empty()) {
    servo(models::ServoPreset("0.0A"), 0.0);
    servo(models::ServoPreset("avg"), 0.5 * cfg.current_high_A);
    servo(models::ServoPreset("2.5A"), cfg.current_high_A);
  }
  for (auto& [pc, g] : plants) {
    const ControllerLti lti = controller->Linearize(pc.current_A);
    for (double f : kFrequencies) {
      pc.tracking.push_back({f, std::abs(TrackingResponse(lti, g, f)), TrackingLagS(lti, g, f) * 1e3});
    }
    if (lti.has_feedback) pc.loop = AnalyzeLoop(lti.fb, g);
    s.plants.push_back(std::move(pc));
  }
  return s;
}

std::string DesignSummary::Report() const {
  std::string o = fmt::format("controller: {} (dt = {} s)\n", NameOf(kControllerKindNames, config.kind), dt_s);
  if (feedforward) {
    const auto& a = *feedforward;
    o += fmt::format("feedforward G_FF(s) = a0 + a1 s + a2 s^2 + a3 s^3 (Eq. 17) of {}{}:\n"
                     "  a0 = {:.7g}  a1 = {:.7g} s  a2 = {:.7g} s^2  a3 = {:.7g} s^3\n",
                     ModelText(config.model), config.half_step_ahead ? ", evaluated half a step ahead" : " (Eq. 19)",
                     a.a0, a.a1, a.a2, a.a3);
  }
  if (poly3) {
    o += fmt::format("3rd-order polynomial extrapolation, tau = {} ms (alpha = {}):\n"
                     "  u_k = {:.6g} r_k {:+.6g} r_k-1 {:+.6g} r_k-2 {:+.6g} r_k-3   (sum {:.12g}; gain at Nyquist {:.1f})\n",
                     poly3->delay_s * 1e3, poly3->alpha, poly3->c[0], poly3->c[1], poly3->c[2], poly3->c[3],
                     poly3->c[0] + poly3->c[1] + poly3->c[2] + poly3->c[3], poly3->nyquist_gain);
  }
  if (lead) {
    o += fmt::format("lead compensator (T_z s + 1)/(T_p s + 1), T_z = {} ms, T_p = {} ms, Tustin:\n"
                     "  u_k = {:.6g} r_k {:+.6g} r_k-1 {:+.6g} u_k-1   (b0, b1, -a1)\n",
                     lead->tz_s * 1e3, lead->tp_s * 1e3, lead->b0, lead->b1, -lead->a1);
  }
  for (std::size_t i = 0; i < lowpass.size(); ++i) {
    const auto& d = lowpass[i];
    o += fmt::format("{}LP(s) G^-1(s) of {}, Butterworth order {} at {} Hz (DC group delay {:.4f} ms), plain "
                     "Tustin, sections b0 b1 b2 / 1 a1 a2:\n",
                     lowpass.size() == 2 ? (i == 0 ? "low (0 A): " : "high (current_high_A): ") : "", ModelText(d.model),
                     d.order, d.cutoff_hz, d.dc_group_delay_s * 1e3);
    for (const auto& q : d.sos.sections) {
      o += fmt::format("  [{:.9g}, {:.9g}, {:.9g}] / [1, {:.9g}, {:.9g}]\n", q.b0, q.b1, q.b2, q.a1, q.a2);
    }
  }
  if (lowpass.size() == 2) {
    o += fmt::format("  u = (1 - lambda) u_low + lambda u_high, lambda = clamp(i_eff / {} A, 0, 1)\n",
                     config.current_high_A);
  }
  if (lqg) {
    const auto& d = *lqg;
    const auto& w = d.weights;
    o += fmt::format("LQG on the deviation system of {} (Eqs. 23-27): q = {}, w_f = 2 pi {} rad/s, xi_f = {}, "
                     "eta_f = {}, W = {}, V = {}\n",
                     ModelText(d.model), w.q, w.w_f_hz, w.xi_f, w.eta_f, w.W, w.V);
    o += fmt::format("  K_c = {}\n  L   = {}\n", Vec(Std(d.Kc)), Vec(Std(d.L)));
    o += fmt::format("  Riccati residuals: LQR {:.2g} ({} doubling steps), Kalman {:.2g} ({} steps)\n", d.lqr_residual,
                     d.lqr_iterations, d.kalman_residual, d.kalman_iterations);
    o += "  regulator poles eig(Phi - Gamma K_c):\n";
    for (Eigen::Index i = 0; i < d.regulator_poles.size(); ++i) o += "    " + Pole(d.regulator_poles(i), dt_s) + "\n";
    o += "  estimator poles eig(Phi - Phi L C):\n";
    for (Eigen::Index i = 0; i < d.estimator_poles.size(); ++i) o += "    " + Pole(d.estimator_poles(i), dt_s) + "\n";
  }
  if (lti) {
    const LtiDesign& d = *lti;
    o += fmt::format("u = C(z) (T(z) r - y), domain {}{}, coefficients in powers of z^-1 (b: numerator, a: "
                     "denominator, a0 = 1):\n",
                     NameOf(kTfDomainNames, d.config.domain),
                     d.config.domain == TfDomain::kS
                         ? fmt::format(", {} at dt = {} s", NameOf(kDiscretisationNames, d.config.discretisation), dt_s)
                         : "");
    for (const auto& [label, part] : {std::pair{"C (feedback)", &d.feedback}, {"T (reference)", &d.reference}}) {
      if (!part->given) {
        o += fmt::format("  {}: 1 (not given)\n", label);
        continue;
      }
      o += fmt::format("  {}: {}\n", label, TfText(part->discrete));
      o += fmt::format("    {} pole(s), {} integrator(s), {} unstable{}\n", part->discrete.order(),
                       part->stability.integrators, part->stability.unstable,
                       part->stability.integrators > 0
                           ? ""
                           : fmt::format(", DC gain {:.6g}", part->discrete.Response(0.0).real()));
      for (const auto z : part->discrete.Poles()) o += "    " + Pole(z, dt_s) + "\n";
    }
    if (d.config.saturation_mm > 0) o += fmt::format("  output saturation |u| <= {} mm\n", d.config.saturation_mm);
    if (d.config.rate_limit_mm_s > 0) o += fmt::format("  rate limit |du/dt| <= {} mm/s\n", d.config.rate_limit_mm_s);
  }
  for (const PlantCheck& p : plants) {
    o += fmt::format("on the ZOH plant {}{}:\n", p.model ? ModelText(*p.model) : p.name,
                     config.kind == control::ControllerKind::kBumplessLp ? fmt::format(" at {} A", p.current_A) : "");
    o += "  f [Hz]    |G_yr|   lag [ms]\n";
    for (const auto& t : p.tracking) o += fmt::format("  {:6.1f}  {:8.4f}  {:8.4f}\n", t.f_hz, t.magnitude, t.lag_ms);
    if (p.loop) {
      const LoopAnalysis& l = *p.loop;
      o += fmt::format("  feedback loop: {} (spectral radius {:.6f}); peak sensitivity {:.3f} dB at {:.1f} Hz\n",
                       l.stable ? "stable" : "UNSTABLE", l.spectral_radius, l.peak_sensitivity_db, l.peak_sensitivity_hz);
      for (const Crossover& x : l.crossovers) {
        o += fmt::format("  crossover {:.3f} Hz: phase margin {:.2f} deg, delay margin {:.3f} ms\n", x.f_hz,
                         x.phase_margin_deg, x.delay_margin_s * 1e3);
      }
      o += "  closed-loop poles (plant + controller):\n";
      for (Eigen::Index i = 0; i < l.closed_loop_poles.size(); ++i) o += "    " + Pole(l.closed_loop_poles(i), dt_s) + "\n";
    }
  }
  return o;
}

nlohmann::json DesignSummary::ToJson() const {
  nlohmann::json j;
  j["kind"] = NameOf(kControllerKindNames, config.kind);
  j["dt_s"] = dt_s;
  if (feedforward) {
    j["feedforward"] = {{"model", ModelJson(config.model)},
                        {"half_step_ahead", config.half_step_ahead},
                        {"a", {feedforward->a0, feedforward->a1, feedforward->a2, feedforward->a3}}};
  }
  if (poly3) {
    j["poly3"] = {{"delay_ms", poly3->delay_s * 1e3}, {"alpha", poly3->alpha},
                  {"c", {poly3->c[0], poly3->c[1], poly3->c[2], poly3->c[3]}}, {"nyquist_gain", poly3->nyquist_gain}};
  }
  if (lead) {
    j["lead"] = {{"delay_ms", lead->delay_s * 1e3}, {"tp_ms", lead->tp_s * 1e3}, {"tz_ms", lead->tz_s * 1e3},
                 {"b0", lead->b0}, {"b1", lead->b1}, {"a1", lead->a1}};
  }
  for (const auto& d : lowpass) {
    j["lowpass"].push_back({{"model", ModelJson(d.model)}, {"order", d.order}, {"cutoff_hz", d.cutoff_hz},
                            {"dc_group_delay_ms", d.dc_group_delay_s * 1e3}, {"discretisation", "tustin (no prewarp)"},
                            {"sos", SosJson(d.sos)}});
  }
  if (lowpass.size() == 2) j["current_high_A"] = config.current_high_A;
  if (lqg) {
    const auto& d = *lqg;
    j["lqg"] = {{"model", ModelJson(d.model)},
                {"weights", {{"q", d.weights.q}, {"w_f_hz", d.weights.w_f_hz}, {"xi_f", d.weights.xi_f},
                             {"eta_f", d.weights.eta_f}, {"W", d.weights.W}, {"V", d.weights.V}}},
                {"Kc", Std(d.Kc)},
                {"L", Std(d.L)},
                {"lqr_residual", d.lqr_residual},
                {"kalman_residual", d.kalman_residual},
                {"regulator_poles", Complex(d.regulator_poles)},
                {"estimator_poles", Complex(d.estimator_poles)}};
  }
  if (lti) {
    j["lti"] = {{"domain", NameOf(kTfDomainNames, lti->config.domain)},
                {"discretisation", NameOf(kDiscretisationNames, lti->config.discretisation)},
                {"feedback", LtiPartJson(lti->feedback)},
                {"reference", LtiPartJson(lti->reference)},
                {"saturation_mm", lti->config.saturation_mm},
                {"rate_limit_mm_s", lti->config.rate_limit_mm_s}};
  }
  for (const PlantCheck& p : plants) {
    nlohmann::json pj = {{"name", p.name}, {"current_A", p.current_A}};
    if (p.model) pj["model"] = ModelJson(*p.model);
    for (const auto& t : p.tracking) {
      pj["tracking"].push_back({{"f_hz", t.f_hz}, {"magnitude", t.magnitude}, {"lag_ms", t.lag_ms}});
    }
    if (p.loop) {
      const LoopAnalysis& l = *p.loop;
      nlohmann::json lj = {{"stable", l.stable},
                           {"spectral_radius", l.spectral_radius},
                           {"peak_sensitivity_db", l.peak_sensitivity_db},
                           {"peak_sensitivity_hz", l.peak_sensitivity_hz},
                           {"closed_loop_poles", Complex(l.closed_loop_poles)},
                           {"crossovers", nlohmann::json::array()}};
      for (const Crossover& x : l.crossovers) {
        lj["crossovers"].push_back({{"f_hz", x.f_hz}, {"phase_margin_deg", x.phase_margin_deg},
                                    {"delay_margin_ms", x.delay_margin_s * 1e3}});
      }
      pj["loop"] = lj;
    }
    j["plants"].push_back(pj);
  }
  return j;
}

}  // namespace rths::control
