#include "ident/damper_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "ident/fit_advice.h"

namespace rths::ident {

namespace {

/// At most this many refits of the damper model around the measurement's effects.
constexpr int kMeasurementRounds = 6;
/// The profiles' smallest steps (ProfileMeasurement): the skew's [ms] (or a sample) and the mass's [kg].
constexpr double kProfileSkewStepMs = 0.1;
constexpr double kProfileSkewMaxStepMs = 1.0;
/// How often the skew's profile may move to its cheaper end.
constexpr int kProfileMoves = 3;
constexpr double kProfileMassStepKg = 0.05;

/// The fit the options ask for, without measurement effects.
DamperModelFit FitBase(const std::vector<io::RigRecord>& records, const DamperFitOptions& o) {
  DamperModelFit fit;
  fit.velocity_cutoff_hz = o.velocity_cutoff_hz;
  if (o.current_A) fit.at_current = FitDamper(records, o);
  else fit.any_input = FitSpencer(records, o);
  return fit;
}

/// The measurement fitted around `fit`'s damper force on the records.
MeasurementFit MeasureAround(const DamperModelFit& fit, const std::vector<io::RigRecord>& records,
                             const MeasurementOptions& m) {
  std::vector<std::vector<double>> F;
  std::vector<double> cut;
  for (const auto& r : records) F.push_back(fit.DamperForce(r)), cut.push_back(fit.CutoffHz(r));
  return FitMeasurement(records, F, cut, m);
}

/// The model refitted with the measurement held at (skew_ms, mass_kg) where given ("fixed"), the
/// other fitted around it as the options say.
DamperModelFit RefitAt(const std::vector<io::RigRecord>& records, const DamperFitOptions& o,
                       const MeasurementOptions& m, const DamperModelFit& at, std::optional<double> skew_ms,
                       std::optional<double> mass_kg) {
  MeasurementFit held = at.measurement;
  if (skew_ms) held.skew_ms = *skew_ms;
  if (mass_kg) held.mass_kg = *mass_kg;
  std::vector<io::RigRecord> own;
  for (const auto& r : records) own.push_back(held.DamperForceRecord(r, at.CutoffHz(r)));
  DamperModelFit f = FitBase(own, o);
  MeasurementOptions mo = m;
  if (skew_ms) mo.skew = MeasurementMode::kGiven, mo.skew_ms = *skew_ms;
  if (mass_kg) mo.inertia = MeasurementMode::kGiven, mo.mass_kg = *mass_kg;
  f.measurement = MeasureAround(f, records, mo);
  f.measurement.options = m;  // what was asked, for the report
  return f;
}

/// The least-squares parabola J(x) = a + b (x - x0) + c (x - x0)^2 through the points; returns
/// {b, c} (c <= 0 or too few points: no minimum).
std::pair<double, double> Parabola(const std::vector<std::pair<double, double>>& pts, double x0) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  for (const auto& [x, J] : pts) {
    const Eigen::Vector3d row(1.0, x - x0, (x - x0) * (x - x0));
    A += row * row.transpose();
    y += row * J;
  }
  if (pts.size() < 3) return {0.0, 0.0};
  const Eigen::Vector3d c = A.ldlt().solve(y);
  return {c(1), c(2)};
}

/// Profiles of the cost J (the damper model refitted at each point, the other measurement parameter
/// fitted around it): five points about each fitted parameter, a least-squares parabola through
/// them (a refit's own convergence scatters J by more than a three-point curvature could stand),
/// its curvature c giving the standard error sqrt(2 sigma^2 tau / (2 c)); for the skew the
/// parabola's vertex, refitted, replaces the alternation's end if its cost is lower.
void ProfileMeasurement(const std::vector<io::RigRecord>& records, const DamperFitOptions& o,
                        const MeasurementOptions& m, DamperModelFit* fit) {
  if (m.skew == MeasurementMode::kAuto) {
    // The step: the finest record's sample (the skew's resolution), at least kProfileSkewStepMs and
    // three conditional standard errors, at most kProfileSkewMaxStepMs; the points kept in the search
    // range. When the cheapest point is an end of the five, the profile moves there (at most
    // kProfileMoves times): the alternation's end may be off by more than two steps.
    double dt_ms = 1e3 * records.front().dt_s;
    for (const auto& r : records) dt_ms = std::min(dt_ms, 1e3 * r.dt_s);
    const double h = std::min(std::max({dt_ms, kProfileSkewStepMs, 3.0 * fit->measurement.skew_se_ms}), kProfileSkewMaxStepMs);
    const double se_held = fit->measurement.skew_se_ms;
    double centre = fit->measurement.skew_ms;
    std::vector<std::pair<double, double>> pts;
    std::optional<DamperModelFit> best;
    for (int move = 0; move <= kProfileMoves; ++move) {
      pts.clear();
      int best_j = 0;
      for (int j = -2; j <= 2; ++j) {
        const double sj = std::clamp(centre + j * h, -kMaxSkewMs, kMaxSkewMs);
        if (!pts.empty() && sj == pts.back().first) continue;
        DamperModelFit f = RefitAt(records, o, m, *fit, sj, std::nullopt);
        pts.emplace_back(sj, f.measurement.cost);
        if (f.measurement.cost < (best ? best->measurement.cost : fit->measurement.cost)) best = std::move(f), best_j = j;
      }
      const bool at_range_end = std::abs(centre + best_j * h) >= kMaxSkewMs;
      if (std::abs(best_j) < 2 || at_range_end || move == kProfileMoves) break;
      centre = best->measurement.skew_ms;  // the profile falls on past its end: move there
    }
    const auto [b, c] = Parabola(pts, centre);
    if (c > 0.0) {
      const double v = std::clamp(centre - b / (2.0 * c), pts.front().first, pts.back().first);
      DamperModelFit at_v = RefitAt(records, o, m, *fit, v, std::nullopt);
      if (at_v.measurement.cost < (best ? best->measurement.cost : fit->measurement.cost)) best = std::move(at_v);
    }
    const double se = c > 0.0 ? std::sqrt(fit->measurement.sigma2 * fit->measurement.tau / c)
                              : std::numeric_limits<double>::infinity();
    if (best) *fit = std::move(*best);
    fit->measurement.skew_se_ms = std::max(se, se_held);
    fit->measurement.skew_at_range_end = std::abs(fit->measurement.skew_ms) >= kMaxSkewMs - 1e-9;
    fit->measurement.profiled = true;
  }
  if (m.inertia == MeasurementMode::kAuto) {
    const double m0 = fit->measurement.mass_kg;
    const double h = std::max({0.25 * m0, 3.0 * fit->measurement.mass_se_kg, kProfileMassStepKg});
    const auto sk = std::optional<double>(fit->measurement.skew_ms);
    std::vector<std::pair<double, double>> pts{{m0, fit->measurement.cost}};
    for (int j : {-2, -1, 1, 2}) {
      const double mj = m0 + j * h;
      if (mj < 0.0) continue;
      pts.emplace_back(mj, RefitAt(records, o, m, *fit, sk, mj).measurement.cost);
    }
    const auto [b, c] = Parabola(pts, m0);
    (void)b;
    fit->measurement.mass_se_kg = c > 0.0 ? std::sqrt(fit->measurement.sigma2 * fit->measurement.tau / c)
                                          : std::numeric_limits<double>::infinity();
    fit->measurement.mass_unresolved = !(fit->measurement.mass_kg > 2.0 * fit->measurement.mass_se_kg);
    fit->measurement.profiled = true;
  }
}

}  // namespace

