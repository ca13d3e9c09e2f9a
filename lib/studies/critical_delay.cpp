// The critical delay of an RTHS loop (studies/critical_delay.h, docs/reproduce_nonlinear.md).
#include "studies/critical_delay.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <numbers>

#include <fmt/format.h>

#include "control/baselines.h"
#include "control/tracking_controller.h"
#include "core/error.h"
#include "models/structure_integrator.h"

namespace rths::studies {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// The real root of x^3 + 3 x^2 + 6 x + 6 (the cubic Taylor polynomial of e^x times 6), by Newton.
double TaylorCubicRealRoot() {
  double x = -1.6;
  for (int i = 0; i < 50; ++i) x -= (((x + 3.0) * x + 6.0) * x + 6.0) / ((3.0 * x + 6.0) * x + 6.0);
  return x;
}

/// The tracking controller of a compensation designed for tau_s (none at tau = 0: nothing to do).
std::unique_ptr<control::TrackingController> MakeCompensator(DelayCompensation c, double tau_s, double dt_s) {
  if (c == DelayCompensation::kNone || tau_s <= 0.0) return std::make_unique<control::NoCompensation>(dt_s);
  if (c == DelayCompensation::kPoly3) {
    return std::make_unique<control::PolynomialExtrapolation>(control::MakePoly3(tau_s, dt_s), dt_s);
  }
  if (c == DelayCompensation::kLead) {
    return std::make_unique<control::LeadCompensator>(control::MakeLead(tau_s, kDelayLeadTpS, dt_s), dt_s);
  }
  return std::make_unique<control::ModelFeedforward>(TaylorDelayModel(tau_s), false, dt_s);
}

}  // namespace

double SplitSdof::TotalStiffness_kN_per_mm() const {
  const double w = kTwoPi * frequency_hz;
  return Mass_kN_s2_per_mm() * w * w;
}

double SplitSdof::Damping_kN_s_per_mm() const { return 2.0 * damping_ratio * Mass_kN_s2_per_mm() * kTwoPi * frequency_hz; }

void SplitSdof::Validate() const {
  if (!(mass_kg > 0.0 && std::isfinite(mass_kg))) throw Error("mass_kg", fmt::format("must be > 0 (got {})", mass_kg));
  if (!(frequency_hz > 0.0 && std::isfinite(frequency_hz)))
    throw Error("frequency_hz", fmt::format("must be > 0 (got {})", frequency_hz));
  if (!(damping_ratio >= 0.0 && damping_ratio < 1.0))
    throw Error("damping_ratio", fmt::format("must be in [0, 1) (got {})", damping_ratio));
  if (!(physical_fraction > 0.0 && physical_fraction < 1.0))
    throw Error("physical_fraction", fmt::format("must be in (0, 1) (got {})", physical_fraction));
}

models::NonlinearBuilding NumericalSubstructure(const SplitSdof& s) {
  s.Validate();
  models::SpringParams spring = s.spring;
  spring.k_kN_per_mm = s.NumericalStiffness_kN_per_mm();
  Eigen::MatrixXd C(1, 1);
  C(0, 0) = s.Damping_kN_s_per_mm();
  return models::NonlinearBuilding::Make({s.mass_kg}, {spring}, C, 0, 1.0);
}

models::ServoModel3 TaylorDelayModel(double tau_s) {
  if (!(tau_s > 0.0 && std::isfinite(tau_s))) throw Error("tau_s", fmt::format("must be > 0 (got {})", tau_s));
  static const double x0 = TaylorCubicRealRoot();
  models::ServoModel3 m;
  m.p = -x0 / tau_s;
  m.b = 3.0 / tau_s - m.p;
  m.K = 6.0 / (tau_s * tau_s * tau_s);
  m.c = m.K / m.p;
  m.name = "custom";
  return m;
}

DelayRun RunDelayLoop(const DelayLoop& loop, double tau_s, double bound_mm) {
  if (!(tau_s >= 0.0 && std::isfinite(tau_s))) throw Error("tau_s", fmt::format("must be >= 0 (got {})", tau_s));
  if (!(loop.tail_s > 0.0)) throw Error("tail_s", fmt::format("must be > 0 (got {})", loop.tail_s));
  const models::NonlinearBuilding b = NumericalSubstructure(loop.sdof);
  const models::StructureIntegrator integ = models::StructureIntegrator::Make(b, loop.dt_s, loop.integrator);
  models::IntegratorState s = models::MakeIntegratorState(b);
  const auto law = MakeCompensator(loop.compensation, tau_s, loop.dt_s);
  control::ExtrapolationState past;

  const std::size_t n_record = loop.ground_mm_s2.size();
  const auto n_tail = static_cast<std::size_t>(std::llround(loop.tail_s / loop.dt_s));
  const std::size_t n = n_record + n_tail;
  const std::size_t early0 = n_record + n_tail / 4, early1 = n_record + n_tail / 2;
  const std::size_t late0 = n_record + 3 * n_tail / 4;
  auto ground = [&](std::size_t k) { return k < n_record ? loop.ground_mm_s2[k] : 0.0; };
  const double k_e = loop.sdof.PhysicalStiffness_kN_per_mm();
  const double x_y = loop.sdof.spring.kind == models::SpringKind::kLinear ? 0.0 : loop.sdof.spring.YieldDisplacement();
  const double lag = tau_s / loop.dt_s;  // the delay in samples

  std::vector<double> u(n, 0.0);  // commands u_k [mm]
  double early_lo = std::numeric_limits<double>::infinity(), early_hi = -early_lo;
  double late_lo = early_lo, late_hi = -early_lo;
  DelayRun out;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = s.x(0);
    if (!std::isfinite(r) || (bound_mm > 0.0 && std::abs(r) > bound_mm)) {
      out.diverged = true;
      break;
    }
    out.peak_mm = std::max(out.peak_mm, std::abs(r));
    if (x_y > 0.0) out.peak_ductility = std::max(out.peak_ductility, std::abs(r) / x_y);
    if (k >= early0 && k < early1) {
      early_lo = std::min(early_lo, r);
      early_hi = std::max(early_hi, r);
    } else if (k >= late0) {
      late_lo = std::min(late_lo, r);
      late_hi = std::max(late_hi, r);
    }
    u[k] = law->Step(control::StepDerivatives(&past, r, loop.dt_s), {}).u_mm;
    // y_k = u(t_k - tau), u linear between samples and 0 before t = 0.
    const double t = static_cast<double>(k) - lag;
    double y = 0.0;
    if (t > -1.0) {
      const double j = std::floor(t);
      const double phi = t - j;
      const auto at = [&](double i) { return i < 0.0 ? 0.0 : u[static_cast<std::size_t>(i)]; };
      y = phi > 0.0 ? (1.0 - phi) * at(j) + phi * at(j + 1.0) : at(j);
    }
    models::Advance(integ, &s, ground(k), ground(k + 1), k_e * y);
    out.steps = static_cast<long>(k) + 1;
  }
  if (!out.diverged) {
    out.tail_early_range_mm = early_hi - early_lo;
    out.tail_late_range_mm = late_hi - late_lo;
  }
  return out;
}

