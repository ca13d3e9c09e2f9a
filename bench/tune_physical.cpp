// bench-tune_physical: tunes the physics-based actuator (docs/models.md section 5,
// lib/models/servo_physical.h) so that E1 run on the rig loaded by the nonlinear MR damper
// (Table 3) identifies as Eqs. 28 (0.0 A) and 29 (2.5 A).
//
//   build/bin/bench-tune_physical [--seconds S] [--cvode] [--iters N] [--free LIST] [--PARAM V ...]
//
// One evaluation is E1 exactly as `rths reproduce fig6` does it (lib/studies/fig6.cpp), minus
// the lockstep transport, which does not change the numbers (u_k = r_k with no controller; the
// plant holds u_k over [t_k, t_{k+1}) and y_k is read at t_k):
//   - u = BLWN 0-50 Hz, RMS 0.254 mm, seed 1, discard 2 s, faded in over 0.5 s (MakeSignal of
//     the scenario's desired-displacement spec), S seconds at dt = 0.5 ms;
//   - the PhysicalRig with the MR damper at a constant current (driver at steady state), current
//     dynamics on, integrated by ARKODE (--cvode, the plant's integrator; the flag's name is historical) or by fixed-step RK4 at
//     dt/4 (default here: about 80x faster; docs/plant.md: they agree to 1e-7 mm);
//   - ident::Identify with the fig6 options (3 poles, 0.5-40 Hz, ZOH-consistent at dt).
// The 8 relative errors e_j = fitted / Eq. - 1 of K, p, b, c at 0.0 A (Eq. 28) and 2.5 A (Eq. 29)
// are minimised by Nelder-Mead in the logarithms of the free parameters, with the cost
//     J = ( sum_j |e_j|^6 / 8 )^(1/6)
// (a smooth stand-in for max_j |e_j|, which is what E1's 8 % bounds).
// --free takes a comma-separated subset of: hz, zeta, gain (K_p K_q / A via K_p), beta, leak,
// volume, mass, cp, and dp, dphz (an experiment not in the library: a high-passed load-pressure
// feedback in the inner loop, see SimulateDp). A free parameter keeps the sign of its start value.
// --iters 0 only evaluates the given point (and prints the damper's equivalent spring-dashpot on
// the record); --objective frf minimises the RMS complex error of H1 against the Eqs. instead;
// --sample N evaluates N random points of a plausible box. Results: docs/plant.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "ident/identify.h"
#include "models/servo_physical.h"
#include "studies/frequency.h"
#include "scenario/scenario.h"
#include "signal/history.h"

using namespace rths;

