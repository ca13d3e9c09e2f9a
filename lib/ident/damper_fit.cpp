#include "ident/damper_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"
#include "ident/bouc_wen_rk4.h"
#include "ident/lm.h"
#include "ident/plausible_range.h"
#include "signal/derivative.h"
#include "signal/metrics.h"
#include "signal/spectral.h"
#include "signal/zero_phase.h"

namespace rths::ident {

namespace {

constexpr int kNonlinear = 6;  // ln alpha, ln c0, ln c1, ln k0, ln beta, ln gamma
constexpr double kInf = std::numeric_limits<double>::infinity();
// Most substeps per sample a trial of the fit may need (Evaluate); the search refuses stiffer ones.
constexpr int kMaxFitSubsteps = 64;

// Bounds of the nonlinear parameters (natural units: kN/mm, kN s/mm, kN s/mm, kN/mm, 1/mm^2,
// 1/mm^2), in the order of theta.
constexpr std::array<double, kNonlinear> kLo = {1e-7, 1e-7, 1e-7, 1e-8, 1e-9, 1e-9};
constexpr std::array<double, kNonlinear> kHi = {1e2, 1e2, 1e3, 1e2, 1e4, 1e4};

using Theta = Eigen::Matrix<double, kNonlinear, 1>;

// One record prepared for the fit: x, v, f and its weight 1 / sum f^2.
struct Prepared {
  const io::RigRecord* rec;
  std::vector<double> v;
  double weight;
  double vmax;
};

models::MrDamperCoefficients FromTheta(const Theta& th, double A, double k1, double x0) {
  models::MrDamperCoefficients k{};
  k.alpha = std::exp(th[0]);
  k.c0 = std::exp(th[1]);
  k.c1 = std::exp(th[2]);
  k.k0 = std::exp(th[3]);
  k.beta = std::exp(th[4]);
  k.gamma = std::exp(th[5]);
  k.A = A;
  k.n = 2.0;
  k.k1 = k1;
  k.x0 = x0;
  return k;
}

// The parameters' names in the model file, in the order of theta.
constexpr std::array<const char*, kNonlinear> kNames = {"alpha", "c0", "c1", "k0", "beta", "gamma"};

// The box in theta: ln of the bounds, a point for a parameter held by DamperFitOptions::hold.
using Box = LmBox<Theta>;
Box MakeBox(const DamperFitOptions& o) {
  Box box(
      kNonlinear, [](int i) { return std::log(kLo[static_cast<std::size_t>(i)]); },
      [](int i) { return std::log(kHi[static_cast<std::size_t>(i)]); });
  const std::vector<std::string> names(kNames.begin(), kNames.end());
  const std::vector<double> l(kLo.begin(), kLo.end()), h(kHi.begin(), kHi.end());
  for (const auto& held : o.hold)
    box.Hold(HeldIndex(held, names, l, h), std::log(held.second), fmt::format("held at {:g} by --hold", held.second));
  return box;
}

// The model at theta on every record: residuals r = sqrt(w_r) (f - F) stacked, with k1 and
// b = -k1 x0 solved by weighted linear least squares (file comment of damper_fit.h).
struct Evaluation {
  Eigen::VectorXd r;
  double cost = kInf;
  double k1 = 0.0, x0 = 0.0, offset = 0.0;
};

Evaluation Evaluate(const Theta& th, const std::vector<Prepared>& data, double A, int substeps_fixed) {
  Evaluation ev;
  std::size_t total = 0;
  for (const auto& p : data) total += p.rec->size();
  const auto k = FromTheta(th, A, 0.0, 0.0);
  std::vector<std::vector<double>> fnl(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto& d = data[i];
    const int m = substeps_fixed > 0 ? substeps_fixed : DamperSubsteps(k, d.rec->dt_s, d.vmax);
    // A trial this stiff is refused rather than integrated (it cost minutes at 3 kHz: thousands of
    // substeps per sample for a step the search rejects anyway).
    if (m > kMaxFitSubsteps) return ev;  // cost = inf
    fnl[i] = SimulateDamperForce(k, d.rec->y_mm, d.v, d.rec->dt_s, m);
    for (double f : fnl[i])
      if (!std::isfinite(f)) return ev;  // cost = inf
  }
  // k1, x0 and the offset by weighted least squares (LinearTerms).
  LinearTerms sums;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto& d = data[i];
    for (std::size_t j = 0; j < d.rec->size(); ++j) sums.Add(d.weight, d.rec->y_mm[j], d.rec->f_kN[j] - fnl[i][j]);
  }
  const auto lin = sums.Solve();
  ev.k1 = lin.k1;
  ev.x0 = lin.x0;
  ev.offset = lin.offset_kN;
  ev.r.resize(static_cast<Eigen::Index>(total));
  Eigen::Index row = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto& d = data[i];
    const double sw = std::sqrt(d.weight);
    for (std::size_t j = 0; j < d.rec->size(); ++j)
      ev.r[row++] = sw * (d.rec->f_kN[j] - fnl[i][j] - lin.At(d.rec->y_mm[j]));
  }
  ev.cost = ev.r.squaredNorm();
  if (!std::isfinite(ev.cost)) ev.cost = kInf;
  return ev;
}

