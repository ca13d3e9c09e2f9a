// Tests for the adaptive tracking controllers (lib/control/ats.h, ambc.h): identification of plants
// whose inverse is in the compensator's family (to round-off) and of gain-and-delay and first-order-lag
// plants (a0 = 1/A, a1 = tau/A or T + dt/2, as independent re-implementations of the OpenFresco and
// RobustAMBCvRTHS wiring give on the same targets), convergence from
// wrong starts, boundedness under measurement noise, the guards (ATS: trigger, fallback, rate limit,
// bounds; AMBC: saturation with windup, Gamma = 0), the exact flow of the gradient law against RK4,
// Linearize against Step, allocation-free steps and the refused configurations.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "control/ambc.h"
#include "control/ats.h"
#include "control/transfer_function.h"
#include "core/error.h"
#include "models/servo_linear.h"
#include "scenario/scenario.h"
#include "signal/blwn.h"
#include "signal/random.h"

#include <Eigen/Dense>

#include "alloc_counter.h"
#include "scenario_support.h"
#include "test_support.h"

namespace ctl = rths::control;
namespace sig = rths::signal;
using std::numbers::pi;
using Target = std::function<double(double)>;

namespace {

constexpr double kAtsDt = 1.0 / 1024.0;   // OpenFresco's OneBayFrame rate
constexpr double kAmbcDt = 1.0 / 4096.0;  // RobustAMBCvRTHS's rate

/// A multi-sine [mm] faded in over 2 s by the quintic smoothstep 10 x^3 - 15 x^4 + 6 x^5 (continuous up
/// to r'': a kink would put a spike of size 1/dt^2 into the third difference D3 r).
Target MultiSine(std::vector<double> f_hz, std::vector<double> amp_mm, double phase_step) {
  return [=](double t) {
    double r = 0.0;
    for (std::size_t i = 0; i < f_hz.size(); ++i) {
      r += amp_mm[i] * std::sin(2.0 * pi * f_hz[i] * t + phase_step * (i + 1.0));
    }
    const double x = std::min(t / 2.0, 1.0);
    return r * x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
  };
}
/// The ATS checks' target: 0.37/1.1/2.3/4.1 Hz, 6/3/1.5/0.8 mm.
Target AtsTarget() { return MultiSine({0.37, 1.1, 2.3, 4.1}, {6.0, 3.0, 1.5, 0.8}, 0.7); }
/// The AMBC checks' target: 0.6/1.7/3.1/5.3/8.9 Hz, 2/1/0.6/0.3/0.15 mm.
Target AmbcTarget() { return MultiSine({0.6, 1.7, 3.1, 5.3, 8.9}, {2.0, 1.0, 0.6, 0.3, 0.15}, 0.9); }

/// A strictly proper test plant: y_k = A u_{k-D} (D >= 1), or the ZOH first-order lag
/// T y' = u - y, plus Gaussian measurement noise.
struct Plant {
  int delay = 0;          ///< D [samples]; 0: the lag
  double gain = 1.0;      ///< A
  double lag_s = 0.0;     ///< T [s]
  double noise_mm = 0.0;  ///< RMS of the measurement noise [mm]
};

class PlantState {
 public:
  PlantState(const Plant& p, double dt)
      : p_(p), past_(std::max(p.delay, 1), 0.0), alpha_(p.lag_s > 0 ? std::exp(-dt / p.lag_s) : 0.0),
        noise_(sig::MakeGaussian(7)) {}
  double Output() {
    const double y = p_.delay > 0 ? p_.gain * past_[head_] : x_;
    return p_.noise_mm > 0.0 ? y + p_.noise_mm * sig::NextGaussian(&noise_) : y;
  }
  void Input(double u) {
    if (p_.delay > 0) {
      past_[head_] = u;  // the oldest (u_{k-D}) replaced by u_k
      head_ = (head_ + 1) % p_.delay;
    }
    x_ = alpha_ * x_ + (1.0 - alpha_) * u;
  }

 private:
  Plant p_;
  std::vector<double> past_;
  std::size_t head_ = 0;
  double alpha_;
  double x_ = 0.0;
  sig::GaussianState noise_;
};

/// What a run did: the coefficients reported (adapt), the command and the tracking error.
struct Trace {
  std::array<double, 4> last{};       ///< adapt at the last step
  std::array<double, 4> tail_mean{};  ///< mean over the tail
  std::array<double, 4> lo{}, hi{};   ///< extremes over the run
  std::array<double, 4> max_change{};  ///< max |adapt_k - adapt_{k-1}|
  double max_abs_u = 0.0, max_abs_r = 0.0;
  double tail_nrms_pct = 0.0;  ///< Eq. 31 over the tail [%]
  bool finite = true;
};

class TraceBuilder {
 public:
  TraceBuilder(long steps, long tail) : steps_(steps), tail_(tail) {
    t_.lo.fill(std::numeric_limits<double>::infinity());
    t_.hi.fill(-std::numeric_limits<double>::infinity());
  }
  void Add(long k, const ctl::Command& c, double r, double y) {
    for (int i = 0; i < 4; ++i) {
      const double a = c.adapt[i];
      t_.finite = t_.finite && std::isfinite(a) && std::isfinite(c.u_mm);
      t_.lo[i] = std::min(t_.lo[i], a), t_.hi[i] = std::max(t_.hi[i], a);
      if (k > 0) t_.max_change[i] = std::max(t_.max_change[i], std::abs(a - t_.last[i]));
      if (k >= steps_ - tail_) t_.tail_mean[i] += a / tail_;
      t_.last[i] = a;
    }
    t_.max_abs_u = std::max(t_.max_abs_u, std::abs(c.u_mm));
    t_.max_abs_r = std::max(t_.max_abs_r, std::abs(r));
    if (k >= steps_ - tail_) e2_ += (r - y) * (r - y), r2_ += r * r;
  }
  Trace Done() {
    t_.tail_nrms_pct = 100.0 * std::sqrt(e2_ / r2_);
    return t_;
  }