DamperModelFit FitDamperModel(const std::vector<io::RigRecord>& records, const DamperFitOptions& o,
                              const MeasurementOptions& m) {
  DamperModelFit fit = FitBase(records, o);
  if (!m.Any()) return fit;
  // Around the model, then the model again on the damper's own force that implies, until the skew
  // moves by less than its standard error (at most kMeasurementRounds refits).
  fit.measurement = MeasureAround(fit, records, m);
  for (int round = 0; round < kMeasurementRounds; ++round) {
    std::vector<io::RigRecord> own;
    for (const auto& r : records) own.push_back(fit.measurement.DamperForceRecord(r, fit.CutoffHz(r)));
    const MeasurementFit before = fit.measurement;
    fit = FitBase(own, o);
    fit.measurement = MeasureAround(fit, records, m);
    if (std::abs(fit.measurement.skew_ms - before.skew_ms) <= std::max(fit.measurement.skew_se_ms, 1e-9) &&
        std::abs(fit.measurement.mass_kg - before.mass_kg) <= std::max(fit.measurement.mass_se_kg, 1e-9))
      break;
  }
  ProfileMeasurement(records, o, m, &fit);
  // The training scores on the measured force.
  auto& scores = fit.at_current ? fit.at_current->records : fit.any_input->records;
  for (std::size_t j = 0; j < records.size() && j < scores.size(); ++j) scores[j] = fit.Score(records[j]);
  return fit;
}

std::string DamperModelFit::Report() const {
  return (at_current ? at_current->Report() : any_input->Report()) + measurement.Report();
}

