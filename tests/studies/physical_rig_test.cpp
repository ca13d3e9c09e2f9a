// Physics-based servohydraulic rig (docs/models.md section 5, lib/models/servo_physical.h): its
// linearisation against Eqs. 28-29, the limits it reproduces, the MR damper load (E6 peaks,
// control-structure interaction), repeatability, allocation-free steps and timing, and the plant
// participant with plant.kind = "physical" through the lockstep.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/error.h"
#include "ident/identify.h"
#include "io/run_log.h"
#include "models/rig.h"
#include "models/servo_physical.h"
#include "studies/frequency.h"
#include "signal/history.h"
#include "run_support.h"
#include "test_support.h"

// Count every heap allocation of the process.
#include "alloc_counter.h"

using namespace rths::models;
using cd = std::complex<double>;
using rths::models::PhysicalActuatorConfig;

namespace {

constexpr double kDt = 0.0005;
constexpr double kPi = std::numbers::pi;

struct Tf3 {  // Eqs. 28-29: K / ((s + p)(s^2 + b s + c))
  double K, p, b, c;
  cd operator()(double f_hz) const {
    const cd s(0.0, 2 * kPi * f_hz);
    return K / ((s + p) * (s * s + b * s + c));
  }
};
const Tf3 kEq28{1.730e7, 182.7, 225.3, 9.499e4};
const Tf3 kEq29{1.613e7, 134.2, 324.6, 1.211e5};

// The fitted inner-loop gain of docs/models.md section 5 is the product K_p K_q / A = 133.3 1/s;
// The scenario default K_p = 331.4 1/m is that product to four digits (docs/models.md rounds it to 331,
// which gives 133.1 1/s and misses the 1.9 deg phase bound at 0.0 A by 0.035 deg).
PhysicalActuatorConfig FittedConfig() {
  PhysicalActuatorConfig c;
  c.kp_per_m = 133.3 * c.area_m2 / c.kq_m3_s;
  return c;
}

// The actuator's 5 x 5 Jacobian at rest (and its input column) by central differences of the
// implemented ActuatorRates, with the spring-dashpot load F = k x + c x'.
struct Linearised {
  Eigen::Matrix<double, 5, 5> J;
  Eigen::Matrix<double, 5, 1> B;
};
Eigen::Matrix<double, 5, 1> RatesVec(const PhysicalActuator& a, const SpringDashpot& load,
                                     const Eigen::Matrix<double, 5, 1>& w, double u_m) {
  const ActuatorState s{w(0), w(1), w(2), w(3), w(4)};
  const ActuatorState d = ActuatorRates(a, s, u_m, load.k_N_m * s.x_m + load.c_N_s_m * s.v_m_s);
  Eigen::Matrix<double, 5, 1> r;
  r << d.x_m, d.v_m_s, d.pL_Pa, d.xv, d.xv_rate_per_s;
  return r;
}
Linearised Linearise(const PhysicalActuator& a, const SpringDashpot& load) {
  // Increments: tiny against each state's scale, so that neither sat nor the sqrt kink is hit
  // (central differences of Q = K_q x_v f(p_L) at x_v = 0 give K_q exactly: the kink's two
  // slopes average to the linearisation's).
  const double inc[5] = {1e-9, 1e-7, 1e-2, 1e-7, 1e-5};
  Linearised L;
  const Eigen::Matrix<double, 5, 1> zero = Eigen::Matrix<double, 5, 1>::Zero();
  for (int j = 0; j < 5; ++j) {
    Eigen::Matrix<double, 5, 1> wp = zero, wm = zero;
    wp(j) = inc[j], wm(j) = -inc[j];
    L.J.col(j) = (RatesVec(a, load, wp, 0.0) - RatesVec(a, load, wm, 0.0)) / (2 * inc[j]);
  }
  L.B = (RatesVec(a, load, zero, 1e-9) - RatesVec(a, load, zero, -1e-9)) / 2e-9;
  return L;
}
cd ContinuousResponse(const Linearised& L, double f_hz) {
  const cd s(0.0, 2 * kPi * f_hz);
  const Eigen::Matrix<cd, 5, 5> m = s * Eigen::Matrix<cd, 5, 5>::Identity() - L.J.cast<cd>();
  return m.partialPivLu().solve(L.B.cast<cd>())(0);
}
// ZOH discretisation at kDt (Van Loan, in a scaled basis: mm, m/s, MPa, -, 1/ms) and the
// sampled response C (zI - Phi)^-1 Gamma at z = e^{j w dt}: what a simulation with u held over
// each step and y read at the samples must give.
cd DiscreteResponse(const Linearised& L, double f_hz) {
  Eigen::Matrix<double, 5, 1> d;
  d << 1e3, 1.0, 1e-6, 1.0, 1e-3;
  Eigen::Matrix<double, 6, 6> aug = Eigen::Matrix<double, 6, 6>::Zero();
  aug.topLeftCorner<5, 5>() = d.asDiagonal() * L.J * d.cwiseInverse().asDiagonal();
  aug.topRightCorner<5, 1>() = d.asDiagonal() * L.B;
  const Eigen::Matrix<double, 6, 6> e = (aug * kDt).exp();
  const Eigen::Matrix<double, 5, 5> phi = e.topLeftCorner<5, 5>();
  const Eigen::Matrix<double, 5, 1> gamma = e.topRightCorner<5, 1>();
  const cd z = std::exp(cd(0.0, 2 * kPi * f_hz * kDt));
  const Eigen::Matrix<cd, 5, 5> m = z * Eigen::Matrix<cd, 5, 5>::Identity() - phi.cast<cd>();
  return m.partialPivLu().solve(gamma.cast<cd>())(0) / d(0);
}

double PhaseDeg(cd h) { return std::arg(h) * 180.0 / kPi; }

struct Match {
  double max_mag = 0, max_phase_deg = 0, f_mag = 0, f_phase = 0;
};
Match Compare(const PhysicalActuator& a, const SpringDashpot& load, const Tf3& ref) {
  Match m;
  for (double f = 0.5; f <= 40.0 + 1e-9; f += 0.1) {
    const cd g = SmallSignalResponse(a, load, f), r = ref(f);
    const double em = std::abs(std::abs(g) / std::abs(r) - 1.0);
    const double ep = std::abs(PhaseDeg(g / r));
    if (em > m.max_mag) m.max_mag = em, m.f_mag = f;
    if (ep > m.max_phase_deg) m.max_phase_deg = ep, m.f_phase = f;
  }
  return m;
}

// Fundamental of a sampled record at f_hz over whole periods: sum x_k e^{-j w t_k}.
cd Fundamental(const std::vector<double>& x, int from, int to, double f_hz) {
  cd acc = 0.0;
  for (int k = from; k < to; ++k) acc += x[k] * std::exp(cd(0.0, -2 * kPi * f_hz * k * kDt));
  return acc;
}

struct Record {
  std::vector<double> u, y, f, i;
};
// Drives a physical rig with u_k = amp sin(2 pi f k dt) [mm] and the current i(k) for n steps;
// y_k, f_k read at sample k (before the step with u_k).
template <class CurrentOf>
Record Drive(const PhysicalRig& rig, double amp_mm, double f_hz, int n, CurrentOf current,
             PhysicalRigState init = {}) {
  PhysicalRigStepper stepper(rig);
  PhysicalRigState s = init;
  Record r;
  for (int k = 0; k < n; ++k) {
    const double u = amp_mm * std::sin(2 * kPi * f_hz * k * kDt);
    r.y.push_back(MeasuredDisplacementMm(rig, s));
    r.f.push_back(MeasuredForceKn(rig, s));
    r.i.push_back(EffectiveCurrentA(rig, s));
    r.u.push_back(u);
    stepper.Step(&s, u, current(k));
  }
  return r;
}

// This thread's CPU time [s]: step timings that other processes on the machine do not inflate.
double ThreadCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double PeakAbs(const std::vector<double>& x, int from, int to) {
  double p = 0;
  for (int k = from; k < to; ++k) p = std::max(p, std::abs(x[k]));
  return p;
}

}  // namespace