 private:
  long steps_, tail_;
  Trace t_;
  double e2_ = 0.0, r2_ = 0.0;
};

/// A closed loop of a controller and a strictly proper plant for duration_s; derivatives by Eqs. 20-22.
Trace Run(ctl::TrackingController& c, const Plant& plant, const Target& r, double dt, double duration_s,
          double tail_s) {
  const long n = std::lround(duration_s / dt), tail = std::lround(tail_s / dt);
  PlantState p(plant, dt);
  ctl::ExtrapolationState past;
  TraceBuilder tb(n, tail);
  for (long k = 0; k < n; ++k) {
    const double rk = r(k * dt), y = p.Output();
    const ctl::Command cmd = c.Step(ctl::StepDerivatives(&past, rk, dt), {y, 0.0, 0.0});
    p.Input(cmd.u_mm);
    tb.Add(k, cmd, rk, y);
  }
  return tb.Done();
}

ctl::AtsConfig WideAts() {
  ctl::AtsConfig c;
  c.lower = {-10.0, -10.0, -10.0};
  c.upper = {10.0, 10.0, 10.0};
  c.max_rate_per_s = {1e9, 1e9, 1e9};
  return c;
}

ctl::AmbcConfig GivenAmbc(std::array<double, 4> initial) {
  ctl::AmbcConfig c;
  c.start = ctl::AmbcStart::kGiven;
  c.initial = initial;
  return c;
}


std::string KeyOf(const std::function<void()>& make) {
  try {
    make();
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find(e.where()) == 0);
    if (e.where() != "controller.model") CHECK(e.problem().find("allowed") != std::string::npos);
    return e.where();
  }
  return "(accepted)";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ATS

TEST_CASE("ats: the filter is c2d(butter(n, w_c, 's'), dt, 'zoh'): ZohTf of the expanded prototype, unit DC") {
  for (const int n : {1, 2, 3, 6}) {
    CAPTURE(n);
    const double wc = 2.0 * pi * 20.0;
    // The prototype's denominator from its poles w_c exp(j pi (2k + n - 1) / (2n)), k = 1..n (buttap).
    std::vector<std::complex<double>> poly{1.0};
    for (int k = 1; k <= n; ++k) {
      const std::complex<double> p = wc * std::exp(std::complex<double>(0.0, pi * (2 * k + n - 1) / (2.0 * n)));
      poly.push_back(0.0);
      for (std::size_t i = poly.size() - 1; i > 0; --i) poly[i] -= p * poly[i - 1];
    }
    ctl::TfChecked tf{{std::pow(wc, n)}, {}};
    for (const auto& v : poly) tf.den.push_back(v.real());
    const ctl::DiscreteTf expanded = ctl::ZohTf(tf, kAtsDt);
    const ctl::ZohButterworth f = ctl::MakeZohButterworth(n, 20.0, kAtsDt);
    for (const double hz : {0.0, 1.0, 5.0, 20.0, 60.0, 200.0}) {
      CAPTURE(hz);
      CHECK(std::abs(f.Response(hz) - expanded.Response(hz)) < 1e-7);  // the expanded polynomial's rounding: ~2e-9
    }
    CHECK(std::abs(f.Response(0.0) - 1.0) < 1e-12);
    CHECK(std::abs(std::abs(f.Response(20.0)) - std::sqrt(0.5)) < 0.01);  // -3 dB at the cutoff (ZOH: ~1e-3 off)
    // Strictly proper: the first input shows at the second output.
    ctl::ZohFilterState s;
    CHECK(ctl::ZohFilterOutput(f, s) == 0.0);
    ctl::ZohFilterUpdate(f, &s, 1.0);
    CHECK(ctl::ZohFilterOutput(f, s) > 0.0);
  }
}

TEST_CASE("ats: a plant whose inverse is in the family gives its coefficients to round-off") {
  // y_k solves u_k = c0 y_k + c1 D1 y_k + c2 D2 y_k (backward differences, y = 0 before the start), so
  // F(u) = c0 F(y) + c1 D1 F(y) + c2 D2 F(y) holds exactly (F linear, both from rest). The plant has
  // direct feedthrough: driven by the two halves of the step (u_k does not depend on y_k).
  const std::array<double, 3> c{1.05, 0.025, 3.0e-4};
  for (const double dt : {kAtsDt, kAmbcDt}) {
    CAPTURE(dt);
    const ctl::AtsDesign d = ctl::MakeAtsDesign(WideAts(), dt);
    ctl::AtsState s = ctl::AtsAtRest(d);
    const Target r = AtsTarget();
    ctl::ExtrapolationState past;
    const double g1 = c[1] / dt, g2 = c[2] / (dt * dt);
    double y1 = 0.0, y2 = 0.0;
    for (long k = 0; k < std::lround(10.0 / dt); ++k) {
      const ctl::Command cmd = ctl::AtsCommand(d, &s, ctl::StepDerivatives(&past, r(k * dt), dt));
      const double y = (cmd.u_mm + (g1 + 2.0 * g2) * y1 - g2 * y2) / (c[0] + g1 + g2);
      ctl::AtsUpdate(d, &s, y);
      y2 = y1, y1 = y;
    }
    CHECK(s.triggered);
    for (int i = 0; i < 3; ++i) CHECK(s.a[i] == doctest::Approx(c[i]).epsilon(1e-7));
  }
}

TEST_CASE("ats: gain and delay, first-order lag: a0 = 1/A, a1 = tau/A (Taylor), a1 = T + dt/2") {
  const Target r = AtsTarget();
  SUBCASE("gain 0.8, delay 10 samples at 1024 Hz (9.77 ms)") {
    ctl::AtsController c(ctl::MakeAtsDesign(WideAts(), kAtsDt));
    const Trace t = Run(c, {10, 0.8}, r, kAtsDt, 20.0, 5.0);
    const double tau = 10 * kAtsDt;
    MESSAGE("delay: a = ", t.last[0], " ", t.last[1], " ", t.last[2], " err ", t.tail_nrms_pct);
    CHECK(t.last[0] == doctest::Approx(1.0 / 0.8).epsilon(0.002));
    CHECK(t.last[1] == doctest::Approx(tau / 0.8).epsilon(0.03));
    CHECK(t.last[2] == doctest::Approx(tau * tau / 2.0 / 0.8).epsilon(0.25));
  }
  SUBCASE("lag T = 20 ms, at 1024 and 4096 Hz") {
    for (const double dt : {kAtsDt, kAmbcDt}) {
      CAPTURE(dt);
      ctl::AtsController c(ctl::MakeAtsDesign(WideAts(), dt));
      const Trace t = Run(c, {0, 1.0, 0.020}, r, dt, 20.0, 5.0);
      MESSAGE("lag: a = ", t.last[0], " ", t.last[1], " ", t.last[2], " err ", t.tail_nrms_pct);
      CHECK(t.last[0] == doctest::Approx(1.0).epsilon(1e-3));
      CHECK(std::abs(t.last[1] - (0.020 + dt / 2.0)) < 1e-4);
      CHECK(t.last[2] == doctest::Approx(0.020 * dt).epsilon(0.3));
    }
  }
}

TEST_CASE("ats: converges from wrong initial values (a1 = 0, a1 = 2 x 20 ms) to the same coefficients") {
  const Target r = AtsTarget();
  const Plant lag{0, 1.0, 0.020};
  ctl::AtsController right(ctl::MakeAtsDesign(WideAts(), kAtsDt));
  const Trace ref = Run(right, lag, r, kAtsDt, 20.0, 5.0);
  for (const double a1 : {0.0, 0.040}) {
    CAPTURE(a1);
    ctl::AtsConfig cfg = WideAts();
    cfg.initial = {1.0, a1, 0.0};
    ctl::AtsController c(ctl::MakeAtsDesign(cfg, kAtsDt));
    const Trace t = Run(c, lag, r, kAtsDt, 20.0, 5.0);
    for (int i = 0; i < 3; ++i) CHECK(t.last[i] == doctest::Approx(ref.last[i]).epsilon(1e-6));
    // Frozen at the wrong start (lower = upper = initial), the tracking is far worse.
    cfg.lower = cfg.upper = cfg.initial;
    ctl::AtsController frozen(ctl::MakeAtsDesign(cfg, kAtsDt));
    const Trace f = Run(frozen, lag, r, kAtsDt, 20.0, 5.0);
    MESSAGE("a1 start ", a1, ": tracking ", t.tail_nrms_pct, " % adaptive, ", f.tail_nrms_pct, " % frozen");
    CHECK(t.tail_nrms_pct < 0.2);
    CHECK(f.tail_nrms_pct > 10.0 * t.tail_nrms_pct);
  }
}

TEST_CASE("ats: bounded under measurement noise (0.016 mm RMS, 200 s, OpenFresco bounds)") {
  ctl::AtsConfig cfg;  // OpenFresco's bounds and rates
  for (const auto derivatives : {ctl::TargetDerivatives::kIntegrator, ctl::TargetDerivatives::kDifference}) {
    cfg.derivatives = derivatives;
    ctl::AtsController c(ctl::MakeAtsDesign(cfg, kAtsDt));
    const Trace t = Run(c, {20, 1.0, 0.0, 0.016}, AtsTarget(), kAtsDt, 200.0, 20.0);
    MESSAGE("noise: a = ", t.tail_mean[0], " ", t.tail_mean[1], " ", t.tail_mean[2], " |u| ", t.max_abs_u, " err ",
            t.tail_nrms_pct);
    CHECK(t.finite);
    for (int i = 0; i < 3; ++i) CHECK((t.lo[i] >= cfg.lower[i] && t.hi[i] <= cfg.upper[i]));
    CHECK(t.max_abs_u < 1.5 * t.max_abs_r);
    CHECK(t.tail_mean[1] == doctest::Approx(20 * kAtsDt).epsilon(0.1));  // still the delay
  }
}

TEST_CASE("ats: the rate limit and the bounds hold, and act") {
  const Target r = AtsTarget();
  const Plant delay{20, 1.0};  // tau = 19.5 ms
  ctl::AtsConfig cfg = WideAts();
  cfg.initial = {1.0, 0.0, 0.0};
  cfg.max_rate_per_s = {0.5, 0.005, 1e-4};  // a1 at most 5 ms per second
  ctl::AtsController slow(ctl::MakeAtsDesign(cfg, kAtsDt));
  const Trace s = Run(slow, delay, r, kAtsDt, 2.0, 1.0);
  for (int i = 0; i < 3; ++i) CHECK(s.max_change[i] <= cfg.max_rate_per_s[i] * kAtsDt * (1.0 + 1e-12));
  CHECK(s.max_change[1] == doctest::Approx(cfg.max_rate_per_s[1] * kAtsDt).epsilon(1e-9));  // it acted
  MESSAGE("rate-limited a1 after 2 s: ", s.last[1]);
  CHECK(s.last[1] > 0.005);         // on its way ...
  CHECK(s.last[1] <= 0.010 + 1e-12);  // ... at most 2 s x 5 ms/s, short of the 19.5 ms

  cfg = WideAts();
  cfg.lower[0] = 1.05;  // a0 -> 1 without it
  cfg.initial[0] = 1.1;
  cfg.upper[1] = 0.01;  // a1 -> 19.5 ms without it
  cfg.initial[1] = 0.005;
  ctl::AtsController bounded(ctl::MakeAtsDesign(cfg, kAtsDt));
  const Trace b = Run(bounded, delay, r, kAtsDt, 10.0, 1.0);
  CHECK(b.lo[0] >= 1.05);
  CHECK(b.last[0] == 1.05);
  CHECK(b.hi[1] <= 0.01);
  CHECK(b.last[1] == 0.01);
}

TEST_CASE("ats: the trigger holds the initial values until |F(y)| > threshold, then stays on") {
  ctl::AtsConfig cfg = WideAts();
  cfg.threshold_mm = 3.0;
  ctl::AtsController c(ctl::MakeAtsDesign(cfg, kAtsDt));
  const Target big = AtsTarget();
  const auto r = [&](double t) { return t < 8.0 ? big(t) : 0.1 * big(t); };  // below 3 mm after 8 s
  PlantState p({20, 1.0}, kAtsDt);
  ctl::ExtrapolationState past;
  long fired = -1, below_after = 0;
  for (long k = 0; k < std::lround(12.0 / kAtsDt); ++k) {
    const double rk = r(k * kAtsDt);
    const ctl::Command cmd = c.Step(ctl::StepDerivatives(&past, rk, kAtsDt), {p.Output()});
    p.Input(cmd.u_mm);
    const ctl::AtsState& s = c.state();
    if (!s.triggered) {
      REQUIRE(std::abs(s.yf_mm) <= 3.0);
      REQUIRE((cmd.adapt[0] == 1.0 && cmd.adapt[1] == 0.020 && cmd.adapt[2] == 2.0e-4));
    } else if (fired < 0) {
      fired = k;
      CHECK(std::abs(s.yf_mm) > 3.0);
    }
    if (k * kAtsDt > 10.0 && std::abs(s.yf_mm) < 3.0) ++below_after;
  }
  MESSAGE("trigger at ", fired * kAtsDt, " s; a1 at the end ", c.state().a[1]);
  CHECK(fired > std::lround(0.5 / kAtsDt));
  CHECK(c.state().triggered);
  CHECK(below_after == std::lround(2.0 / kAtsDt) - 1);          // all the last 2 s below the threshold
  CHECK(c.state().a[1] == doctest::Approx(0.0191).epsilon(0.02));  // still estimating, not back to 20 ms

  // threshold 0: the first non-zero F(y) triggers on an all-zero window: not solvable, initial values.
  cfg.threshold_mm = 0.0;
  const ctl::AtsDesign d = ctl::MakeAtsDesign(cfg, kAtsDt);
  ctl::AtsState s = ctl::AtsAtRest(d);
  long k = 0;
  for (; !s.triggered; ++k) {
    ctl::AtsCommand(d, &s, {big(k * kAtsDt)});
    ctl::AtsUpdate(d, &s, 1.0);
  }
  CHECK(k == 2);  // fired at step 1: F(y)_1 = C Gamma y_0 > 0, the window holds step 0 only (zeros)
  CHECK(s.fallback);
  CHECK(s.a == cfg.initial);
}

// ---------------------------------------------------------------------------------------------
// AMBC

namespace {

const std::array<double, 4> kRaInitial{1.000000015, 0.0198592, 8.44014e-5, 1.98592e-7};  // AmbcConfig's default
const std::array<double, 4> kThetaStar{1.02, 0.030, 2.0e-4, 1.0e-6};

/// The exact plant: y_k solves u_k = theta*^T [y, D1 y, D2 y, D3 y]_k (backward differences, y = 0
/// before the start; its poles are the backward-Euler images of a stable cubic's), run with the two
/// halves of the step (u_k does not depend on y_k). Returns the mean theta_s over the last 10 s.
std::array<double, 4> RunExactAmbc(const ctl::AmbcConfig& cfg, double duration_s, ctl::AmbcState* out = nullptr) {
  const double dt = kAmbcDt, dt2 = dt * dt, dt3 = dt2 * dt;
  const auto& a = kThetaStar;
  const double w0 = a[0] + a[1] / dt + a[2] / dt2 + a[3] / dt3, w1 = -a[1] / dt - 2.0 * a[2] / dt2 - 3.0 * a[3] / dt3,
               w2 = a[2] / dt2 + 3.0 * a[3] / dt3, w3 = -a[3] / dt3;
  const ctl::AmbcDesign d = ctl::MakeAmbcDesign(cfg, {}, dt);
  ctl::AmbcState s = ctl::AmbcAtRest(d);
  const Target r = AmbcTarget();
  ctl::ExtrapolationState past;
  double y1 = 0.0, y2 = 0.0, y3 = 0.0;
  const long n = std::lround(duration_s / dt), tail = std::lround(10.0 / dt);
  std::array<double, 4> mean{};
  for (long k = 0; k < n; ++k) {
    const ctl::Command c = ctl::AmbcCommand(d, &s, ctl::StepDerivatives(&past, r(k * dt), dt));
    const double y = (c.u_mm - w1 * y1 - w2 * y2 - w3 * y3) / w0;
    ctl::AmbcUpdate(d, &s, y);
    y3 = y2, y2 = y1, y1 = y;
    if (k >= n - tail) {
      for (int i = 0; i < 4; ++i) mean[i] += c.adapt[i] / tail;
    }
  }
  if (out) *out = s;
  return mean;
}

/// One step of the law by classical RK4 with phi, z held (the reference's ode4), for comparison.
void Rk4Step(const ctl::AmbcDesign& d, const std::array<double, 4>& phi, double z, std::array<double, 4>* th) {
  const auto f = [&](const std::array<double, 4>& t) {
    double m2 = 1.0, e = z;
    for (int i = 0; i < 4; ++i) m2 += phi[i] * phi[i], e -= std::clamp(t[i], d.config.lower[i], d.config.upper[i]) * phi[i];
    std::array<double, 4> out;
    for (int i = 0; i < 4; ++i) out[i] = d.gamma[i] * phi[i] * e / m2;
    return out;
  };
  const double h = d.dt_s;
  const auto add = [](std::array<double, 4> a, const std::array<double, 4>& b, double c) {
    for (int i = 0; i < 4; ++i) a[i] += c * b[i];
    return a;
  };
  const auto k1 = f(*th), k2 = f(add(*th, k1, h / 2)), k3 = f(add(*th, k2, h / 2)), k4 = f(add(*th, k3, h));
  for (int i = 0; i < 4; ++i) (*th)[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

}  // namespace

TEST_CASE("ambc: a plant whose inverse is in the family: theta -> theta* to 4 digits, eps -> 0") {
  ctl::AmbcState s;
  const std::array<double, 4> mean = RunExactAmbc(GivenAmbc(kRaInitial), 40.0, &s);
  MESSAGE("exact: theta = ", mean[0], " ", mean[1], " ", mean[2], " ", mean[3], " eps ", s.eps);
  for (int i = 0; i < 4; ++i) CHECK(mean[i] == doctest::Approx(kThetaStar[i]).epsilon(1e-4));
  CHECK(std::abs(s.eps) < 1e-9);
}

TEST_CASE("ambc: converges from wrong initial values (a1 = 0, a1 = 2 x 19.9 ms)") {
  for (const double a1 : {0.0, 2.0 * kRaInitial[1]}) {
    CAPTURE(a1);
    std::array<double, 4> start = kRaInitial;
    start[1] = a1;
    const std::array<double, 4> mean = RunExactAmbc(GivenAmbc(start), 60.0);
    MESSAGE("from a1 = ", a1, ": theta = ", mean[0], " ", mean[1], " ", mean[2], " ", mean[3]);
    for (int i = 0; i < 4; ++i) CHECK(mean[i] == doctest::Approx(kThetaStar[i]).epsilon(1e-4));
  }
}

TEST_CASE("ambc: first-order lag 20 ms: a0 -> 1, a1 -> T + dt/2; a3 saturates at 0 and its integrator winds up") {
  ctl::AmbcController c(ctl::MakeAmbcDesign(GivenAmbc(kRaInitial), {}, kAmbcDt));
  const Trace t = Run(c, {0, 1.0, 0.020}, AmbcTarget(), kAmbcDt, 40.0, 10.0);
  MESSAGE("lag: theta = ", t.tail_mean[0], " ", t.tail_mean[1], " ", t.tail_mean[2], " ", t.tail_mean[3], " err ",
          t.tail_nrms_pct, " theta3 state ", c.state().theta[3]);
  CHECK(t.tail_mean[0] == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(std::abs(t.tail_mean[1] - (0.020 + kAmbcDt / 2)) < 1e-4);
  CHECK(t.tail_mean[2] < 2e-5);
  CHECK(t.last[3] == 0.0);              // the bound a3 >= 0 holds ...
  CHECK(c.state().theta[3] < 0.0);      // ... on the output only
  CHECK(t.tail_nrms_pct < 0.05);
}

TEST_CASE("ambc: bounded under measurement noise (0.016 mm RMS, 200 s), on a delay and a lag") {
  for (const Plant& p : {Plant{80, 1.0, 0.0, 0.016}, Plant{0, 1.0, 0.020, 0.016}}) {
    CAPTURE(p.delay);
    ctl::AmbcController c(ctl::MakeAmbcDesign(GivenAmbc(kRaInitial), {}, kAmbcDt));
    const Trace t = Run(c, p, AmbcTarget(), kAmbcDt, 200.0, 20.0);
    MESSAGE("noise: theta = ", t.tail_mean[0], " ", t.tail_mean[1], " ", t.tail_mean[2], " ", t.tail_mean[3],
            " |u| ", t.max_abs_u, " err ", t.tail_nrms_pct);
    CHECK(t.finite);
    for (int i = 0; i < 4; ++i) CHECK(t.lo[i] >= 0.0);
    CHECK(t.max_abs_u < 1.5 * t.max_abs_r);
    CHECK(t.tail_mean[0] == doctest::Approx(1.0).epsilon(0.01));
    CHECK(t.tail_mean[1] == doctest::Approx(0.0195).epsilon(0.05));
  }
}

TEST_CASE("ambc: the upper bound saturates the coefficient used, not the integrator") {
  ctl::AmbcConfig cfg = GivenAmbc(kRaInitial);
  cfg.upper[1] = 0.015;  // a1 -> 20 ms without it
  cfg.initial[1] = 0.01;
  ctl::AmbcController c(ctl::MakeAmbcDesign(cfg, {}, kAmbcDt));
  const Trace t = Run(c, {0, 1.0, 0.020}, AmbcTarget(), kAmbcDt, 20.0, 5.0);
  CHECK(t.hi[1] <= 0.015);
  CHECK(t.last[1] == 0.015);
  CHECK(c.state().theta[1] > 0.015);
}

TEST_CASE("ambc: the exact flow of the law equals an RK4 step where RK4 is stable, and stays stable where it is not") {
  ctl::AmbcConfig cfg = GivenAmbc(kRaInitial);
  cfg.lower.fill(-std::numeric_limits<double>::infinity());  // no saturation: the linear law
  cfg.upper.fill(std::numeric_limits<double>::infinity());
  const ctl::AmbcDesign d = ctl::MakeAmbcDesign(cfg, {}, kAmbcDt);
  // 2 mm, 10 mm/s, 0.1 m/s^2, 1 m/s^3: mu dt = 0.28 (the level of the identification runs here); the two
  // differ by about (mu dt)^4 / 120 = 5e-5 relative in the change.
  const std::array<double, 4> phi{2e-3, 0.01, 0.1, 1.0};
  const double z = 1.01 * 2e-3 + 0.021 * 0.01 + 9e-5 * 0.1 + 2.1e-7 * 1.0;
  std::array<double, 4> exact = kRaInitial, rk4 = kRaInitial;
  ctl::IntegrateGradientLaw(d, phi, z, &exact);
  Rk4Step(d, phi, z, &rk4);
  for (int i = 0; i < 4; ++i) {
    CAPTURE(i);
    CHECK(exact[i] - kRaInitial[i] == doctest::Approx(rk4[i] - kRaInitial[i]).epsilon(1e-4));
  }
  // 20 mm held: mu dt = Gamma_0 phi_0^2 dt / (1 + phi_0^2) = 24.5: RK4 diverges, the exact flow settles
  // on the fixed point theta_0 = z / phi_0.
  const std::array<double, 4> big{0.02, 0.0, 0.0, 0.0};
  exact = rk4 = kRaInitial;
  for (int k = 0; k < 50; ++k) {
    ctl::IntegrateGradientLaw(d, big, 0.02 * 1.1, &exact);
    Rk4Step(d, big, 0.02 * 1.1, &rk4);
  }
  CHECK(exact[0] == doctest::Approx(1.1).epsilon(1e-12));
  CHECK(!(std::abs(rk4[0]) < 1e6));
  // In closed loop with the default gains and a slow 20 mm sine (mu dt ~ 25 near the peaks), the
  // controller still identifies the lag. (With RK4 steps in its place, theta_0 reaches 5 and ends at 0.)
  ctl::AmbcController c(ctl::MakeAmbcDesign(GivenAmbc(kRaInitial), {}, kAmbcDt));
  const Trace t = Run(c, {0, 1.0, 0.020}, MultiSine({0.3}, {20.0}, 0.0), kAmbcDt, 10.0, 1.0);
  CHECK(t.hi[0] < 1.01);
  CHECK(t.last[0] == doctest::Approx(1.0).epsilon(0.005));
  CHECK(t.last[1] == doctest::Approx(0.0201).epsilon(0.02));
}

// ---------------------------------------------------------------------------------------------
// Both: fixed coefficients, the factory, allocation, refusals

TEST_CASE("Linearize matches Step for fixed coefficients (ats before its trigger, ambc with Gamma = 0)") {
  const std::vector<double> r = sig::Blwn(20.0, 2.0, kAmbcDt, 4000, 11, 0.2);
  constexpr double kOff = -std::numeric_limits<double>::infinity();
  for (const auto derivatives : {ctl::TargetDerivatives::kIntegrator, ctl::TargetDerivatives::kDifference}) {
    CAPTURE(static_cast<int>(derivatives));
    ctl::AtsConfig ats;
    ats.threshold_mm = 1e9;  // never fires
    ats.derivatives = derivatives;
    ctl::AmbcConfig ambc = GivenAmbc(kRaInitial);
    ambc.gain_log10 = {kOff, kOff, kOff, kOff};
    ambc.derivatives = derivatives;
    ctl::AtsController c1(ctl::MakeAtsDesign(ats, kAmbcDt));
    ctl::AmbcController c2(ctl::MakeAmbcDesign(ambc, {}, kAmbcDt));
    for (ctl::TrackingController* c : {static_cast<ctl::TrackingController*>(&c1), static_cast<ctl::TrackingController*>(&c2)}) {
      const ctl::ControllerLti lti = c->Linearize(0.0);
      CHECK(!lti.has_feedback);
      const std::vector<double> expected = ctl::Simulate(lti.ff, r);
      ctl::ExtrapolationState past;
      double worst = 0.0, peak = 0.0;
      for (std::size_t k = 0; k < r.size(); ++k) {
        const ctl::Command cmd = c->Step(ctl::StepDerivatives(&past, r[k], kAmbcDt), {0.7 * r[k]});
        worst = std::max(worst, std::abs(cmd.u_mm - expected[k]));
        peak = std::max(peak, std::abs(cmd.u_mm));
      }
      CHECK(peak > 1.0);
      CHECK(worst < 1e-9 * peak);
    }
    CHECK(c1.state().a == ats.initial);
    CHECK(c2.state().theta == kRaInitial);
  }
}

TEST_CASE("ambc with start = \"model\", integrator derivatives and Gamma = 0 is the `ff` controller, bit for bit") {
  ctl::ControllerConfig cfg;
  cfg.model = rths::models::ServoPreset("avg");
  cfg.kind = ctl::ControllerKind::kAmbc;
  cfg.ambc.derivatives = ctl::TargetDerivatives::kIntegrator;
  constexpr double kOff = -std::numeric_limits<double>::infinity();
  cfg.ambc.gain_log10 = {kOff, kOff, kOff, kOff};
  auto ambc = ctl::MakeTrackingController(cfg, 0.0005);
  cfg.kind = ctl::ControllerKind::kFf;
  auto ff = ctl::MakeTrackingController(cfg, 0.0005);
  const ctl::FeedforwardCoefficients a = ctl::MakeFeedforwardCoefficients(cfg.model);
  const std::vector<double> r = sig::Blwn(20.0, 2.0, 0.0005, 2000, 3, 0.2);
  ctl::ExtrapolationState past;
  int equal = 0;
  for (double rk : r) {
    const ctl::Derivatives d = ctl::StepDerivatives(&past, rk, 0.0005);
    const ctl::Command c = ambc->Step(d, {0.5 * rk});
    equal += c.u_mm == ff->Step(d, {0.5 * rk}).u_mm;
    CHECK(c.n_adapt == 4);
    CHECK(c.adapt == std::array<double, 4>{a.a0, a.a1, a.a2, a.a3});
  }
  CHECK(equal == static_cast<int>(r.size()));
}

TEST_CASE("MakeTrackingController builds ats and ambc with their defaults; Step() allocates nothing") {
  const std::vector<double> r = sig::Blwn(10.0, 3.0, kAmbcDt, 8000, 5, 0.1);
  for (const auto kind : {ctl::ControllerKind::kAts, ctl::ControllerKind::kAmbc}) {
    for (const auto derivatives : {ctl::TargetDerivatives::kIntegrator, ctl::TargetDerivatives::kDifference}) {
      for (const double dt : {kAmbcDt, kAtsDt, 0.0005}) {
        CAPTURE(static_cast<int>(kind));
        CAPTURE(dt);
        ctl::ControllerConfig cfg;
        cfg.kind = kind;
        cfg.ats.derivatives = cfg.ambc.derivatives = derivatives;
        auto c = ctl::MakeTrackingController(cfg, dt);
        ctl::ExtrapolationState past;
        PlantState plant({0, 1.0, 0.015, 0.016}, dt);
        double sink = 0.0;
        int n_adapt = 0;
        const long before = rths_test::AllocationCount();
        for (double rk : r) {
          const ctl::Command cmd = c->Step(ctl::StepDerivatives(&past, rk, dt), {plant.Output(), 1.0, 0.0});
          plant.Input(cmd.u_mm);
          sink += cmd.u_mm + cmd.adapt[1];
          n_adapt = cmd.n_adapt;
        }
        CHECK(rths_test::AllocationCount() - before == 0);
        CHECK(std::isfinite(sink));
        CHECK(n_adapt == (kind == ctl::ControllerKind::kAts ? 3 : 4));
      }
    }
  }
}

TEST_CASE("refused configurations name the scenario key and the allowed range") {
  using A = ctl::AtsConfig;
  const auto ats = [](void (*edit)(A*), double dt = kAtsDt) {
    return KeyOf([=] {
      A c;
      edit(&c);
      ctl::MakeAtsDesign(c, dt);
    });
  };
  CHECK(ats([](A* c) { c->lower[1] = 0.1; }) == "controller.ats.lower");  // above upper (0.08)
  CHECK(ats([](A* c) { c->upper[2] = std::nan(""); }) == "controller.ats.upper");
  CHECK(ats([](A* c) { c->initial[0] = 1.5; }) == "controller.ats.initial");
  CHECK(ats([](A* c) { c->max_rate_per_s[1] = 0.0; }) == "controller.ats.max_rate_per_s");
  CHECK(ats([](A* c) { c->window_s = 0.03; }) == "controller.ats.window_s");  // 31 samples / 16: 2 points
  CHECK(ats([](A* c) { c->window_s = 0.04; }) == "(accepted)");              // 41 samples: 3 points
  CHECK(ats([](A* c) { c->window_s = -1.0; }) == "controller.ats.window_s");
  CHECK(ats([](A* c) { c->skip = 0; }) == "controller.ats.skip");
  CHECK(ats([](A* c) { c->filter_order = 9; }) == "controller.ats.filter_order");
  CHECK(ats([](A* c) { c->filter_hz = 512.0; }) == "controller.ats.filter_hz");  // Nyquist at 1024 Hz
  CHECK(ats([](A* c) { c->threshold_mm = -0.1; }) == "controller.ats.threshold_mm");
  CHECK(ats([](A*) {}, 0.0) == "run.dt_s");

  using B = ctl::AmbcConfig;
  const auto ambc = [](void (*edit)(B*), rths::models::ServoModel3 model = rths::models::ServoPreset("avg")) {
    return KeyOf([=] {
      B c;
      edit(&c);
      ctl::MakeAmbcDesign(c, model, kAmbcDt);
    });
  };
  CHECK(ambc([](B*) {}) == "(accepted)");
  CHECK(ambc([](B* c) { c->start = ctl::AmbcStart::kGiven; c->initial[2] = -1e-5; }) == "controller.ambc.initial");
  CHECK(ambc([](B* c) { c->start = ctl::AmbcStart::kGiven; c->initial[0] = INFINITY; }) == "controller.ambc.initial");
  CHECK(ambc([](B*) {}, {-1.0, 1.0, 1.0, 1.0, "bad"}) == "controller.model");
  CHECK(ambc([](B* c) { c->upper[0] = 0.5; }) == "controller.ambc.upper");  // the model's a0 = 1/0.99407 above it
  CHECK(ambc([](B* c) { c->lower[3] = 2.0; c->upper[3] = 1.0; }) == "controller.ambc.lower");
  CHECK(ambc([](B* c) { c->lower[1] = std::nan(""); }) == "controller.ambc.lower");
  CHECK(ambc([](B* c) { c->upper[1] = -INFINITY; }) == "controller.ambc.upper");
  CHECK(ambc([](B* c) { c->gain_log10[0] = 31.0; }) == "controller.ambc.gain_log10");
  CHECK(ambc([](B* c) { c->gain_log10[0] = std::nan(""); }) == "controller.ambc.gain_log10");
  CHECK(ambc([](B* c) { c->filter_order = 0; }) == "controller.ambc.filter_order");
  CHECK(ambc([](B* c) { c->filter_hz = 2048.0; }) == "controller.ambc.filter_hz");

  ctl::ControllerConfig cfg;  // through the factory
  cfg.kind = ctl::ControllerKind::kAts;
  cfg.ats.skip = -3;
  CHECK(KeyOf([&] { ctl::MakeTrackingController(cfg, kAtsDt); }) == "controller.ats.skip");
}

TEST_CASE("scenario keys: [controller.ats] and [controller.ambc] read, written back, refused with the file and key") {
  const std::string base = R"(
[run]
dt_s = 0.000244140625
duration_s = 1.0
[controller]
kind = "ats"
[controller.ats]
initial = [1.0, 0.025, 3e-4]
upper = [1.2, 0.05, 0.003]
window_s = 0.5
derivatives = "difference"
[controller.ambc]
start = "given"
gain_log10 = [7, 5, 2, 1]
)";
  auto error_of = [](const std::string& text) { return rths_test::ParseError(text); };
  REQUIRE(error_of(base).empty());
  const rths::scenario::Scenario s = rths::scenario::ParseScenario(base, "x.toml");
  CHECK(s.controller.ats.initial == std::array<double, 3>{1.0, 0.025, 3e-4});
  CHECK(s.controller.ats.upper[1] == 0.05);
  CHECK(s.controller.ats.lower == rths::control::AtsConfig{}.lower);  // default kept
  CHECK(s.controller.ats.derivatives == rths::control::TargetDerivatives::kDifference);
  CHECK(s.controller.ambc.start == rths::control::AmbcStart::kGiven);
  CHECK(s.controller.ambc.gain_log10 == std::array<double, 4>{7, 5, 2, 1});
  const rths::scenario::Scenario back = rths::scenario::ParseScenario(rths::scenario::ToToml(s), "y.toml");
  CHECK(back.controller.ats == s.controller.ats);
  CHECK(back.controller.ambc == s.controller.ambc);

  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  // The design's checks across keys, named with the file.
  CHECK(error_of(with("initial = [1.0, 0.025, 3e-4]", "initial = [1.0, 0.09, 3e-4]")).find("x.toml: controller.ats.initial") == 0);
  CHECK(error_of(with("window_s = 0.5", "window_s = 0.001")).find("x.toml: controller.ats.window_s") == 0);
  // Per-key ranges and shapes.
  CHECK(error_of(with("upper = [1.2, 0.05, 0.003]", "upper = [1.2, 0.05]")).find("x.toml: controller.ats.upper: 2 values: expected 3") == 0);
  CHECK(error_of(with("upper = [1.2, 0.05, 0.003]", "upper = [1.2, \"a\", 0.003]")).find("x.toml: controller.ats.upper: element 2") == 0);
  CHECK(error_of(with("gain_log10 = [7, 5, 2, 1]", "gain_log10 = [7, 50, 2, 1]")).find("x.toml: controller.ambc.gain_log10[1]: 50 is out of range") == 0);
  CHECK(error_of(with("derivatives = \"difference\"", "derivatives = \"spline\"")).find("x.toml: controller.ats.derivatives") == 0);
  // ambc's design is checked when it is the kind: start "model" needs a model inside its bounds.
  std::string ambc = with("kind = \"ats\"", "kind = \"ambc\"");
  CHECK(error_of(ambc).empty());
  CHECK(error_of(ambc + "lower = [2.0, 0, 0, 0]\n").find("x.toml: controller.ambc.") == 0);
}
