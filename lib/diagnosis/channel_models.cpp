#include "diagnosis/channel_models.h"
#include "diagnosis/ripple_fit.h"

#include <algorithm>
#include <optional>
#include <cmath>
#include <complex>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/error.h"
#include "scenario/from_toml.h"
#include "models/servo_flow_limit.h"
#include "signal/derivative.h"
#include "signal/zero_phase.h"

namespace rths::diagnosis {

NominalModel PaperModel() { return NominalModel{}; }

NominalModel LoadModel(const std::string& path) {
  toml::table tbl;
  try {
    tbl = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw Error(fmt::format("{}:{}", path, b.line), fmt::format("not a TOML file: {}", e.description()));
  }
  const auto* plant = tbl["plant"].as_table();
  const bool actuator_only = !tbl.contains("run") && !tbl.contains("structure") &&
                             (plant == nullptr || (!plant->contains("specimen") && !plant->contains("damper")));
  const scenario::Scenario s = scenario::ScenarioFromToml(tbl, path);  // the table parsed above: once
  NominalModel m;
  m.actuator = s.plant.actuator;
  m.damper = s.plant.damper;
  m.current_dynamics = s.plant.current_dynamics;
  m.current_driver = s.plant.current_driver;
  m.has_damper = !actuator_only && s.plant.specimen == models::Specimen::kMrDamper;
  m.source = fmt::format("{}: [plant] actuator K={:.6g} p={:.6g} b={:.6g} c={:.6g}", path, m.actuator.K,
                         m.actuator.p, m.actuator.b, m.actuator.c);
  if (actuator_only) {
    m.notes.push_back(fmt::format("{}: an actuator model only (no [run], [structure], plant.specimen or "
                                  "plant.damper): the force channel is not diagnosed",
                                  path));
  } else if (!m.has_damper) {
    m.notes.push_back(fmt::format("{}: plant.specimen = \"{}\": the force channel is not diagnosed", path,
                                  NameOf(models::kSpecimenNames, s.plant.specimen)));
  } else {
    m.source += fmt::format("; Spencer damper from [plant.damper]; current dynamics {}",
                            !m.current_dynamics ? "off"
                            : m.current_driver.kind == models::CurrentFilter::kFirstOrder
                                ? fmt::format("first order, eta = {:g} 1/s", m.current_driver.eta_1_s)
                                : std::string("Eq. 40 + 75 Hz"));
  }
  if (s.plant.kind != models::PlantKind::kLinear)
    m.notes.push_back(fmt::format("{}: plant.kind = \"{}\": the diagnosis uses the 3-pole [plant] actuator "
                                  "as the displacement model",
                                  path, NameOf(models::kPlantKindNames, s.plant.kind)));
  if (s.plant.RigMode())
    m.notes.push_back(fmt::format("{}: the file switches rig-mode effects on; the nominal model ignores them", path));
  return m;
}

void Differentiate(const std::vector<double>& x, double dt_s, std::vector<double>* v) {
  *v = signal::Derivative(x, dt_s);  // second order next to the ends, one-sided at them
  const std::size_t n = x.size();
  for (std::size_t k = 2; k + 2 < n; ++k)
    (*v)[k] = (-x[k + 2] + 8.0 * x[k + 1] - 8.0 * x[k - 1] + x[k - 2]) / (12.0 * dt_s);
}

SmoothedMotion SmoothMotion(std::span<const double> y_mm, double dt_s, double smooth_hz) {
  const std::size_t n = y_mm.size();
  if (n < 4) throw Error("SmoothMotion", "need at least 4 samples");
  if (!(dt_s > 0.0) || !(smooth_hz > 0.0) || !(smooth_hz < 0.5 / dt_s))
    throw Error("SmoothMotion", fmt::format("smooth_hz {} must be in (0, {}) Hz", smooth_hz, 0.5 / dt_s));
  // Odd reflection about both ends: 6 time constants of the filter, at most n - 1 samples.
  const std::size_t pad = std::min<std::size_t>(n - 1, static_cast<std::size_t>(std::ceil(6.0 / (smooth_hz * dt_s))) + 8);
  SmoothedMotion m;
  m.x_mm = signal::ZeroPhaseLowpass(y_mm, dt_s, smooth_hz, 2, pad, signal::Reflection::kOdd);
  m.v_mm_s.resize(n);
  Differentiate(m.x_mm, dt_s, &m.v_mm_s);
  return m;
}

SmoothedMotion ModelAidedMotion(std::span<const double> y_mm, std::span<const double> yhat_mm,
                                std::span<const double> vhat_mm_s, double dt_s, double smooth_hz,
                                std::span<const double> ahat_mm_s2) {
  const std::size_t n = y_mm.size();
  if (yhat_mm.size() != n || (!vhat_mm_s.empty() && vhat_mm_s.size() != n) ||
      (!ahat_mm_s2.empty() && (ahat_mm_s2.size() != n || vhat_mm_s.empty())))
    throw Error("ModelAidedMotion", "lengths differ");
  std::vector<double> res(n);
  for (std::size_t k = 0; k < n; ++k) res[k] = y_mm[k] - yhat_mm[k];
  SmoothedMotion m = SmoothMotion(res, dt_s, smooth_hz);  // x = S(res), v = its derivative
  if (!ahat_mm_s2.empty()) {
    Differentiate(m.v_mm_s, dt_s, &m.a_mm_s2);  // d^2/dt^2 S(res)
    for (std::size_t k = 0; k < n; ++k) m.a_mm_s2[k] += ahat_mm_s2[k];
  }
  for (std::size_t k = 0; k < n; ++k) m.x_mm[k] += yhat_mm[k];
  if (vhat_mm_s.empty()) {
    Differentiate(m.x_mm, dt_s, &m.v_mm_s);
  } else {
    for (std::size_t k = 0; k < n; ++k) m.v_mm_s[k] += vhat_mm_s[k];
  }
  return m;
}

std::vector<double> PredictDisplacement(const models::LinearServo& servo, const models::EffectSet& effects,
                                        std::span<const double> u_mm, std::span<const double> f_kN,
                                        std::vector<double>* v_mm_s, std::vector<double>* a_mm_s2,
                                        std::span<const double> y_meas_mm, std::size_t first) {
  if (effects.supply_ripple && !y_meas_mm.empty()) {
    if (y_meas_mm.size() != u_mm.size())
      throw Error("PredictDisplacement", fmt::format("y has {} samples, u {}", y_meas_mm.size(), u_mm.size()));
    models::EffectSet rest = effects;
    rest.supply_ripple.reset();
    std::vector<double> y = PredictDisplacement(servo, rest, u_mm, f_kN, v_mm_s, a_mm_s2);
    std::vector<double> e(y.size());
    for (std::size_t k = 0; k < y.size(); ++k) e[k] = y_meas_mm[k] - y[k];
    FitRipple(e, servo.dt_s, effects.supply_ripple->f_hz, first)
        .AddTo(servo.dt_s, y, v_mm_s != nullptr ? std::span<double>(*v_mm_s) : std::span<double>{},
               a_mm_s2 != nullptr ? std::span<double>(*a_mm_s2) : std::span<double>{});
    return y;
  }
  const std::size_t n = u_mm.size();
  std::vector<double> y(n);
  std::vector<double> servo_v, servo_a;  // the servo's exact velocity z1 and acceleration z2 at t_k
  if (a_mm_s2 != nullptr && v_mm_s == nullptr) throw Error("PredictDisplacement", "an acceleration needs the velocity");
  if (v_mm_s != nullptr) {
    servo_v.resize(n);
    v_mm_s->resize(n);
  }
  if (a_mm_s2 != nullptr) servo_a.resize(n);
  models::DisplacementEffects fx(effects, servo.dt_s);
  // Plain 3x3 arithmetic (this is the inner loop of every fit).
  const Eigen::Matrix3d& P = servo.Phi;
  const Eigen::Vector3d& G = servo.Gamma;
  double z0 = 0, z1 = 0, z2 = 0;
  // servovalve_saturation inside the loop: the actuator integrated with its flow limit
  // (models/servo_flow_limit.h); z0, z1, z2 then carry its x, x' and x''.
  const bool in_loop = effects.servovalve_saturation && effects.servovalve_saturation->InLoop();
  std::optional<models::FlowLimitedServo> limited;
  if (in_loop) limited = models::FlowLimitedServo::Make(servo, effects.servovalve_saturation->vmax_mm_per_s);
  models::FlowLimitedServoState ls;
  for (std::size_t k = 0; k < n; ++k) {
    // load_coupling acts on the measured force of the same sample (see the header).
    const double fk = k < f_kN.size() ? f_kN[k] : 0.0;
    y[k] = fx.Post(z0, fk);
    if (v_mm_s != nullptr) {
      servo_v[k] = z1;
      (*v_mm_s)[k] = y[k] - z0;  // the output effects' share, differentiated below
    }
    if (a_mm_s2 != nullptr) servo_a[k] = z2;
    const double ua = fx.Pre(u_mm[k]);
    if (in_loop) {
      models::Step(*limited, &ls, ua);
      z0 = ls.x, z1 = models::Velocity(*limited, ls), z2 = models::Acceleration(*limited, ls);
      continue;
    }
    const double n0 = P(0, 0) * z0 + P(0, 1) * z1 + P(0, 2) * z2 + G(0) * ua;
    const double n1 = P(1, 0) * z0 + P(1, 1) * z1 + P(1, 2) * z2 + G(1) * ua;
    const double n2 = P(2, 0) * z0 + P(2, 1) * z1 + P(2, 2) * z2 + G(2) * ua;
    z0 = n0, z1 = n1, z2 = n2;
  }
  if (v_mm_s != nullptr && n >= 2) {
    std::vector<double> post_v;
    Differentiate(*v_mm_s, servo.dt_s, &post_v);
    for (std::size_t k = 0; k < n; ++k) (*v_mm_s)[k] = servo_v[k] + post_v[k];
    if (a_mm_s2 != nullptr) {
      Differentiate(post_v, servo.dt_s, a_mm_s2);
      for (std::size_t k = 0; k < n; ++k) (*a_mm_s2)[k] += servo_a[k];
    }
  }
  return y;
}

ForcePredictor::ForcePredictor(const models::MrDamperParams& damper, bool current_dynamics, double dt_s,
                               const models::CurrentDriverParams& driver)
    : damper_(damper), current_dynamics_(current_dynamics), dt_s_(dt_s),
      driver_(models::CurrentDriver::Make(driver, dt_s)) {
  damper_.Validate();
}

namespace {

/// Eqs. 35-39 tabulated on a 1 mA grid over the currents a record can reach (the effective
/// current overshoots a step of the command by a few per cent), linear interpolation between
/// (relative error below 1e-5 for Table 3's rates); exact outside the table.
class CoefficientTable {
 public:
  CoefficientTable(const models::MrDamperParams& damper, std::span<const double> i_A) : damper_(damper) {
    double imin = i_A[0], imax = i_A[0];
    for (double v : i_A) imin = std::min(imin, v), imax = std::max(imax, v);
    const double span = imax - imin;
    tlo_ = imin - 0.25 * span - 0.01;
    const double thi = imax + 0.25 * span + 0.01;
    nt_ = static_cast<std::size_t>(std::ceil((thi - tlo_) / kDi)) + 2;
    table_.resize(nt_);
    for (std::size_t j = 0; j < nt_; ++j) table_[j] = models::CoefficientsAt(damper_, tlo_ + kDi * static_cast<double>(j));
  }
  models::MrDamperCoefficients At(double i) const {
    const double x = (i - tlo_) / kDi;
    if (!(x >= 0.0) || x >= static_cast<double>(nt_ - 1)) return models::CoefficientsAt(damper_, i);
    const auto j = static_cast<std::size_t>(x);
    const double w = x - static_cast<double>(j);
    const auto& a = table_[j];
    const auto& b = table_[j + 1];
    models::MrDamperCoefficients c = a;
    c.alpha += w * (b.alpha - a.alpha);
    c.c0 += w * (b.c0 - a.c0);
    c.c1 += w * (b.c1 - a.c1);
    c.beta += w * (b.beta - a.beta);
    c.gamma += w * (b.gamma - a.gamma);
    return c;
  }