TEST_CASE("(a) linearisation at rest matches Eqs. 28 and 29 with the equivalent spring-dashpot") {
  const PhysicalActuator fitted = PhysicalActuator::Make(FittedConfig());
  const PhysicalActuator defaults = PhysicalActuator::Make(PhysicalActuatorConfig{});
  CHECK(fitted.LoopGainPerS() == doctest::Approx(133.3).epsilon(1e-12));

  struct Case {
    std::string name;
    SpringDashpot load;
    Tf3 ref;
  };
  for (const Case& c : {Case{"0.0 A / Eq. 28", kEquivalentDamper0A, kEq28},
                        Case{"2.5 A / Eq. 29", kEquivalentDamper2p5A, kEq29}}) {
    CAPTURE(c.name);
    // The closed form is the implemented model's linearisation: the Jacobian of ActuatorRates.
    const Linearised L = Linearise(fitted, c.load);
    for (double f : {0.5, 5.0, 20.0, 40.0, 100.0}) {
      const cd g = SmallSignalResponse(fitted, c.load, f);
      CHECK(std::abs(ContinuousResponse(L, f) / g - 1.0) < 1e-6);
    }
    const Match m = Compare(fitted, c.load, c.ref);
    const Match m_default = Compare(defaults, c.load, c.ref);
    MESSAGE(c.name << ", K_p K_q / A = 133.3 1/s: max |mag error| " << 100 * m.max_mag << " % at "
                   << m.f_mag << " Hz, max |phase error| " << m.max_phase_deg << " deg at "
                   << m.f_phase << " Hz; with the scenario default K_p = "
                   << PhysicalActuatorConfig{}.kp_per_m << " 1/m: "
                   << 100 * m_default.max_mag << " %, " << m_default.max_phase_deg << " deg");
    CHECK(m.max_mag < 0.034);
    CHECK(m.max_phase_deg < 1.9);
    CHECK(m_default.max_mag < 0.034);
    CHECK(m_default.max_phase_deg < 1.9);
    // DC gain K_p K_q / (K_p K_q + C_tot k / A): the leakage under the spring's force costs
    // 0.3 % at 0.0 A and 3.5 % at 2.5 A (Eq. 29 has 0.75 %), the largest magnitude error.
    const double dc = std::abs(SmallSignalResponse(fitted, c.load, 0.0));
    const double dc_ref = c.ref.K / (c.ref.p * c.ref.c);
    MESSAGE(c.name << ": DC gain " << dc << " (Eq.: " << dc_ref << ")");
    CHECK(dc == doctest::Approx(dc_ref).epsilon(0.034));
  }
}