namespace {
bool Decays(const DelayRun& r, const DelaySearch& search) {
  return !r.diverged && r.tail_late_range_mm < search.decay_ratio * r.tail_early_range_mm;
}
}  // namespace

bool Unstable(const DelayRun& r, const DelaySearch& search) {
  return search.criterion == DelayCriterion::kDivergence ? r.diverged : !Decays(r, search);
}

std::string Verdict(const DelayRun& r, const DelaySearch& search) {
  if (r.diverged) return "diverged";
  return Decays(r, search) ? "decays" : "does not decay";
}

CriticalDelay FindCriticalDelay(const DelayLoop& loop, const DelaySearch& search) {
  CriticalDelay cd;
  const DelayRun free = RunDelayLoop(loop, 0.0, 0.0);
  cd.runs = 1;
  cd.delay_free_peak_mm = free.peak_mm;
  cd.delay_free_ductility = free.peak_ductility;
  if (Unstable(free, search)) {
    throw Error("critical delay", fmt::format("the delay-free loop is unstable ({})", Verdict(free, search)));
  }
  const double bound = search.divergence_factor * free.peak_mm;
  auto unstable = [&](double tau, std::string* verdict) {
    const DelayRun r = RunDelayLoop(loop, tau, bound);
    ++cd.runs;
    if (verdict) *verdict = Verdict(r, search);
    return Unstable(r, search);
  };
  // Scan up from 0 to the first unstable delay.
  double lo = 0.0, hi = 0.0;
  std::string verdict;
  for (double tau = search.scan_step_s;; tau += std::max(search.scan_step_s, search.scan_growth * tau)) {
    tau = std::min(tau, search.max_delay_s);
    if (unstable(tau, &verdict)) {
      hi = tau;
      cd.found = true;
      break;
    }
    lo = tau;
    if (tau >= search.max_delay_s) break;
  }
  cd.stable_s = lo;
  if (!cd.found) {
    cd.tau_s = search.max_delay_s;
    return cd;
  }
  while (hi - lo > search.resolution_s) {
    const double mid = 0.5 * (lo + hi);
    std::string v;
    if (unstable(mid, &v)) {
      hi = mid;
      verdict = v;
    } else {
      lo = mid;
    }
  }
  cd.stable_s = lo;
  cd.unstable_s = hi;
  cd.verdict = verdict;
  cd.tau_s = 0.5 * (lo + hi);
  return cd;
}

DelayMargin ContinuousDelayMargin(double m, double c, double k_n, double k_e) {
  if (!(m > 0.0) || c < 0.0 || k_n < 0.0 || k_e < 0.0)
    throw Error("delay margin", fmt::format("needs m > 0, c, k_n, k_e >= 0 (got {}, {}, {}, {})", m, c, k_n, k_e));
  DelayMargin d;
  d.negative_damping_s = k_e > 0.0 ? c / k_e : std::numeric_limits<double>::infinity();
  // |k_n - m w^2 + i c w|^2 = k_e^2:  m^2 W^2 + (c^2 - 2 k_n m) W + k_n^2 - k_e^2 = 0,  W = w^2.
  const double qa = m * m, qb = c * c - 2.0 * k_n * m, qc = k_n * k_n - k_e * k_e;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return d;
  const double sq = std::sqrt(disc);
  double best = std::numeric_limits<double>::infinity(), best_w = 0.0;
  for (double W : {(-qb + sq) / (2.0 * qa), (-qb - sq) / (2.0 * qa)}) {
    if (!(W > 0.0)) continue;
    const double w = std::sqrt(W);
    // k_n - m w^2 + i c w = -k_e e^{-i w tau} = k_e e^{i (pi - w tau)}.
    double phase = std::numbers::pi - std::arg(std::complex<double>(k_n - m * W, c * w));
    phase = std::fmod(phase, kTwoPi);
    if (phase < 0.0) phase += kTwoPi;
    const double tau = phase / w;
    if (tau < best) {
      best = tau;
      best_w = w;
    }
  }
  if (!std::isfinite(best)) return d;
  d.exists = true;
  d.tau_s = best;
  d.crossing_hz = best_w / kTwoPi;
  return d;
}

}  // namespace rths::studies