const FitStatus& DamperModelFit::status() const { return at_current ? at_current->status : any_input->status; }

std::vector<std::string> DamperModelFit::Advice() const {
  AdviceContext c;
  if (at_current) {
    c.current_A = at_current->current_A;
    c.A = at_current->coef.A;
  } else {
    c.any_input = true;
    c.voltage = any_input->voltage;
    c.input_min = any_input->input_min;
    c.input_max = any_input->input_max;
    c.levels = any_input->levels;
    c.A = any_input->params.A;
  }
  return FitAdvice(status(), c);
}

double DamperModelFit::CutoffHz(const io::RigRecord& record) const {
  return velocity_cutoff_hz > 0.0 ? velocity_cutoff_hz : VelocityCutoffHz(record);
}

std::vector<double> DamperModelFit::DamperForce(const io::RigRecord& r) const {
  const double cutoff = CutoffHz(r);
  if (any_input)
    return PredictSpencerForce(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage, cutoff,
                               any_input->force_offset_kN);
  return PredictDamperForce(at_current->coef, r, cutoff, at_current->force_offset_kN);
}

std::vector<double> DamperModelFit::PredictForce(const io::RigRecord& r) const {
  auto F = DamperForce(r);
  return measurement.Any() ? measurement.Measured(F, r, CutoffHz(r)) : F;
}

DamperRecordScore DamperModelFit::Score(const io::RigRecord& r) const {
  if (measurement.Any()) return ScoreForce(r, PredictForce(r), CutoffHz(r));
  if (any_input)
    return ScoreSpencer(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage,
                        velocity_cutoff_hz, any_input->force_offset_kN);
  return ScoreDamper(at_current->coef, r, velocity_cutoff_hz, at_current->force_offset_kN);
}

std::string DamperModelFit::ModelToml(const std::string& title) const {
  return (at_current ? DamperTomlFragment(*at_current, title) : SpencerModelToml(*any_input, title)) + measurement.Toml();
}

std::string DamperModelFit::HeldOutReport(const std::vector<io::RigRecord>& held) const {
  if (held.empty()) return "";
  std::string o = "  held-out force error (Eq. 31 on f), same model:\n";
  const int width = at_current ? 6 : 7;
  for (const auto& h : held) {
    const auto sc = Score(h);
    if (std::isfinite(sc.nrmse_f_pct)) {
      o += fmt::format("    {:<40} {:>{}} samples at {:g} s, peak {:.4g} kN: {:.3f} %\n", sc.source, sc.samples, width,
                       sc.dt_s, sc.peak_force_kN, sc.nrmse_f_pct);
      continue;
    }
    // The prediction stopped being finite: say where, not "inf %".
    const auto F = PredictForce(h);
    std::size_t k = 0;
    while (k < F.size() && std::isfinite(F[k])) ++k;
    o += fmt::format("    {:<40} {:>{}} samples at {:g} s, peak {:.4g} kN: no score: the model's force stops being "
                     "finite at t = {:.4g} s (sample {}): the model is too stiff for this record's motion (more than "
                     "{} substeps a sample) or its state diverges there\n",
                     sc.source, sc.samples, width, sc.dt_s, sc.peak_force_kN, static_cast<double>(k) * h.dt_s, k,
                     kMaxSpencerSubsteps);
  }
  return o;
}

DamperModelFit::Verdict DamperModelFit::Judge(const std::string& tool, bool accept_unconverged) const {
  // A failed fit (fit_status.h) is written, marked, and exits kExitFitFailed unless accepted; an
  // implausible value is a warning. Either way, what to try (fit_advice.h).
  Verdict v;
  const auto& st = status();
  for (const auto& p : st.implausible) v.messages += fmt::format("{}: warning: {}\n", tool, p.Warning());
  if (const auto advice = Advice(); !advice.empty()) {
    v.messages += fmt::format("{}: what to try (docs/identification.md \"When a fit fails\"):\n", tool);
    for (const auto& a : advice) v.messages += fmt::format("  - {}\n", a);
  }
  if (st.Ok()) return v;
  v.messages += fmt::format("{}: fit status: {}\n", tool, st.Summary());
  if (accept_unconverged) {
    v.messages += fmt::format("{}: --accept-unconverged: exit 0 all the same\n", tool);
  } else {
    v.messages += fmt::format("{}: exit {} (the model file says FIT FAILED; --accept-unconverged exits 0; "
                              "docs/identification.md \"When a fit fails\")\n",
                              tool, kExitFitFailed);
    v.exit_code = kExitFitFailed;
  }
  return v;
}

}  // namespace rths::ident