TEST_CASE("(a) simulated small sines (CVODE, u held per step) give the linearisation's sampled response") {
  const PhysicalActuatorConfig cfg = FittedConfig();
  const PhysicalRig rig = PhysicalRig::Make(cfg, kDt, RigLoad::kSpringDashpot, false,
                                            MrDamperParams::Table3(), kEquivalentDamper2p5A);
  const Linearised L = Linearise(rig.actuator, rig.spring);
  for (double f : {2.0, 10.0, 20.0, 40.0}) {
    const int period = static_cast<int>(std::lround(1.0 / (f * kDt)));
    const int settle = 400, n = settle + 2 * std::max(period, 400) / period * period;
    const Record r = Drive(rig, 1e-3, f, n, [](int) { return 0.0; });  // 1 micron
    const cd g = Fundamental(r.y, settle, n, f) / Fundamental(r.u, settle, n, f);
    const cd gd = DiscreteResponse(L, f);
    MESSAGE(f << " Hz: simulated |G| " << std::abs(g) << ", phase " << PhaseDeg(g)
              << " deg; linearisation (ZOH, sampled) " << std::abs(gd) << ", " << PhaseDeg(gd)
              << " deg; continuous " << PhaseDeg(ContinuousResponse(L, f)) << " deg");
    CHECK(std::abs(g) == doctest::Approx(std::abs(gd)).epsilon(2e-3));
    CHECK(std::abs(PhaseDeg(g / gd)) < 0.1);
  }
}