 private:
  static constexpr double kDi = 1e-3;  ///< the grid step [A]
  const models::MrDamperParams& damper_;
  double tlo_ = 0;
  std::size_t nt_ = 0;
  std::vector<models::MrDamperCoefficients> table_;
};

/// The motion inside step k -> k+1: the cubic Hermite interpolant of (x, v) at both ends, or the
/// quintic through the accelerations too.
struct StepMotion {
  double dt, x0, x1, v0, v1, a0, a1;
  bool quintic;
  /// x [mm] and x' [mm/s] at tau [s] into the step.
  void At(double tau, double* x, double* xd) const {
    const double t = tau / dt;
    const double t2 = t * t, t3 = t2 * t;
    if (quintic) {  // Hermite through (x, v, a) at both ends
      const double t4 = t3 * t, t5 = t4 * t, d2 = dt * dt;
      *x = (1 - 10 * t3 + 15 * t4 - 6 * t5) * x0 + (t - 6 * t3 + 8 * t4 - 3 * t5) * dt * v0 +
           0.5 * (t2 - 3 * t3 + 3 * t4 - t5) * d2 * a0 + (10 * t3 - 15 * t4 + 6 * t5) * x1 +
           (-4 * t3 + 7 * t4 - 3 * t5) * dt * v1 + 0.5 * (t3 - 2 * t4 + t5) * d2 * a1;
      *xd = ((-30 * t2 + 60 * t3 - 30 * t4) * x0 + (1 - 18 * t2 + 32 * t3 - 15 * t4) * dt * v0 +
             0.5 * (2 * t - 9 * t2 + 12 * t3 - 5 * t4) * d2 * a0 + (30 * t2 - 60 * t3 + 30 * t4) * x1 +
             (-12 * t2 + 28 * t3 - 15 * t4) * dt * v1 + 0.5 * (3 * t2 - 8 * t3 + 5 * t4) * d2 * a1) /
            dt;
      return;
    }
    *x = (2 * t3 - 3 * t2 + 1) * x0 + (t3 - 2 * t2 + t) * dt * v0 + (-2 * t3 + 3 * t2) * x1 + (t3 - t2) * dt * v1;
    *xd = ((6 * t2 - 6 * t) * x0 + (3 * t2 - 4 * t + 1) * dt * v0 + (-6 * t2 + 6 * t) * x1 + (3 * t2 - 2 * t) * dt * v1) / dt;
  }
};

/// Substeps of a step (file comment): from the size of the local Jacobian at the start of the
/// step, more across a reversal of the relative velocity; in [1, 256].
int Substeps(const models::MrDamperCoefficients& c0, const models::MrDamperState& s, const StepMotion& mo) {
  const double dt = mo.dt;
  const double vmax = std::max(std::abs(mo.v0), std::abs(mo.v1));
  const double zabs = std::abs(s.z_mm);
  const double zpow = c0.n == 2.0 ? zabs : std::pow(zabs, c0.n - 1.0);
  const double lam = (c0.beta + c0.gamma) * c0.n * zpow * vmax + c0.A * c0.alpha / (c0.c0 + c0.c1) +
                     c0.k0 / (c0.c0 + c0.c1);
  int m = std::clamp(static_cast<int>(std::ceil(dt * lam / kRk4StepLambda)), 1, 256);
  // A reversal of the relative velocity r = x' - y' inside the step (r changes sign between its
  // ends, the end's taken with the state at the start): Eq. 33 has a kink there (|r|), which
  // RK4 integrates with an error of about A alpha |r'| h^2 / 8 in alpha z (its slope jumps by up
  // to A), whatever the Jacobian's size. Substeps so that it stays below kKinkForceTolKn.
  const double r0 = mo.v0 - models::DamperRates(c0, s, mo.x0, mo.v0).ydot_mm_s;
  const double r1 = mo.v1 - models::DamperRates(c0, s, mo.x1, mo.v1).ydot_mm_s;
  const double dr = std::abs(mo.v1 - mo.v0);
  if (r0 * r1 <= 0.0) {
    const double kink = c0.A * c0.alpha * dr / dt / 8.0;  // [kN / s^2]
    if (kink > 0) m = std::clamp(static_cast<int>(std::ceil(dt * std::sqrt(kink / kKinkForceTolKn))), m, 256);
  }
  return m;
}

/// The effective current at tau = j h / 2, j = 0 .. 2m, inside a step from the closed form of
/// models/current_driver.h, i_c = i_h + r_1 e_1 e^{lambda_1 tau} + 2 Re(r e_q e^{lambda tau}),
/// with the exponentials advanced by multiplication (cached per substep count).
class HalfStepCurrents {
 public:
  explicit HalfStepCurrents(const models::CurrentDriver& driver) : driver_(driver), ic_(2 * 256 + 1) {}
  void Fill(const models::CurrentDriverState& cs, int m, double h) {
    if (m != cached_m_) {
      cached_m_ = m;
      half1_ = std::exp(driver_.pole1 * 0.5 * h);
      half_ = std::exp(driver_.pole * 0.5 * h);
    }
    double e1 = cs.e1_A_s;
    std::complex<double> eq = cs.eq_A_s;
    for (int j = 0; j <= 2 * m; ++j) {
      ic_[static_cast<std::size_t>(j)] = cs.held_A + driver_.residue1 * e1 + 2.0 * (driver_.residue * eq).real();
      e1 *= half1_;
      eq *= half_;
    }
  }
  double operator[](int j) const { return ic_[static_cast<std::size_t>(j)]; }