// Substeps of every record at theta (the Jacobian keeps them fixed so that the finite
// differences see a smooth function).
int MaxSubsteps(const Theta& th, const std::vector<Prepared>& data, double A) {
  const auto k = FromTheta(th, A, 0.0, 0.0);
  int m = 1;
  for (const auto& d : data) m = std::max(m, DamperSubsteps(k, d.rec->dt_s, d.vmax));
  return m;
}

using State = LmState<Theta, Evaluation>;

// Levenberg-Marquardt iterations on theta (lm.h), the Jacobian at the base point's substeps.
void Iterate(State* s, const std::vector<Prepared>& data, double A, const Box& box, int iterations) {
  int m = 1;  // substeps of the base point, kept by its Jacobian's columns
  LmIterate(
      s, box, iterations,
      [&](const Theta& t) {
        m = MaxSubsteps(t, data, A);
        return Evaluate(t, data, A, m);
      },
      [&](const Theta& t, const Evaluation&, int) { return Evaluate(t, data, A, m); },
      [&](const Theta& t) { return Evaluate(t, data, A, 0); }, 1e-7, 1e-6);
}

}  // namespace

std::vector<double> SmoothVelocity(std::span<const double> x, double dt, double cutoff_hz) {
  const std::size_t n = x.size();
  if (n < 3) throw Error("SmoothVelocity", fmt::format("{} samples: need at least 3", n));
  if (!(dt > 0.0)) throw Error("SmoothVelocity", fmt::format("dt_s = {}: must be > 0", dt));
  if (!(cutoff_hz > 0.0)) throw Error("SmoothVelocity", fmt::format("cutoff_hz = {}: must be > 0", cutoff_hz));
  const std::vector<double> d = signal::Derivative(x, dt);
  const double fs = 1.0 / dt;
  const double fc = std::min(cutoff_hz, 0.45 * fs);
  // Odd reflection about both ends, about 3 time constants of the filter (at least 12 samples);
  // each pass starts at its first value's steady state.
  const std::size_t pad = std::min<std::size_t>(n - 1, std::max<std::size_t>(12, static_cast<std::size_t>(3.0 * fs / fc)));
  return signal::ZeroPhaseLowpass(d, dt, fc, 4, pad, signal::Reflection::kOdd, signal::FilterStart::kSteadyState);
}

double VelocityCutoffHz(const io::RigRecord& rec) {
  const double fs = 1.0 / rec.dt_s, top = 0.45 * fs;
  const std::size_t n = rec.size();
  if (n < 64) return std::min(50.0, top);
  std::size_t L = 1;
  while (L * 2 <= std::min<std::size_t>(n / 4, static_cast<std::size_t>(2.0 * fs))) L *= 2;
  L = std::max<std::size_t>(L, 32);
  const auto psd = signal::WelchPsd(rec.y_mm, rec.dt_s, L);
  const std::size_t m = psd.size();
  std::vector<double> hi(psd.begin() + static_cast<std::ptrdiff_t>(m * 4 / 5), psd.end());
  std::nth_element(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(hi.size() / 2), hi.end());
  const double floor = hi.empty() ? 0.0 : hi[hi.size() / 2];
  // Velocity density of the signal: (2 pi f)^2 (S_y - floor) where S_y stands clear of the floor
  // (10 x: a Welch estimate of noise alone scatters by far less), 0 elsewhere; the constant
  // factor drops out.
  auto vel = [&](std::size_t i) {
    return psd[i] > 10.0 * floor ? static_cast<double>(i) * static_cast<double>(i) * (psd[i] - floor) : 0.0;
  };
  double total = 0.0;
  for (std::size_t i = 1; i < m; ++i) total += vel(i);
  double edge = 0.0, cum = 0.0;
  for (std::size_t i = 1; i < m && total > 0.0; ++i) {
    cum += vel(i);
    if (cum >= 0.999 * total) {
      edge = static_cast<double>(i) * fs / static_cast<double>(L);
      break;
    }
  }
  return std::clamp(4.0 * edge, std::min(50.0, top), top);
}