TEST_CASE("(a) E1 on the damper-loaded rig (16 s records): how close the identified models come to Eqs. 28-29") {
  // E1 as `rths reproduce fig6 --quick` runs it (lib/studies/fig6.cpp), without the lockstep:
  // BLWN 0-50 Hz, 0.254 mm RMS, seed 1, 2 s discarded, 0.5 s fade-in; u_k held over each step,
  // y_k read at t_k; the MR damper (Table 3) at a constant current; H1 and the ZOH-consistent
  // 3-pole fit over 0.5-40 Hz.
  const std::vector<double> u = rths::signal::MakeSignal(rths::studies::FrequencyExcitation(), kDt, 32000);
  rths::ident::IdentifyOptions io;
  io.fit.poles = 3;
  io.fit.band_lo_hz = 0.5;
  io.fit.band_hi_hz = 40.0;
  io.fit.zoh_dt_s = kDt;
  const double current[2] = {0.0, 2.5};
  const char* cond[2] = {"0.0A", "2.5A"};
  rths::models::ServoModel3 fit[2];
  double lag_ms[2];
  for (int j = 0; j < 2; ++j) {
    const std::string name = cond[j];
    CAPTURE(name);
    const PhysicalRig rig = PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kMrDamper, true);
    PhysicalRigStepper stepper(rig);
    PhysicalRigState s;
    s.current = SteadyState(current[j]);
    std::vector<double> y(u.size());
    for (std::size_t k = 0; k < u.size(); ++k) {
      y[k] = MeasuredDisplacementMm(rig, s);
      stepper.Step(&s, u[k], current[j]);
    }
    const auto id = rths::ident::Identify(u, y, kDt, io);
    const auto ref = rths::models::ServoPreset(cond[j]);
    fit[j] = id.fit.model.ToServoModel3();
    lag_ms[j] = 1e3 * id.fit.model.DcLagS();
    const double ref_lag_ms = 1e3 * rths::ident::PoleModel::FromServoModel3(ref).DcLagS();
    // The measured response against the Eq.'s own (ZOH at dt, as the data are).
    const auto zoh = rths::ident::Discretise(rths::ident::PoleModel::FromServoModel3(ref), kDt);
    double mag = 0, phase = 0;
    for (std::size_t i = 0; i < id.frf.f_hz.size(); ++i) {
      if (id.frf.f_hz[i] < 0.5 || id.frf.f_hz[i] > 40.0) continue;
      const cd q = id.frf.h[i] / rths::ident::ZohResponse(zoh, id.frf.f_hz[i]);
      mag = std::max(mag, std::abs(std::abs(q) - 1.0));
      phase = std::max(phase, std::abs(PhaseDeg(q)));
    }
    MESSAGE(cond[j] << ": fitted K " << fit[j].K << " (" << 100 * (fit[j].K / ref.K - 1) << " %), p " << fit[j].p
                    << " (" << 100 * (fit[j].p / ref.p - 1) << " %), b " << fit[j].b << " ("
                    << 100 * (fit[j].b / ref.b - 1) << " %), c " << fit[j].c << " (" << 100 * (fit[j].c / ref.c - 1)
                    << " %); fit error: magnitude " << id.fit.max_mag_error_pct << " %, phase "
                    << id.fit.max_phase_error_deg << " deg; DC lag " << lag_ms[j] << " ms (Eq.: " << ref_lag_ms
                    << "); measured vs the Eq.: magnitude " << 100 * mag << " %, phase " << phase << " deg");
    // What holds: a 3-pole model describes the loaded rig well, its real pole and its
    // low-frequency lag are the Eq.'s, and the measured response is within 10 % / 8 deg of it.
    CHECK(id.fit.max_mag_error_pct < 2.0);
    CHECK(id.fit.max_phase_error_deg < 2.0);
    CHECK(fit[j].p == doctest::Approx(ref.p).epsilon(0.05));
    CHECK(lag_ms[j] == doctest::Approx(ref_lag_ms).epsilon(0.06));
    CHECK(mag < 0.10);
    CHECK(phase < 8.0);
  }
  // Control-structure interaction: 2.5 A lags more, as Eq. 29 does.
  CHECK(lag_ms[1] > lag_ms[0] + 2.0);
  // What does not hold (docs/plant.md, "E1 on the damper-loaded rig"): E1's 8 % on K, b, c
  // (0.0 A: K +27 %, b +32 %, c +21 %; 2.5 A: K -17 %, c -14 %). From Eq. 28 to Eq. 29 the
  // complex pair moves up and is damped more (b x 1.44, c x 1.27); the loaded rig's pair barely
  // moves with the current (ratios about 1.03 and 0.91). bench/tune_physical.cpp searched the
  // valve and oil-column parameters of docs/models.md section 5 for both conditions at once: the best
  // balance is about 17 % (K, b, c split +/-), so no retuning of those parameters meets 8 %.
  MESSAGE("b 2.5A/0.0A " << fit[1].b / fit[0].b << " (Eqs.: 1.441), c 2.5A/0.0A " << fit[1].c / fit[0].c
                         << " (Eqs.: 1.275)");
}