 private:
  const models::CurrentDriver& driver_;
  int cached_m_ = -1;
  double half1_ = 1.0;
  std::complex<double> half_{1.0, 0.0};
  std::vector<double> ic_;
};

/// m classical RK4 substeps of Eqs. 32-33 over the step, the coefficients from c0 (constant) or
/// at the half-step currents ic.
void IntegrateStep(const StepMotion& mo, int m, bool constant, const models::MrDamperCoefficients& c0,
                   const HalfStepCurrents& ic, const CoefficientTable& coef, models::MrDamperState* sp) {
  models::MrDamperState& s = *sp;
  const double h = mo.dt / m;
  models::MrDamperCoefficients cmid = c0, cend = c0, cstart = c0;
  double xa, va;
  mo.At(0.0, &xa, &va);
  for (int j = 0; j < m; ++j) {
    const double tb = j * h + 0.5 * h, tc = j * h + h;
    if (!constant) {
      cstart = j == 0 ? c0 : cend;
      cmid = coef.At(ic[2 * j + 1]);
      cend = coef.At(ic[2 * j + 2]);
    }
    double xb, vb, xc, vc;
    mo.At(tb, &xb, &vb);
    mo.At(tc, &xc, &vc);
    const models::MrDamperRates r1 = models::DamperRates(cstart, s, xa, va);
    const models::MrDamperState s2{s.y_mm + 0.5 * h * r1.ydot_mm_s, s.z_mm + 0.5 * h * r1.zdot_mm_s};
    const models::MrDamperRates r2 = models::DamperRates(cmid, s2, xb, vb);
    const models::MrDamperState s3{s.y_mm + 0.5 * h * r2.ydot_mm_s, s.z_mm + 0.5 * h * r2.zdot_mm_s};
    const models::MrDamperRates r3 = models::DamperRates(cmid, s3, xb, vb);
    const models::MrDamperState s4{s.y_mm + h * r3.ydot_mm_s, s.z_mm + h * r3.zdot_mm_s};
    const models::MrDamperRates r4 = models::DamperRates(cend, s4, xc, vc);
    s.y_mm += h / 6.0 * (r1.ydot_mm_s + 2 * r2.ydot_mm_s + 2 * r3.ydot_mm_s + r4.ydot_mm_s);
    s.z_mm += h / 6.0 * (r1.zdot_mm_s + 2 * r2.zdot_mm_s + 2 * r3.zdot_mm_s + r4.zdot_mm_s);
    xa = xc, va = vc;
  }
}

}  // namespace

std::vector<double> ForcePredictor::Predict(const SmoothedMotion& motion, std::span<const double> i_A,
                                            const models::EffectSet& effects, double i_start_A) const {
  auto f = PredictUnscaled(motion, i_A, effects, i_start_A);
  if (effects.damper_scale)
    for (double& v : f) v *= effects.damper_scale->scale;
  return f;
}

std::vector<double> ForcePredictor::PredictUnscaled(const SmoothedMotion& motion, std::span<const double> i_A,
                                                    const models::EffectSet& effects, double i_start_A) const {
  const std::size_t n = motion.x_mm.size();
  if (i_A.size() != n || motion.v_mm_s.size() != n) throw Error("ForcePredictor", "lengths differ");
  std::vector<double> f(n, 0.0);
  if (n == 0) return f;
  models::EffectSet fe_set;  // force effects only (current_lag); damper_scale is applied outside
  fe_set.current_lag = effects.current_lag;
  models::ForceEffects fe(fe_set, dt_s_);
  const double i_before = std::isnan(i_start_A) ? i_A[0] : i_start_A;
  fe.Reset(i_before);
  models::CurrentDriverState cs = models::SteadyState(i_before);
  models::MrDamperState s{};
  const CoefficientTable coef(damper_, i_A);
  HalfStepCurrents ic(driver_);
  const bool quintic = motion.a_mm_s2.size() == n;
  for (std::size_t k = 0; k < n; ++k) {
    const double ic_k = current_dynamics_ ? models::EffectiveCurrentA(driver_, cs) : cs.held_A;
    f[k] = models::DamperForceKn(coef.At(ic_k), s, motion.x_mm[k], motion.v_mm_s[k]);
    if (k + 1 == n) break;
    const double il = fe.Current(i_A[k]);
    if (current_dynamics_) {
      models::Hold(driver_, &cs, il);
    } else {
      cs = models::SteadyState(il);
    }
    const bool constant = !current_dynamics_ || models::AtSteadyState(cs);
    const StepMotion mo{dt_s_,
                        motion.x_mm[k],
                        motion.x_mm[k + 1],
                        motion.v_mm_s[k],
                        motion.v_mm_s[k + 1],
                        quintic ? motion.a_mm_s2[k] : 0.0,
                        quintic ? motion.a_mm_s2[k + 1] : 0.0,
                        quintic};
    const models::MrDamperCoefficients c0 = coef.At(constant ? cs.held_A : models::EffectiveCurrentAt(driver_, cs, 0.0));
    const int m = Substeps(c0, s, mo);
    if (!constant) ic.Fill(cs, m, dt_s_ / m);
    IntegrateStep(mo, m, constant, c0, ic, coef, &s);
    if (current_dynamics_) models::Advance(driver_, &cs);
  }
  return f;
}

}  // namespace rths::diagnosis