std::string TomlFloat(double v) {
  std::string s = fmt::format("{:.10g}", v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

int DamperSubsteps(const models::MrDamperCoefficients& k, double dt, double vmax) {
  const double lambda =
      BoucWenRateBound(k.A, std::max(k.beta + k.gamma, 0.0), std::abs(vmax), (k.A * k.alpha + k.k0) / (k.c0 + k.c1));
  if (!std::isfinite(lambda)) return 4000;
  const double m = SubstepsFor(dt, lambda);
  return static_cast<int>(std::clamp(m, 1.0, 4000.0));
}

std::vector<double> SimulateDamperForce(const models::MrDamperCoefficients& k, std::span<const double> x,
                                        std::span<const double> v, double dt, int substeps) {
  if (x.size() != v.size())
    throw Error("SimulateDamperForce", fmt::format("x has {} samples, v {}", x.size(), v.size()));
  const std::size_t n = x.size();
  std::vector<double> f(n, std::numeric_limits<double>::quiet_NaN());
  if (n == 0) return f;
  if (substeps <= 0) {
    double vmax = 0.0;
    for (double vi : v) vmax = std::max(vmax, std::abs(vi));
    substeps = DamperSubsteps(k, dt, vmax);
  }
  models::MrDamperState s{x[0], 0.0};
  for (std::size_t j = 0; j < n; ++j) {
    f[j] = models::DamperForceKn(k, s, x[j], v[j]);
    if (!std::isfinite(f[j]) || !std::isfinite(s.y_mm) || !std::isfinite(s.z_mm)) {
      f[j] = std::numeric_limits<double>::quiet_NaN();
      return f;
    }
    if (j + 1 == n) break;
    const double dx = x[j + 1] - x[j], dv = v[j + 1] - v[j];
    Rk4Substeps(substeps, dt, &s.y_mm, &s.z_mm, [&](double a, double y, double z, double* ydot, double* zdot) {
      const auto r = models::DamperRates(k, {y, z}, x[j] + a * dx, v[j] + a * dv);
      *ydot = r.ydot_mm_s;
      *zdot = r.zdot_mm_s;
    });
  }
  return f;
}

std::string RecordName(const io::RigRecord& record) { return record.source.empty() ? "record" : record.source; }

void CheckDamperColumns(const io::RigRecord& rec) {
  if (rec.size() < 3 || rec.f_kN.size() != rec.size() || rec.y_mm.size() != rec.size())
    throw Error(RecordName(rec), "too few samples or columns of different lengths");
}

double ForceWeight(const io::RigRecord& rec) {
  double sf = 0.0;
  for (std::size_t k = 0; k < rec.size(); ++k) sf += rec.f_kN[k] * rec.f_kN[k];
  if (!(sf > 0.0)) throw Error(RecordName(rec), "the force f_kN is zero throughout: nothing to fit");
  return 1.0 / sf;
}

double PeakForce(const std::vector<io::RigRecord>& records) {
  double fpeak = 0.0;
  for (const auto& rec : records)
    for (double f : rec.f_kN) fpeak = std::max(fpeak, std::abs(f));
  return fpeak;
}

DamperRecordScore ScoreForce(const io::RigRecord& rec, std::span<const double> F, double velocity_cutoff_hz) {
  DamperRecordScore s;
  s.source = rec.source;
  s.samples = rec.size();
  s.dt_s = rec.dt_s;
  s.velocity_cutoff_hz = velocity_cutoff_hz;
  signal::RmsErrorAccumulator eq31;  // Eq. 31 with f in the role of r
  for (std::size_t k = 0; k < rec.size(); ++k) {
    eq31.Add(rec.f_kN[k], F[k]);
    s.peak_force_kN = std::max(s.peak_force_kN, std::abs(rec.f_kN[k]));
  }
  s.nrmse_f_pct = eq31.Percent();
  if (!std::isfinite(eq31.sum_error2)) s.nrmse_f_pct = std::numeric_limits<double>::infinity();
  return s;
}

std::vector<double> PredictDamperForce(const models::MrDamperCoefficients& coef, const io::RigRecord& rec,
                                       double velocity_cutoff_hz, double force_offset_kN) {
  const double cutoff = velocity_cutoff_hz > 0.0 ? velocity_cutoff_hz : VelocityCutoffHz(rec);
  auto F = SimulateDamperForce(coef, rec.y_mm, SmoothVelocity(rec.y_mm, rec.dt_s, cutoff), rec.dt_s);
  for (double& f : F) f += force_offset_kN;
  return F;
}

DamperRecordScore ScoreDamper(const models::MrDamperCoefficients& coef, const io::RigRecord& rec,
                              double velocity_cutoff_hz, double force_offset_kN) {
  const double cutoff = velocity_cutoff_hz > 0.0 ? velocity_cutoff_hz : VelocityCutoffHz(rec);
  return ScoreForce(rec, PredictDamperForce(coef, rec, cutoff, force_offset_kN), cutoff);
}

LinearTerms::Solution LinearTerms::Solve() const {
  Solution out;
  const double det = sxx * s1 - sx * sx;
  if (det > 1e-12 * sxx * s1) {
    const double k1 = (sxe * s1 - sx * se) / det, b = (sxx * se - sx * sxe) / det;
    if (k1 > 0.0) {  // an accumulator: k1 (x - x0) carries the constant too
      out.k1 = k1;
      out.x0 = -b / k1;
      return out;
    }
  }
  out.offset_kN = s1 > 0.0 ? se / s1 : 0.0;  // k1 = 0: the constant alone
  return out;
}

std::string ForceOffsetComment(double offset_kN) {
  if (offset_kN == 0.0) return "";
  return fmt::format(
      "# Force offset {:.6g} kN: the load cell's zero on the training records, fitted as a constant because\n"
      "# k1 came out 0 (k1 (x - x0) cannot carry it then). Not part of the damper model: a run does not add\n"
      "# it; the errors above include it ([fit] force_offset_kN).\n",
      offset_kN);
}

std::string ForceOffsetKey(double offset_kN) {
  return offset_kN == 0.0 ? "" : fmt::format("force_offset_kN = {}\n", TomlFloat(offset_kN));
}

namespace {

constexpr int kStartIterations = 6;  ///< LM iterations per start (DamperFitOptions::start_iterations unset)
constexpr int kMaxIterations = 200;  ///< ... for the best start (max_iterations unset)

/// Sums of the rough yield-force / viscous fit f ~ F_y sgn(v) + c v over every record, weighted.
struct RoughSums {
  double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
};

/// Throws rths::Error naming the record if a sample's current differs from current_A by more
/// than the tolerance.
void CheckOneCurrent(const io::RigRecord& rec, double current_A, double tolerance_A) {
  const auto& command = rec.Command();  // i_A, or v_V of a voltage-only record
  for (std::size_t k = 0; k < command.size(); ++k) {
    if (std::abs(command[k] - current_A) > tolerance_A)
      throw Error(RecordName(rec), fmt::format("sample {} (t = {} s): current i_A = {} A differs from --current {} A by "
                                               "more than {} A: the fit is at one current",
                                               k + 1, k < rec.t_s.size() ? rec.t_s[k] : 0.0, command[k], current_A,
                                               tolerance_A));
  }
}

/// One record prepared for the fit (its smoothed velocity and weight); adds it to the rough
/// fit's sums and raises *xmax to its largest |x|.
Prepared PrepareRecord(const io::RigRecord& rec, const DamperFitOptions& o, RoughSums* r, double* xmax) {
  CheckDamperColumns(rec);
  CheckOneCurrent(rec, *o.current_A, o.current_tolerance_A);
  const double cutoff = o.velocity_cutoff_hz > 0.0 ? o.velocity_cutoff_hz : VelocityCutoffHz(rec);
  Prepared p{&rec, SmoothVelocity(rec.y_mm, rec.dt_s, cutoff), 0.0, 0.0};
  for (std::size_t k = 0; k < rec.size(); ++k) {
    p.vmax = std::max(p.vmax, std::abs(p.v[k]));
    *xmax = std::max(*xmax, std::abs(rec.y_mm[k]));
  }
  p.weight = ForceWeight(rec);
  for (std::size_t k = 0; k < rec.size(); ++k) {
    const double s = p.v[k] > 0.0 ? 1.0 : (p.v[k] < 0.0 ? -1.0 : 0.0), v = p.v[k], f = rec.f_kN[k];
    r->a11 += p.weight * s * s;
    r->a12 += p.weight * s * v;
    r->a22 += p.weight * v * v;
    r->b1 += p.weight * s * f;
    r->b2 += p.weight * v * f;
  }
  return p;
}

/// The starts (file comment of damper_fit.h): pre-yield travel delta [mm] x c1/c0, around the
/// rough yield force Fy [kN] and viscous c [kN s/mm], evaluated.
std::vector<State> Starts(double Fy, double c, double xmax, const std::vector<Prepared>& data, double A,
                          const Box& box) {
  std::vector<State> starts;
  for (double delta : {0.1, 0.5, 2.0}) {
    for (double ratio : {1.0, 10.0}) {
      const double c0 = c * (1.0 + ratio) / ratio, c1 = ratio * c0;
      const double zmax = A * delta;                    // z_max = A delta
      const double bg = 1.0 / (A * delta * delta);      // beta + gamma
      const double alpha = Fy / zmax * (c0 + c1) / c1;  // alpha z_max c1 / (c0 + c1) = F_y
      const double k0 = 0.01 * Fy / std::max(xmax, 1e-3);
      State s;
      s.theta << std::log(alpha), std::log(c0), std::log(c1), std::log(k0), std::log(0.5 * bg), std::log(0.5 * bg);
      s.theta = box.Clamp(s.theta);
      s.ev = Evaluate(s.theta, data, A, 0);
      starts.push_back(std::move(s));
    }
  }
  return starts;
}

}  // namespace

DamperFitResult FitDamper(const std::vector<io::RigRecord>& records, const DamperFitOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw Error("DamperFitOptions", why);
  if (!o.current_A) throw Error("DamperFitOptions", "current_A: the fit at one current needs it");
  if (records.empty()) throw Error("FitDamper", "no records");
  std::vector<Prepared> data;
  RoughSums r;
  double xmax = 0, vmax_all = 0;
  for (const auto& rec : records) {
    data.push_back(PrepareRecord(rec, o, &r, &xmax));
    vmax_all = std::max(vmax_all, data.back().vmax);
  }
  if (!(vmax_all > 0.0)) throw Error("FitDamper", "the displacement never moves: nothing to fit");
  const double det = r.a11 * r.a22 - r.a12 * r.a12;
  double Fy = det > 0.0 ? (r.b1 * r.a22 - r.b2 * r.a12) / det : 0.0;
  double c = det > 0.0 ? (r.a11 * r.b2 - r.a12 * r.b1) / det : 0.0;
  const double fpeak = PeakForce(records);
  if (!(Fy > 0.0)) Fy = 0.5 * fpeak;
  if (!(c > 0.0)) c = 0.1 * fpeak / vmax_all;

  const Box box = MakeBox(o);
  std::vector<State> starts = Starts(Fy, c, xmax, data, o.A, box);
  DamperFitResult res;
  res.current_A = *o.current_A;
  int best = -1;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    if (std::isfinite(starts[i].ev.cost)) Iterate(&starts[i], data, o.A, box, o.start_iterations.value_or(kStartIterations));
    res.start_costs.push_back(starts[i].ev.cost);
    if (std::isfinite(starts[i].ev.cost) && (best < 0 || starts[i].ev.cost < starts[static_cast<std::size_t>(best)].ev.cost))
      best = static_cast<int>(i);
  }
  if (best < 0) throw Error("FitDamper", "no start gives a finite force prediction");
  State& s = starts[static_cast<std::size_t>(best)];
  s.converged = false;
  Iterate(&s, data, o.A, box, o.max_iterations.value_or(kMaxIterations));
  res.best_start = best;
  res.iterations = s.iterations;
  res.converged = s.converged;
  res.cost = s.ev.cost;
  res.coef = FromTheta(s.theta, o.A, s.ev.k1, s.ev.x0);
  res.force_offset_kN = s.ev.offset;
  for (const auto& rec : records)
    res.records.push_back(ScoreDamper(res.coef, rec, o.velocity_cutoff_hz, res.force_offset_kN));
  res.status.converged = s.converged;
  res.status.iterations = s.iterations;
  res.status.max_iterations = o.max_iterations.value_or(kMaxIterations);
  // Every lower bound is a floor standing for 0 (the coefficients are >= 0: fit_status.h).
  for (int i = 0; i < kNonlinear; ++i) {
    auto p = StatusOf(kNames[static_cast<std::size_t>(i)], std::exp(s.theta[i]), kLo[i], kHi[i], true);
    if (box.Held(i)) p.state = ParameterState::kHeld, p.why = box.held_why[static_cast<std::size_t>(i)];
    res.status.parameters.push_back(std::move(p));
  }
  res.status.implausible = CheckPlausible(FittedValues(res.status, {{"k1", res.coef.k1}}), o.A, false);
  return res;
}

std::string DamperFitResult::Report() const {
  const auto& k = coef;
  const double bg = k.beta + k.gamma;
  const double zmax = bg > 0.0 ? std::sqrt(k.A / bg) : kInf;
  std::string o = fmt::format("Spencer MR damper model at {} A (Eqs. 32-34, n = 2, A held at {}):\n", current_A, k.A);
  o += fmt::format("  alpha = {:.6g} kN/mm   c0 = {:.6g} kN s/mm   c1 = {:.6g} kN s/mm\n", k.alpha, k.c0, k.c1);
  o += fmt::format("  k0 = {:.6g} kN/mm   k1 = {:.6g} kN/mm   x0 = {:.6g} mm\n", k.k0, k.k1, k.x0);
  if (force_offset_kN != 0.0)
    o += fmt::format("  force offset (the load cell's zero; k1 = 0) = {:.6g} kN\n", force_offset_kN);
  o += fmt::format("  beta = {:.6g} 1/mm^2   gamma = {:.6g} 1/mm^2   A = {:.6g}   n = 2\n", k.beta, k.gamma, k.A);
  o += fmt::format(
      "  derived: z_max = sqrt(A/(beta+gamma)) = {:.4g} mm, Bouc-Wen force alpha z_max = {:.4g} kN,\n"
      "           pre-yield travel 1/sqrt(A (beta+gamma)) = {:.4g} mm, post-yield damping c0 c1/(c0+c1) = {:.4g} kN s/mm\n",
      zmax, k.alpha * zmax, 1.0 / std::sqrt(k.A * bg), k.c0 * k.c1 / (k.c0 + k.c1));
  o += fmt::format("  Levenberg-Marquardt: start {} of {} won, {} iterations, {}; cost J = {:.6g}\n", best_start + 1,
                   start_costs.size(), iterations, converged ? "converged" : "not converged (iteration limit)", cost);
  o += status.Details("  ");
  o += "  force error per record (Eq. 31 on f):\n";
  for (const auto& r : records)
    o += fmt::format("    {:<40} {:6d} samples at {:g} s, peak {:.4g} kN: {:.3f} %\n", r.source, r.samples, r.dt_s,
                     r.peak_force_kN, r.nrmse_f_pct);
  return o;
}

models::MrDamperParams ParamsAtOneCurrent(const models::MrDamperCoefficients& k) {
  models::MrDamperParams p;
  p.alpha_a = p.alpha_b = k.alpha;
  p.c0_a = p.c0_b = k.c0;
  p.c1_a = p.c1_b = k.c1;
  p.beta_a = p.beta_b = k.beta;
  p.gamma_a = p.gamma_b = k.gamma;
  p.alpha_c = p.c0_c = p.c1_c = p.beta_c = p.gamma_c = 0.0;
  p.A = k.A;
  p.n = k.n;
  p.k0 = k.k0;
  p.k1 = k.k1;
  p.x0 = k.x0;
  return p;
}

std::string DamperTable(const models::MrDamperParams& p) {
  std::string o = "[plant.damper]\n";
  for (const models::MrDamperField& f : models::kMrDamperFields) o += fmt::format("{} = {}\n", f.key, TomlFloat(p.*f.member));
  return o;
}

std::string DamperTomlFragment(const DamperFitResult& fit, const std::string& title) {
  const auto p = ParamsAtOneCurrent(fit.coef);
  std::string o = fmt::format("# {}\n", title);
  o += fmt::format(
      "# Spencer MR damper (Eqs. 32-34, n = 2) fitted at {} A; current-independent here (p_a = p_b, rate 0),\n"
      "# so it holds at {} A only. Force error (Eq. 31 on f) per training record:\n",
      fit.current_A, fit.current_A);
  for (const auto& r : fit.records) o += fmt::format("#   {}: {:.3f} %\n", r.source, r.nrmse_f_pct);
  o += ForceOffsetComment(fit.force_offset_kN);
  o += fit.status.Comment();
  o += "\n" + DamperTable(p);
  o += "\n" + fit.status.TomlTable() + ForceOffsetKey(fit.force_offset_kN);
  return o;
}

}  // namespace rths::ident