TEST_CASE("(b) limits: velocity K_q / A, valve saturation beyond 1 / K_p, flow factor at 190 kN") {
  const PhysicalActuator a = PhysicalActuator::Make(PhysicalActuatorConfig{});
  CHECK(a.VelocityLimitM_s() == doctest::Approx(0.40).epsilon(0.01));
  CHECK(a.SaturationErrorM() == doctest::Approx(3.0e-3).epsilon(0.01));
  CHECK(a.ForceCapacityN() == doctest::Approx(561e3).epsilon(0.001));

  // Valve saturation: |u - x| > 1 / K_p = 3.02 mm opens the spool fully.
  CHECK(ValveCommand(a, 3.1e-3, 0.0) == 1.0);
  CHECK(ValveCommand(a, -3.1e-3, 0.0) == -1.0);
  const double kp = PhysicalActuatorConfig{}.kp_per_m;
  CHECK(ValveCommand(a, 2.9e-3, 0.0) == doctest::Approx(kp * 2.9e-3));
  CHECK(ValveCommand(a, 12.0e-3, 10.0e-3) == doctest::Approx(kp * 2.0e-3));

  // Flow factor: 190 kN against the flow -> sqrt(1 - p_L / P_s) = 0.81; with it: 1.16; the
  // guard gives no flow against a load pressure above supply.
  const double p190 = 190e3 / a.area_m2;
  CHECK(FlowFactor(a, 0.5, p190) == doctest::Approx(0.81).epsilon(0.01));
  CHECK(FlowFactor(a, -0.5, -p190) == doctest::Approx(0.81).epsilon(0.01));
  CHECK(FlowFactor(a, -0.5, p190) == doctest::Approx(std::sqrt(1 + p190 / 20.7e6)));
  CHECK(FlowFactor(a, 1.0, 2 * a.supply_pressure_Pa) == 0.0);
  CHECK(FlowFactor(a, 0.0, p190) == 1.0);

  // A 100 mm step with no specimen: the spool saturates and the piston cruises at K_q / A.
  // (Unloaded, the oil column's 250 Hz mode is damped by leakage alone, zeta ~ 0.4 %: the
  // velocity rings around the limit after the spool opens; the mean speed is the limit.)
  {
    const PhysicalRig rig = PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kNone, false);
    PhysicalRigStepper stepper(rig);
    PhysicalRigState s;
    double iv_min = 1, x20 = 0, x180 = 0;
    for (int k = 1; k <= 600; ++k) {  // 0.3 s
      stepper.Step(&s, 100.0, 0.0);
      if (k >= 20 && k <= 180) iv_min = std::min(iv_min, ValveCommand(rig.actuator, 0.1, s.actuator.x_m));
      if (k == 20) x20 = s.actuator.x_m;
      if (k == 180) x180 = s.actuator.x_m;
    }
    const double v_mean = (x180 - x20) / (160 * kDt);
    MESSAGE("100 mm step, no load: mean speed " << v_mean << " m/s over 10-90 ms (K_q / A = "
                                                << rig.actuator.VelocityLimitM_s() << ")");
    CHECK(iv_min == 1.0);  // saturated while |u - x| > 3 mm
    CHECK(v_mean == doctest::Approx(rig.actuator.VelocityLimitM_s()).epsilon(0.002));
    CHECK(MeasuredDisplacementMm(rig, s) == doctest::Approx(100.0).epsilon(1e-3));
  }
  // A 100 mm step into a dashpot that takes 190 kN at the resulting speed: full spool, and the
  // speed drops to the flow factor (0.81) times K_q / A, less the leakage C_tot p_L / A.
  {
    const SpringDashpot dashpot{0.0, 5.96e5};
    const PhysicalRig rig =
        PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kSpringDashpot, false,
                          MrDamperParams::Table3(), dashpot);
    PhysicalRigStepper stepper(rig);
    PhysicalRigState s;
    for (int k = 0; k < 200; ++k) stepper.Step(&s, 100.0, 0.0);  // 0.1 s: at cruise speed
    const double f_kN = MeasuredForceKn(rig, s);
    const double v = s.actuator.v_m_s;
    const double pL = s.actuator.pL_Pa;
    const double factor = FlowFactor(rig.actuator, 1.0, pL);
    MESSAGE("dashpot at full spool: force " << f_kN << " kN, speed " << v << " m/s = "
                                            << v / rig.actuator.VelocityLimitM_s()
                                            << " of K_q / A; flow factor " << factor);
    CHECK(s.actuator.xv == doctest::Approx(1.0).epsilon(1e-6));
    CHECK(f_kN == doctest::Approx(190.0).epsilon(0.02));
    CHECK(factor == doctest::Approx(0.81).epsilon(0.01));
    CHECK(v * rig.actuator.area_m2 ==
          doctest::Approx(rig.actuator.kq_m3_s * factor - rig.actuator.leakage_m3_s_Pa * pL)
              .epsilon(1e-4));
  }
}