namespace {

constexpr double kDt = 0.0005;
bool frf_objective = false;  // --objective frf: minimise the RMS complex error of H1 instead

struct Eval {
  double err[2][4]{};  // [current][K, p, b, c]
  double fit_mag_pct[2]{}, fit_phase_deg[2]{};
  double frf_mag_pct[2]{}, frf_phase_deg[2]{};  // measured H1 vs the Eq.'s ZOH response
  double frf_rms[2]{};  // RMS complex relative error of H1 against the Eq.'s ZOH response, 0.5-40 Hz
  models::ServoModel3 fit[2];
  double cost = 0, max_abs = 0;
};

std::vector<double> Command(double seconds) {
  return signal::MakeSignal(studies::FrequencyExcitation(), kDt, static_cast<std::size_t>(std::lround(seconds / kDt)));
}

// Experimental, not in the library: a high-passed load-pressure ("delta-P") feedback in the
// inner loop, i_v = sat(+/-1, K_p (u - x) - g_dp (p_L - q) / P_s), q' = w_hp (p_L - q).
double g_dp = 0.0, dp_hp_hz = 1.0;

// The rig of PhysicalRigStepper with RK4 at dt/4 and the extra state q (constant current).
std::vector<double> SimulateDp(const models::PhysicalRig& rig, double current_A, const std::vector<double>& u) {
  const auto coef = models::CoefficientsAt(rig.damper, current_A);
  const auto& a = rig.actuator;
  const double whp = 2 * M_PI * dp_hp_hz;
  auto rhs = [&](const double* w, double um, double* d) {
    const models::ActuatorState s{w[0], w[1], w[2], w[3], w[4]};
    const models::MrDamperState ds{w[5], w[6]};
    const double load = 1e3 * models::DamperForceKn(coef, ds, 1e3 * s.x_m, 1e3 * s.v_m_s);
    const auto r = models::DamperRates(coef, ds, 1e3 * s.x_m, 1e3 * s.v_m_s);
    // Shift the command so that K_p (u' - x) = K_p (u - x) - g_dp p_hp / P_s.
    const double ushift = -g_dp * (s.pL_Pa - w[7]) / a.supply_pressure_Pa / a.kp_per_m;
    const auto da = models::ActuatorRates(a, s, um + ushift, load);
    d[0] = da.x_m, d[1] = da.v_m_s, d[2] = da.pL_Pa, d[3] = da.xv, d[4] = da.xv_rate_per_s;
    d[5] = r.ydot_mm_s, d[6] = r.zdot_mm_s, d[7] = whp * (s.pL_Pa - w[7]);
  };
  double w[8] = {0, 0, 0, 0, 0, 0, 0, 0}, k1[8], k2[8], k3[8], k4[8], t[8];
  std::vector<double> y(u.size());
  const double h = kDt / 4;
  for (std::size_t k = 0; k < u.size(); ++k) {
    y[k] = 1e3 * w[0];
    const double um = 1e-3 * u[k];
    for (int j = 0; j < 4; ++j) {
      rhs(w, um, k1);
      for (int i = 0; i < 8; ++i) t[i] = w[i] + 0.5 * h * k1[i];
      rhs(t, um, k2);
      for (int i = 0; i < 8; ++i) t[i] = w[i] + 0.5 * h * k2[i];
      rhs(t, um, k3);
      for (int i = 0; i < 8; ++i) t[i] = w[i] + h * k3[i];
      rhs(t, um, k4);
      for (int i = 0; i < 8; ++i) w[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
    if (!std::isfinite(w[0])) throw std::runtime_error("diverged");
  }
  return y;
}

// E1 at one current: identify the damper-loaded rig.
ident::IdentifyResult RunE1(const models::PhysicalActuatorConfig& cfg, double current_A,
                            const std::vector<double>& u, bool cvode) {
  ident::IdentifyOptions io;
  io.fit.poles = 3;
  io.fit.band_lo_hz = 0.5;
  io.fit.band_hi_hz = 40.0;
  io.fit.zoh_dt_s = kDt;
  if (g_dp != 0.0) {
    const auto rig = models::PhysicalRig::Make(cfg, kDt, models::RigLoad::kMrDamper, false);
    return ident::Identify(u, SimulateDp(rig, current_A, u), kDt, io);
  }
  models::PhysicalRig rig = models::PhysicalRig::Make(cfg, kDt, models::RigLoad::kMrDamper, true);
  if (!cvode) {
    rig.integrator = models::RigIntegrator::kRk4;
    rig.rk4_substeps = 4;
  }
  models::PhysicalRigStepper stepper(rig);
  models::PhysicalRigState s;
  s.current = models::SteadyState(current_A);
  std::vector<double> y(u.size());
  for (std::size_t k = 0; k < u.size(); ++k) {
    y[k] = models::MeasuredDisplacementMm(rig, s);
    stepper.Step(&s, u[k], current_A);
    if (!std::isfinite(s.actuator.x_m)) throw std::runtime_error("diverged");
  }
  return ident::Identify(u, y, kDt, io);
}

// The damper's equivalent spring-dashpot on the E1 record of the loaded rig (ARKODE): least squares
// F = k x + c x' over the record after the fade-in, and the residual's RMS relative to F's.
void PrintEquivalent(const models::PhysicalActuatorConfig& cfg, const std::vector<double>& u) {
  for (double current_A : {0.0, 2.5}) {
    const auto rig = models::PhysicalRig::Make(cfg, kDt, models::RigLoad::kMrDamper, true);
    models::PhysicalRigStepper stepper(rig);
    models::PhysicalRigState s;
    s.current = models::SteadyState(current_A);
    double sxx = 0, sxv = 0, svv = 0, sfx = 0, sfv = 0, sff = 0;
    std::vector<double> x, v, f;
    for (std::size_t k = 0; k < u.size(); ++k) {
      if (k * kDt >= 1.0) {
        x.push_back(s.actuator.x_m), v.push_back(s.actuator.v_m_s);
        f.push_back(1e3 * models::MeasuredForceKn(rig, s));
      }
      stepper.Step(&s, u[k], current_A);
    }
    for (std::size_t k = 0; k < x.size(); ++k) {
      sxx += x[k] * x[k], sxv += x[k] * v[k], svv += v[k] * v[k];
      sfx += f[k] * x[k], sfv += f[k] * v[k], sff += f[k] * f[k];
    }
    const double det = sxx * svv - sxv * sxv;
    const double k_e = (sfx * svv - sfv * sxv) / det, c_e = (sfv * sxx - sfx * sxv) / det;
    double res = 0;
    for (std::size_t i = 0; i < x.size(); ++i) res += std::pow(f[i] - k_e * x[i] - c_e * v[i], 2);
    std::printf("damper at %.1f A on the E1 record: k_e %.3g N/m, c_e %.3g N s/m, residual %.1f %% RMS, "
                "force %.2f kN RMS, x %.3f mm RMS\n",
                current_A, k_e, c_e, 100 * std::sqrt(res / sff), 1e-3 * std::sqrt(sff / f.size()),
                1e3 * std::sqrt(sxx / x.size()));
  }
}

Eval Evaluate(const models::PhysicalActuatorConfig& cfg, const std::vector<double>& u, bool cvode) {
  Eval e;
  const double currents[2] = {0.0, 2.5};
  const char* names[2] = {"0.0A", "2.5A"};
  std::future<ident::IdentifyResult> f0 =
      std::async(std::launch::async, [&] { return RunE1(cfg, currents[0], u, cvode); });
  const ident::IdentifyResult r1 = RunE1(cfg, currents[1], u, cvode);
  const ident::IdentifyResult r0 = f0.get();
  const ident::IdentifyResult* rs[2] = {&r0, &r1};
  double sum = 0;
  for (int j = 0; j < 2; ++j) {
    const auto ref = models::ServoPreset(names[j]);
    const auto fit = rs[j]->fit.model.ToServoModel3();
    e.fit[j] = fit;
    const double got[4] = {fit.K, fit.p, fit.b, fit.c}, want[4] = {ref.K, ref.p, ref.b, ref.c};
    for (int i = 0; i < 4; ++i) {
      e.err[j][i] = got[i] / want[i] - 1.0;
      sum += std::pow(std::abs(e.err[j][i]), 6);
      e.max_abs = std::max(e.max_abs, std::abs(e.err[j][i]));
    }
    e.fit_mag_pct[j] = rs[j]->fit.max_mag_error_pct;
    e.fit_phase_deg[j] = rs[j]->fit.max_phase_error_deg;
    const auto zoh = ident::Discretise(ident::PoleModel::FromServoModel3(ref), kDt);
    const auto& frf = rs[j]->frf;
    int points = 0;
    for (std::size_t i = 0; i < frf.f_hz.size(); ++i) {
      if (frf.f_hz[i] < 0.5 || frf.f_hz[i] > 40.0) continue;
      const auto q = frf.h[i] / ident::ZohResponse(zoh, frf.f_hz[i]);
      e.frf_mag_pct[j] = std::max(e.frf_mag_pct[j], 100 * std::abs(std::abs(q) - 1.0));
      e.frf_phase_deg[j] = std::max(e.frf_phase_deg[j], std::abs(std::arg(q)) * 180 / M_PI);
      e.frf_rms[j] += std::norm(q - 1.0);
      ++points;
    }
    e.frf_rms[j] = std::sqrt(e.frf_rms[j] / points);
  }
  e.cost = frf_objective ? std::hypot(e.frf_rms[0], e.frf_rms[1]) / std::sqrt(2.0)
                         : std::pow(sum / 8.0, 1.0 / 6.0);
  return e;
}

struct Param {
  std::string name;
  double value;
  bool free = false;
};

void Apply(const std::vector<Param>& ps, models::PhysicalActuatorConfig* c) {
  for (const auto& p : ps) {
    if (p.name == "hz") c->valve_hz = p.value;
    if (p.name == "zeta") c->valve_zeta = p.value;
    if (p.name == "gain") c->kp_per_m = p.value * c->area_m2 / c->kq_m3_s;
    if (p.name == "beta") c->beta_Pa = p.value;
    if (p.name == "leak") c->leakage_m3_s_Pa = p.value;
    if (p.name == "volume") c->volume_m3 = p.value;
    if (p.name == "mass") c->piston_mass_kg = p.value;
    if (p.name == "cp") c->piston_damping_N_s_m = p.value;
    if (p.name == "dp") g_dp = p.value;
    if (p.name == "dphz") dp_hp_hz = p.value;
  }
}

std::string Line(const std::vector<Param>& ps, const Eval& e) {
  std::string s;
  for (const auto& p : ps) s += fmt::format("{}={:.5g} ", p.name, p.value);
  s += fmt::format("| J {:.4f} max {:.2f} % | b, c 2.5A/0.0A {:.3f} {:.3f} (Eqs. 1.441 1.275) |", e.cost,
                   100 * e.max_abs, e.fit[1].b / e.fit[0].b, e.fit[1].c / e.fit[0].c);
  for (int j = 0; j < 2; ++j) {
    s += fmt::format(" {}: K {:+.1f} p {:+.1f} b {:+.1f} c {:+.1f} (frf rms {:.1f} %, {:.1f} %, {:.1f} deg)",
                     j ? "2.5A" : "0.0A", 100 * e.err[j][0], 100 * e.err[j][1], 100 * e.err[j][2],
                     100 * e.err[j][3], 100 * e.frf_rms[j], e.frf_mag_pct[j], e.frf_phase_deg[j]);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tune the physical actuator so that E1 on the damper-loaded rig gives Eqs. 28-29"};
  double seconds = 20.0;
  bool cvode = false;
  int iters = 150;
  std::string free_list = "hz,zeta,gain,beta,leak";
  const models::PhysicalActuatorConfig d;
  std::vector<Param> ps{{"hz", d.valve_hz},
                        {"zeta", d.valve_zeta},
                        {"gain", d.kp_per_m * d.kq_m3_s / d.area_m2},
                        {"beta", d.beta_Pa},
                        {"leak", d.leakage_m3_s_Pa},
                        {"volume", d.volume_m3},
                        {"mass", d.piston_mass_kg},
                        {"cp", d.piston_damping_N_s_m},
                        {"dp", 0.0},
                        {"dphz", 1.0}};
  app.add_option("--seconds", seconds, "record length [s]");
  app.add_flag("--cvode", cvode, "integrate with ARKODE (the plant's integrator; the flag's name is historical) instead of RK4 at dt/4");
  app.add_option("--iters", iters, "Nelder-Mead iterations (0: evaluate only)");
  app.add_option("--free", free_list, "free parameters, comma-separated");
  std::string objective = "coef";
  app.add_option("--objective", objective, "coef: the 6-norm of the 8 coefficient errors; frf: RMS complex error of H1")
      ->check(CLI::IsMember({"coef", "frf"}));
  for (auto& p : ps) app.add_option("--" + p.name, p.value, "start value of " + p.name);
  int samples = 0;
  app.add_option("--sample", samples,
                 "evaluate N random points (log-uniform: hz 40-120, zeta 0.3-1, gain 80-200 1/s, beta "
                 "0.7-1.8 GPa, leak 1e-13-1e-10) and print the range of b, c 2.5A/0.0A");
  CLI11_PARSE(app, argc, argv);
  {
    std::stringstream ss(free_list);
    std::string item;
    while (std::getline(ss, item, ',')) {
      bool found = false;
      for (auto& p : ps) found = found || (p.name == item && (p.free = true));
      if (!found) {
        std::fprintf(stderr, "unknown parameter '%s'\n", item.c_str());
        return 2;
      }
    }
  }
  frf_objective = objective == "frf";
  const std::vector<double> u = Command(seconds);
  if (samples > 0) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    auto logu = [&](double lo, double hi) { return lo * std::pow(hi / lo, uni(rng)); };
    double rb_lo = 1e9, rb_hi = 0, rc_lo = 1e9, rc_hi = 0, best = 1e9;
    for (int i = 0; i < samples; ++i) {
      std::vector<Param> q = ps;
      for (auto& p : q) {
        if (p.name == "hz") p.value = logu(40, 120);
        if (p.name == "zeta") p.value = logu(0.3, 1.0);
        if (p.name == "gain") p.value = logu(80, 200);
        if (p.name == "beta") p.value = logu(0.7e9, 1.8e9);
        if (p.name == "leak") p.value = logu(1e-13, 1e-10);
      }
      models::PhysicalActuatorConfig c;
      Apply(q, &c);
      try {
        const Eval e = Evaluate(c, u, cvode);
        const double rb = e.fit[1].b / e.fit[0].b, rc = e.fit[1].c / e.fit[0].c;
        rb_lo = std::min(rb_lo, rb), rb_hi = std::max(rb_hi, rb);
        rc_lo = std::min(rc_lo, rc), rc_hi = std::max(rc_hi, rc);
        best = std::min(best, e.max_abs);
        std::printf("%s\n", Line(q, e).c_str());
      } catch (const std::exception& ex) {
        std::printf("failed: %s\n", ex.what());
      }
    }
    std::printf("%d samples: b 2.5A/0.0A in [%.3f, %.3f], c in [%.3f, %.3f] (Eqs. 29/28: 1.441, 1.275); "
                "smallest max coefficient error %.1f %%\n",
                samples, rb_lo, rb_hi, rc_lo, rc_hi, 100 * best);
    return 0;
  }
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(ps.size()); ++i)
    if (ps[i].free && ps[i].value != 0) idx.push_back(i);
  const int n = static_cast<int>(idx.size());

  int evals = 0;
  auto at = [&](const std::vector<double>& x) {
    std::vector<Param> q = ps;
    for (int i = 0; i < n; ++i) q[idx[i]].value = ps[idx[i]].value * std::exp(x[i]);
    return q;
  };
  auto cost = [&](const std::vector<double>& x, bool print) {
    const auto q = at(x);
    models::PhysicalActuatorConfig c;
    Apply(q, &c);
    Eval e;
    try {
      e = Evaluate(c, u, cvode);
    } catch (const std::exception& ex) {
      if (print) std::printf("#%d failed: %s\n", evals, ex.what());
      ++evals;
      return 1e9;
    }
    ++evals;
    if (print) std::printf("#%d %s\n", evals, Line(q, e).c_str()), std::fflush(stdout);
    return e.cost;
  };

  std::vector<std::vector<double>> simplex(n + 1, std::vector<double>(n, 0.0));
  std::vector<double> f(n + 1);
  f[0] = cost(simplex[0], true);
  if (iters <= 0 || n == 0) {
    models::PhysicalActuatorConfig c;
    Apply(at(simplex[0]), &c);
    if (g_dp == 0.0) PrintEquivalent(c, u);
    return 0;
  }
  for (int i = 0; i < n; ++i) {
    simplex[i + 1][i] = 0.15;
    f[i + 1] = cost(simplex[i + 1], true);
  }
  for (int it = 0; it < iters; ++it) {
    std::vector<int> o(n + 1);
    for (int i = 0; i <= n; ++i) o[i] = i;
    std::sort(o.begin(), o.end(), [&](int a, int b) { return f[a] < f[b]; });
    auto S = simplex;
    auto F = f;
    for (int i = 0; i <= n; ++i) simplex[i] = S[o[i]], f[i] = F[o[i]];
    if (f[n] - f[0] < 1e-5) break;
    std::vector<double> c(n, 0.0);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) c[j] += simplex[i][j] / n;
    auto along = [&](double t) {
      std::vector<double> x(n);
      for (int j = 0; j < n; ++j) x[j] = c[j] + t * (simplex[n][j] - c[j]);
      return x;
    };
    const auto xr = along(-1.0);
    const double fr = cost(xr, true);
    if (fr < f[0]) {
      const auto xe = along(-2.0);
      const double fe = cost(xe, true);
      if (fe < fr) simplex[n] = xe, f[n] = fe;
      else simplex[n] = xr, f[n] = fr;
    } else if (fr < f[n - 1]) {
      simplex[n] = xr, f[n] = fr;
    } else {
      const auto xc = fr < f[n] ? along(-0.5) : along(0.5);
      const double fc = cost(xc, true);
      if (fc < std::min(fr, f[n])) {
        simplex[n] = xc, f[n] = fc;
      } else {
        for (int i = 1; i <= n; ++i) {
          for (int j = 0; j < n; ++j) simplex[i][j] = simplex[0][j] + 0.5 * (simplex[i][j] - simplex[0][j]);
          f[i] = cost(simplex[i], true);
        }
      }
    }
  }
  int best = 0;
  for (int i = 1; i <= n; ++i)
    if (f[i] < f[best]) best = i;
  std::printf("best after %d evaluations:\n", evals);
  cost(simplex[best], true);
  return 0;
}