TEST_CASE("(c) MR damper load: 1 Hz 25.4 mm sine peaks near E6; 2.5 A lags more (CSI)") {
  PhysicalActuatorConfig cfg;  // scenario defaults
  const int n = 6000;          // 3 s; peaks over the 2nd and 3rd cycles (E6's convention)
  double peaks[2], amp[2];
  const double current[2] = {0.0, 2.5}, e6[2] = {18.3, 187.0};
  for (int j = 0; j < 2; ++j) {
    const PhysicalRig rig = PhysicalRig::Make(cfg, kDt, RigLoad::kMrDamper, true);
    const double i = current[j];
    PhysicalRigState init;
    init.current = SteadyState(i);
    const Record r = Drive(rig, 25.4, 1.0, n, [i](int) { return i; }, init);
    peaks[j] = PeakAbs(r.f, 2000, n);
    amp[j] = std::abs(Fundamental(r.y, 2000, n, 1.0)) / std::abs(Fundamental(r.u, 2000, n, 1.0));
    MESSAGE(current[j] << " A: peak force " << peaks[j] << " kN (E6, the damper alone at exactly "
                       "25.4 mm: " << e6[j] << "), displacement amplitude ratio " << amp[j]);
  }
  // At 1 Hz the loop gain is high: the piston follows the command to within 0.1 % in amplitude,
  // about 8-11 ms late. A lag does not change the peak of a periodic response, and a yielded MR
  // damper's force depends on the amplitude only weakly (through its viscous part), so the peaks
  // land within 1 % of E6 (the 190 kN flow factor of 0.81 costs loop gain, not amplitude, here).
  CHECK(amp[0] == doctest::Approx(1.0).epsilon(0.002));
  CHECK(amp[1] == doctest::Approx(1.0).epsilon(0.002));
  CHECK(peaks[0] == doctest::Approx(e6[0]).epsilon(0.01));
  CHECK(peaks[1] == doctest::Approx(e6[1]).epsilon(0.01));

  // Control-structure interaction: the measured time lag at 5 Hz (1 mm sine) is larger at 2.5 A.
  double lag_ms[2];
  for (int j = 0; j < 2; ++j) {
    const PhysicalRig rig = PhysicalRig::Make(cfg, kDt, RigLoad::kMrDamper, true);
    const double i = current[j];
    PhysicalRigState init;
    init.current = SteadyState(i);
    const int m = 2400;  // 1.2 s; the last 0.8 s (4 periods of 400 samples)
    const Record r = Drive(rig, 1.0, 5.0, m, [i](int) { return i; }, init);
    const cd g = Fundamental(r.y, 800, m, 5.0) / Fundamental(r.u, 800, m, 5.0);
    lag_ms[j] = -std::arg(g) / (2 * kPi * 5.0) * 1e3;
    MESSAGE(current[j] << " A, 5 Hz, 1 mm: |G| " << std::abs(g) << ", time lag " << lag_ms[j]
                       << " ms (Eq. " << std::string(j ? "29: 10.0" : "28: 7.8") << " ms)");
  }
  CHECK(lag_ms[1] > lag_ms[0] + 1.0);
  CHECK(lag_ms[0] > 5.0);
  CHECK(lag_ms[1] < 20.0);
}

TEST_CASE("(c) CVODE and fixed-step RK4 at dt/4 agree") {
  PhysicalRig rig = PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kMrDamper, true);
  const auto pulse = [](int k) { return (k / 1000) % 2 ? 0.0 : 2.5; };
  const Record cv = Drive(rig, 25.4, 1.0, 4000, pulse);
  rig.integrator = RigIntegrator::kRk4;
  rig.rk4_substeps = 4;
  const Record rk = Drive(rig, 25.4, 1.0, 4000, pulse);
  double dy = 0, df = 0;
  for (int k = 0; k < 4000; ++k) {
    dy = std::max(dy, std::abs(cv.y[k] - rk.y[k]));
    df = std::max(df, std::abs(cv.f[k] - rk.f[k]));
  }
  MESSAGE("CVODE (rtol 1e-8) vs RK4 (dt/4), 1 Hz 25.4 mm, 0.5 Hz 0/2.5 A pulse: max |dy| " << dy
                                                                                      << " mm, max |df| " << df << " kN");
  CHECK(dy < 1e-3);
  CHECK(df < 0.5);
}

TEST_CASE("(d) repeatable: bit-identical runs, and a step depends only on (state, u, i)") {
  const PhysicalRig rig = PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kMrDamper, true);
  const auto pulse = [](int k) { return (k / 400) % 2 ? 2.5 : 0.0; };
  const Record a = Drive(rig, 10.0, 3.0, 3000, pulse);
  const Record b = Drive(rig, 10.0, 3.0, 3000, pulse);
  CHECK(a.y == b.y);
  CHECK(a.f == b.f);
  CHECK(a.i == b.i);
  // Re-answering step k from the saved state at k-1, with a stepper of another history.
  PhysicalRigStepper stepper(rig), other(rig);
  PhysicalRigState s;
  std::vector<PhysicalRigState> states;
  for (int k = 0; k < 1500; ++k) {
    states.push_back(s);
    stepper.Step(&s, 10.0 * std::sin(0.01 * k), pulse(k));
  }
  states.push_back(s);
  for (int k : {1499, 401, 800, 3}) {
    PhysicalRigState t = states[k];
    other.Step(&t, 10.0 * std::sin(0.01 * k), pulse(k));
    CHECK(t.actuator.x_m == states[k + 1].actuator.x_m);
    CHECK(t.actuator.pL_Pa == states[k + 1].actuator.pL_Pa);
    CHECK(t.damper.z_mm == states[k + 1].damper.z_mm);
    CHECK(t.current.e1_A_s == states[k + 1].current.e1_A_s);
  }
}

TEST_CASE("Rig::Step allocates nothing; time per step, physical vs linear") {
  for (const std::string kind : {"linear", "physical"}) {
    for (const bool pulse : {false, true}) {
      rths::models::PlantConfig cfg;  // MR damper, current dynamics on
      cfg.kind = rths::ParseName(rths::models::kPlantKindNames, kind, "kind");
      auto rig = MakeRig(cfg, kDt);
      const int steps = 4000;
      double sum = 0;
      const long before = rths_test::AllocationCount();
      const double t0 = ThreadCpuS();
      for (int k = 0; k < steps; ++k) {
        // 0.5 Hz 2.5 A / 0 A pulse through the current dynamics, or a constant 2.5 A.
        const double i = pulse && (k / 1000) % 2 ? 0.0 : 2.5;
        rig->Step(25.4 * std::sin(2 * kPi * k * kDt), i);
        sum += rig->f_kN() + rig->y_mm() + rig->current_A();
      }
      const double t1 = ThreadCpuS();
      const long allocations = rths_test::AllocationCount() - before;
      const double us = (t1 - t0) * 1e6 / steps;
      MESSAGE(kind << " rig, MR damper, 1 Hz 25.4 mm sine, "
                   << std::string(pulse ? "0.5 Hz 2.5/0 A pulse" : "constant 2.5 A") << ": " << us
                   << " us CPU per step (mean of " << steps << ")");
      CHECK(allocations == 0);
      CHECK(std::isfinite(sum));
    }
  }
}

TEST_CASE("Make validates") {
  PhysicalActuatorConfig bad;
  bad.beta_Pa = 0.0;
  CHECK_THROWS_AS(PhysicalActuator::Make(bad), rths::Error);
  CHECK_THROWS_AS(PhysicalRig::Make(PhysicalActuatorConfig{}, 0.0, RigLoad::kNone, false),
                  rths::Error);
  CHECK_THROWS_AS(PhysicalRig::Make(PhysicalActuatorConfig{}, kDt, RigLoad::kSpringDashpot, false,
                                    MrDamperParams::Table3(), {-1.0, 0.0}),
                  rths::Error);
  rths::models::PlantConfig cfg;
  cfg.kind = static_cast<rths::models::PlantKind>(42);  // not a loading system
  CHECK_THROWS_AS(MakeRig(cfg, kDt), rths::Error);
}

namespace {

struct LockstepOutcome {
  double peak_f_kN = 0, peak_i_A = 0, rms_error = 0;
  bool finite = true;
  double current_1 = -1, current_0 = -1;
};
LockstepOutcome RunPlant(const std::string& kind, const std::string& semiactive) {
  using namespace rths_test;
  const auto dir = TempDir("plant_" + kind + "_" + semiactive);
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 0.5
[structure]
mode = "rths"
mass_kg = 20000.0
frequency_hz = 5.0
[structure.ground]
kind = "blwn"
band_hz = 30.0
rms_mm_s2 = 2000.0
seed = 5
[controller]
kind = "ff"
model = "avg"
[plant]
kind = ")" + kind + R"("
specimen = "mr_damper"
[semiactive]
mode = ")" + semiactive + R"("
)").string());
  const auto run = RunMemq({s}, dir);
  for (const auto& e : run.errors) CAPTURE(e);
  REQUIRE(run.code == 0);
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  const std::int64_t n = s.steps();
  REQUIRE(log.CompleteSteps() == n);
  LockstepOutcome o;
  double sum_e2 = 0, sum_r2 = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto& m = log.measured[k];
    o.finite = o.finite && std::isfinite(m.y_mm) && std::isfinite(m.f_kN) && std::isfinite(m.current_A);
    o.peak_f_kN = std::max(o.peak_f_kN, std::abs(m.f_kN));
    o.peak_i_A = std::max(o.peak_i_A, m.current_A);
    const double e = log.desired[k].r_mm - m.y_mm;
    sum_e2 += e * e;
    sum_r2 += log.desired[k].r_mm * log.desired[k].r_mm;
  }
  o.rms_error = std::sqrt(sum_e2 / sum_r2);
  o.current_0 = log.measured[0].current_A;
  o.current_1 = log.measured[1].current_A;
  return o;
}

}  // namespace

TEST_CASE("(e) the plant participant with plant.kind = \"physical\" through the lockstep (memq)") {
  // SDOF 5 Hz, 20 t, BLWN ground 0-30 Hz, FF (avg model), damper at 2.5 A, 0.5 s.
  const LockstepOutcome phys = RunPlant("physical", "passive_on");
  const LockstepOutcome lin = RunPlant("linear", "passive_on");
  const LockstepOutcome phys_off = RunPlant("physical", "passive_off");
  const LockstepOutcome lin_off = RunPlant("linear", "passive_off");
  MESSAGE("2.5 A: physical plant: peak force " << phys.peak_f_kN << " kN, RMS tracking error "
                                        << 100 * phys.rms_error << " %; linear plant (Eq. 30): "
                                        << lin.peak_f_kN << " kN, " << 100 * lin.rms_error << " %");
  MESSAGE("0.0 A: physical plant: peak force " << phys_off.peak_f_kN << " kN, RMS tracking error "
                                        << 100 * phys_off.rms_error << " %; linear plant (Eq. 30): "
                                        << lin_off.peak_f_kN << " kN, " << 100 * lin_off.rms_error << " %");
  CHECK(phys_off.finite);
  CHECK(phys.finite);
  CHECK(phys.current_0 == 0.0);
  CHECK(phys.current_1 == 2.5);  // the driver starts steady at the first command
  CHECK(phys.peak_i_A == 2.5);
  CHECK(phys.peak_f_kN > 1.0);
  CHECK(phys.peak_f_kN < 250.0);  // the 200-kN damper
  // The same order of force as the linear plant's run; tracking worse (the FF inverts Eq. 30,
  // and the loaded physical actuator at 2.5 A lags more and has a lower gain) but bounded.
  CHECK(phys.peak_f_kN == doctest::Approx(lin.peak_f_kN).epsilon(0.5));
  CHECK(phys.rms_error < 0.25);
}
