// The extended Table 2 (issue 25; docs/reproduce_table2.md "--extended"): beside the paper's
// proposed controllers (ff, ff_lqg as Table 2 designs them) and none, the field's adaptive
// compensators (ats, ambc with their published defaults) and a PI + phase lead designed for this
// plant by a written rule, in the manner of the RTHS benchmark's example controller.
#include "report/table2_extended.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <mutex>
#include <numbers>
#include <thread>

#include <fmt/format.h>

#include "control/analysis.h"
#include "control/feedforward.h"
#include "control/lti.h"
#include "control/lti_controller.h"
#include "core/error.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/run_log.h"
#include "signal/metrics.h"

namespace rths::report {

namespace fs = std::filesystem;
using io::CsvWriter;
using io::FormatSig;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

/// The Tustin PI's response at f: Kp + Ki (dt/2)(z + 1)/(z - 1) = Kp - j Ki h, h = (dt/2) cot(w dt/2).
double TustinIntegratorGain(double f_hz, double dt_s) {
  const double half = kPi * f_hz * dt_s;  // w dt / 2
  return 0.5 * dt_s / std::tan(half);
}

/// The PI that gives the loop |L| = 1 and the phase margin pm_rad at f, from the plant's response
/// there (g) and its phase unwrapped from 0 Hz (theta). Kp < 0 or Ki <= 0 when the margin cannot be
/// had at f with a PI (the plant's phase outside (-180 + pm, -90 + pm)).
struct PiAt {
  double kp = 0.0, ki = 0.0;
};
PiAt PiForMargin(std::complex<double> g, double theta, double pm_rad, double f_hz, double dt_s) {
  const double phc = -kPi + pm_rad - theta;  // arg C needed
  const double mag = std::abs(g);
  return {std::cos(phc) / mag, -std::sin(phc) / (mag * TustinIntegratorGain(f_hz, dt_s))};
}

control::LtiConfig PiLeadLti(double kp, double ki, bool with_lead, double k, double zero, double pole) {
  control::LtiConfig c;
  c.feedback = {{kp, ki}, {1.0, 0.0}};
  if (with_lead) c.reference = {{k, -k * zero}, {1.0, -pole}};
  c.domain = control::TfDomain::kS;
  c.discretisation = control::Discretisation::kTustin;
  return c;
}

control::ControllerLti Linearized(const control::LtiConfig& cfg, double dt_s) {
  return control::LtiController(control::MakeLtiDesign(cfg, dt_s)).Linearize(0.0);
}

}  // namespace

PiLeadDesign DesignPiLead(const models::ServoModel3& model, double dt_s) {
  PiLeadDesign d;
  d.model = model;
  d.dt_s = dt_s;
  const control::DiscreteSs g = control::ServoZoh(model, dt_s);
  const double pm = d.target_pm_deg * kDeg;

  // (1) The PI: for every crossover frequency f of the grid, the Kp, Ki that give the margin there;
  // of those whose loop has a peak sensitivity <= max_sensitivity, the largest Ki. The plant's
  // phase is unwrapped from the lowest frequency of the grid up (the ZOH model's phase passes
  // -180 deg below Nyquist); the sensitivity is evaluated on the same grid.
  const double f_lo = 0.1, f_hi = 0.45 / dt_s;
  const int n = 6000;
  std::vector<double> f(n + 1), theta(n + 1), hint(n + 1);
  std::vector<std::complex<double>> gr(n + 1);
  for (int i = 0; i <= n; ++i) {
    f[i] = f_lo * std::pow(f_hi / f_lo, static_cast<double>(i) / n);
    gr[i] = g.Response(f[i]);
    theta[i] = i == 0 ? std::arg(gr[0]) : theta[i - 1] + std::arg(gr[i] / gr[i - 1]);
    hint[i] = TustinIntegratorGain(f[i], dt_s);
  }
  const double max_s = std::pow(10.0, d.max_sensitivity_db / 20.0);
  int best = -1;
  for (int i = 0; i <= n; ++i) {
    const PiAt pi = PiForMargin(gr[i], theta[i], pm, f[i], dt_s);
    if (!(pi.kp >= 0.0 && pi.ki > 0.0) || (best >= 0 && pi.ki <= d.ki)) continue;
    double peak = 0.0;
    for (int j = 0; j <= n && peak <= max_s; ++j) {
      peak = std::max(peak, 1.0 / std::abs(1.0 + std::complex<double>(pi.kp, -pi.ki * hint[j]) * gr[j]));
    }
    if (peak > max_s) continue;
    best = i;
    d.kp = pi.kp;
    d.ki = pi.ki;
    d.pi_crossover_hz = f[i];
  }
  if (best < 0) {
    throw Error("pi_lead", fmt::format("no PI gives the design model a {:g} deg phase margin with a peak sensitivity "
                                       "of at most {:g} dB",
                                       d.target_pm_deg, d.max_sensitivity_db));
  }

  // The PI loop as it runs (Tustin at dt, u = C (r - y)), analysed on the design model.
  const control::ControllerLti pi_lin = Linearized(PiLeadLti(d.kp, d.ki, false, 0, 0, 0), dt_s);
  const control::LoopAnalysis loop = control::AnalyzeLoop(pi_lin.fb, g);
  d.pi_stable = loop.stable;
  d.pi_spectral_radius = loop.spectral_radius;
  d.pi_crossovers = static_cast<int>(loop.crossovers.size());
  d.pi_phase_margin_deg = loop.critical.phase_margin_deg;
  d.pi_delay_margin_ms = 1e3 * loop.critical.delay_margin_s;
  d.pi_peak_sensitivity_db = loop.peak_sensitivity_db;
  if (!loop.stable || loop.crossovers.size() != 1 || std::abs(d.pi_phase_margin_deg - d.target_pm_deg) > 0.5 ||
      d.pi_peak_sensitivity_db > d.max_sensitivity_db + 0.05) {
    throw Error("pi_lead", fmt::format("the PI (Kp {:.6g}, Ki {:.6g}) does not give one stable crossover with a "
                                       "{:g} deg margin on the design model: {} crossover(s), margin {:.2f} deg, "
                                       "peak sensitivity {:.2f} dB, spectral radius {:.6f}",
                                       d.kp, d.ki, d.target_pm_deg, loop.crossovers.size(), d.pi_phase_margin_deg,
                                       d.pi_peak_sensitivity_db, loop.spectral_radius));
  }
  const double lag_s = control::TrackingLagS(pi_lin, g, d.lag_hz);
  d.pi_lag_ms = 1e3 * lag_s;

  // (2) The lead, with the benchmark's formulas; Tl from the PI loop's lag.
  d.phi_deg = d.pi_phase_margin_deg + d.safety_deg;
  const double s = std::sin(d.phi_deg * kDeg);
  d.a = (1.0 + s) / (1.0 - s);
  d.tl_s = lag_s / (d.a - 1.0 / d.fac);
  d.w_m_rad_s = 1.0 / (d.tl_s * std::sqrt(d.a));
  const double pole0 = -1.0 / d.tl_s;
  d.zero = pole0 / d.a;
  d.pole = pole0 * d.fac;
  d.k = d.a * d.fac;

  d.controller.kind = control::ControllerKind::kLti;
  d.controller.lti = PiLeadLti(d.kp, d.ki, true, d.k, d.zero, d.pole);
  const control::ControllerLti lin = Linearized(d.controller.lti, dt_s);
  for (double f : {1.0, 5.0, 10.0, 15.0}) {
    d.check_hz.push_back(f);
    d.gyr_magnitude.push_back(std::abs(control::TrackingResponse(lin, g, f)));
    d.gyr_lag_ms.push_back(1e3 * control::TrackingLagS(lin, g, f));
  }
  return d;
}

std::string PiLeadDesign::Describe() const {
  std::string t;
  t += fmt::format("pi_lead, designed on the {} model (K {:g}, p {:g}, b {:g}, c {:g}; ZOH at {:g} ms):\n", model.name,
                   model.K, model.p, model.b, model.c, 1e3 * dt_s);
  t += fmt::format("  PI C(s) = Kp + Ki/s: the largest Ki with a {:g} deg phase margin and a peak sensitivity <= {:g} dB "
                   "(Tustin PI, ZOH model): Kp = {:.6g}, Ki = {:.6g} 1/s; crossover {:.2f} Hz, margin {:.2f} deg "
                   "({:.2f} ms of delay), peak sensitivity {:.2f} dB, {} crossover, closed loop {} (spectral radius "
                   "{:.5f})\n",
                   target_pm_deg, max_sensitivity_db, kp, ki, pi_crossover_hz, pi_phase_margin_deg, pi_delay_margin_ms,
                   pi_peak_sensitivity_db, pi_crossovers, pi_stable ? "stable" : "UNSTABLE", pi_spectral_radius);
  t += fmt::format("  the PI loop's lag at {:g} Hz: {:.3f} ms (the plant alone: 1/p + b/c + dt/2 = {:.3f} ms)\n", lag_hz,
                   pi_lag_ms, 1e3 * (1.0 / model.p + model.b / model.c + dt_s / 2));
  t += fmt::format("  lead T(s) = k (s - zero)/(s - pole): phi = margin + {:g} deg = {:.2f} deg, a = (1 + sin phi)/(1 - "
                   "sin phi) = {:.4f}, Tl = lag / (a - 1/fac) = {:.5g} ms (fac {:g}), w_m = 1/(Tl sqrt a) = {:.1f} rad/s; "
                   "zero = -1/(a Tl) = {:.5g} 1/s, pole = -fac/Tl = {:.5g} 1/s, k = a fac = {:.5g}\n",
                   safety_deg, phi_deg, a, 1e3 * tl_s, fac, w_m_rad_s, zero, pole, k);
  t += "  G_yr on the design model:";
  for (std::size_t i = 0; i < check_hz.size(); ++i) {
    t += fmt::format(" {:g} Hz |G| {:.4f} lag {:.3f} ms;", check_hz[i], gyr_magnitude[i], gyr_lag_ms[i]);
  }
  t.back() = '\n';
  t += fmt::format("  [controller.lti] feedback = {{ num = [{:.17g}, {:.17g}], den = [1.0, 0.0] }}, reference = {{ num = "
                   "[{:.17g}, {:.17g}], den = [1.0, {:.17g}] }}, domain = \"s\", discretisation = \"tustin\"\n",
                   kp, ki, k, -k * zero, -pole);
  return t;
}

std::vector<Table2ExtendedController> Table2ExtendedControllers(const std::string& condition,
                                                                const PiLeadDesign& pi_lead) {
  const Table2Controller* none = nullptr;
  const Table2Controller* ff = nullptr;
  const Table2Controller* ff_lqg = nullptr;
  static const std::vector<Table2Controller> table = Table2Controllers();
  for (const auto& row : table) {
    if (row.condition != condition) continue;
    if (row.controller.kind == control::ControllerKind::kNone) none = &row;
    if (row.controller.kind == control::ControllerKind::kFf) ff = &row;
    if (row.controller.kind == control::ControllerKind::kFfLqg) ff_lqg = &row;
  }
  if (!none || !ff || !ff_lqg) throw Error("table2 --extended", fmt::format("unknown condition '{}'", condition));
  const models::ServoModel3& m = ff->controller.model;  // the condition's design model (Table 2's G_FF row)
  std::vector<Table2ExtendedController> out;
  out.push_back({condition, "none", none->name, "u = r", none->controller});
  out.push_back({condition, "ff", ff->name, fmt::format("Eq. 19 on the {} model", m.name), ff->controller});
  out.push_back({condition, "ff_lqg", ff_lqg->name,
                 fmt::format("Eq. 19 + LQG on the {} model", ff_lqg->controller.model.name), ff_lqg->controller});
  const control::AtsConfig ats;
  out.push_back({condition, "ats", "",
                 fmt::format("AtsConfig defaults (OpenFresco): a = [{:g}, {:g} ms, {:g} s^2] at start, a1 in [{:g}, {:g}] "
                             "ms, trigger {:g} mm",
                             ats.initial[0], 1e3 * ats.initial[1], ats.initial[2], 1e3 * ats.lower[1], 1e3 * ats.upper[1],
                             ats.threshold_mm),
                 ControllerKind("ats")});
  auto ambc = ControllerKind("ambc");
  ambc.model = m;
  ambc.ambc.start = control::AmbcStart::kModel;
  out.push_back({condition, "ambc", "",
                 fmt::format("start = \"model\" on the {} model (Eq. 19), the other keys AmbcConfig's defaults "
                             "(RobustAMBCvRTHS)",
                             m.name),
                 ambc});
  out.push_back({condition, "pi_lead", "",
                 fmt::format("C(s) = {:.4g} + {:.4g}/s, T(s) = {:.4g} (s + {:.4g})/(s + {:.4g}), designed on the {} model",
                             pi_lead.kp, pi_lead.ki, pi_lead.k, -pi_lead.zero, -pi_lead.pole, pi_lead.model.name),
                 pi_lead.controller});
  return out;
}

void MeasureExtendedRows(std::vector<Table2ExtendedRow>* rows, int jobs) {
  std::atomic<std::size_t> next{0};
  std::mutex m;
  std::vector<std::string> errors;
  auto worker = [&] {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= rows->size()) return;
      Table2ExtendedRow& row = (*rows)[i];
      row.ours_pct = row.second_half_pct = row.peak_error_mm = std::nan("");
      const fs::path file = row.run_dir / "log.lcm";
      if (!fs::exists(file)) continue;
      try {
        const io::RunLog log = io::ReadRunLog(file.string());
        const std::int64_t n = log.CompleteSteps();
        row.steps = n;
        std::vector<double> r(n), y(n);
        double peak = 0.0;
        for (std::int64_t k = 0; k < n; ++k) {
          r[k] = log.desired[k].r_mm;
          y[k] = log.measured[k].y_mm;
          peak = std::max(peak, std::abs(r[k] - y[k]));
        }
        if (n == 0) continue;
        row.peak_error_mm = peak;
        row.ours_pct = signal::RmsErrorPercent(r, y);
        const std::size_t h = static_cast<std::size_t>(n / 2);
        row.second_half_pct = signal::RmsErrorPercent(std::span<const double>(r).subspan(h),
                                                      std::span<const double>(y).subspan(h));
        const auto& last = log.command[n - 1];
        if (last.n_adapt > 0) {
          row.final_coefficients.assign(last.adapt.begin(), last.adapt.end());
          const auto& first = log.command[0].adapt;
          const double dt = log.StepS();
          for (std::int64_t k = 1; k < n; ++k) {
            if (log.command[k].adapt != first) {
              row.adapt_start_s = static_cast<double>(k) * dt;
              break;
            }
          }
        }
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(m);
        errors.push_back(fmt::format("{}: {}", file.string(), e.what()));
      }
    }
  };
  std::vector<std::thread> threads;
  const int n = std::clamp<int>(jobs, 1, static_cast<int>(std::max<std::size_t>(rows->size(), 1)));
  for (int t = 0; t < n; ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (!errors.empty()) throw Error("table2 --extended", errors.front());
}

namespace {

std::string Pct(double v) { return std::isfinite(v) ? fmt::format("{:#.3g}", v) : "-"; }

const Table2ExtendedRow* FindExt(const std::vector<Table2ExtendedRow>& rows, const std::string& cond,
                                 const std::string& band, const std::string& name) {
  for (const auto& r : rows) {
    if (r.condition == cond && r.band == band && r.controller == name) return &r;
  }
  return nullptr;
}

std::vector<std::string> ExtendedNames(const std::vector<Table2ExtendedRow>& rows) {
  std::vector<std::string> names;
  for (const auto& r : rows) {
    if (std::find(names.begin(), names.end(), r.controller) == names.end()) names.push_back(r.controller);
  }
  return names;
}

void WriteFigure(const ReproduceOptions& opts, const std::vector<Table2ExtendedRow>& rows) {
  if (!io::GnuplotAvailable(opts.gnuplot)) {
    if (opts.log) opts.log("table2 --extended: gnuplot not found, no table2_extended.png (apt-get install gnuplot-nox)");
    return;
  }
  const std::vector<std::string> conditions{"0.0A", "2.5A", "pulse"};
  const auto names = ExtendedNames(rows);
  io::Figure fig;
  fig.name = "table2_extended";
  fig.title = fmt::format("Table 2, extended: Eq. 31 tracking error ({} plant{}); a missing bar: stopped", opts.plant,
                          opts.quick ? ", --quick" : "");
  fig.columns = 2;
  fig.width_px = 1400;
  fig.panel_height_px = 420;
  fig.gnuplot = opts.gnuplot;
  const auto& colors = io::ReadableColors();
  for (const char* band : {"0-5", "0-15"}) {
    std::vector<io::Series> series;
    for (std::size_t j = 0; j < names.size(); ++j) {
      io::Series s = io::MakeSeries(names[j], colors[j % colors.size()]);
      for (const auto& c : conditions) {
        const Table2ExtendedRow* r = FindExt(rows, c, band, names[j]);
        s.y.push_back(r && r->stopped == "no" ? r->ours_pct : std::nan(""));
      }
      series.push_back(s);
    }
    io::Panel p = io::MakeBarPanel(fmt::format("{} Hz BLWN", band), "Tracking error, Eq. 31 [%]", conditions, series);
    p.log_y = true;
    p.key = "outside right top";
    fig.panels.push_back(p);
  }
  const int margin = io::KeyMarginChars({&fig.panels[0], &fig.panels[1]});
  for (auto& p : fig.panels) p.right_margin_chars = margin;
  io::Plot(fig, opts.out_dir);
}

}  // namespace

void WriteTable2Extended(const ReproduceOptions& opts, const std::vector<Table2ExtendedRow>& rows,
                         const PiLeadDesign& pi_lead) {
  {
    CsvWriter csv(opts.out_dir / "table2_extended.csv",
                  {"condition", "band_hz", "controller", "table2_row", "ours_pct", "second_half_pct", "peak_error_mm",
                   "steps", "steps_planned", "stopped", "a0", "a1_s", "a2_s2", "a3_s3", "adapt_start_s"});
    for (const auto& r : rows) {
      auto coef = [&](std::size_t i) { return i < r.final_coefficients.size() ? FormatSig(r.final_coefficients[i], 6) : ""; };
      csv.Row({r.condition, r.band, r.controller, r.table2_row, FormatSig(r.ours_pct, 4), FormatSig(r.second_half_pct, 4),
               FormatSig(r.peak_error_mm, 4), std::to_string(r.steps), std::to_string(r.steps_planned), r.stopped,
               coef(0), coef(1), coef(2), coef(3), r.adapt_start_s >= 0 ? FormatSig(r.adapt_start_s, 4) : ""});
    }
    csv.Close();
  }

  const fs::path file = opts.out_dir / "table2_extended.md";
  std::ofstream md(file);
  if (!md) throw Error(file.string(), "cannot open for writing");
  const std::string stamp = UtcStamp();
  const auto names = ExtendedNames(rows);
  const std::vector<std::string> conditions{"0.0A", "2.5A", "pulse"};
  md << "# Table 2, extended: the field's adaptive compensators beside the paper's proposed controllers\n\n"
     << fmt::format("Made by `rths reproduce table2{} --extended --plant {}` on {}. The paper's 36 rows are in "
                    "table2.md, unchanged; this table adds runs, it does not replace any.\n\n",
                    opts.quick ? " --quick" : "", opts.plant, stamp)
     << "Same lockstep runs as Table 2 (same records, currents, plant and Eq. 31 over every logged step); "
     << "`none`, `ff` and `ff_lqg` *are* Table 2's runs (the row named), the others are new runs of the same "
        "length as Table 2's compensated rows. \"2nd half\" is Eq. 31 over the second half of the run's steps (an "
        "adaptive controller has converged by then); \"peak\" is max |r_k - y_k| [mm]. A run the safety monitor "
        "stopped is a row with its reason; its numbers are over the steps before the stop.\n\n"
     << "## The controllers\n\n";
  {
    std::map<std::string, std::string> ff_rows, models_of;
    for (const auto& c : conditions) {
      for (const auto& x : Table2ExtendedControllers(c, pi_lead)) {
        if (x.name == "ff") ff_rows[c] = x.table2_row, models_of[c] = x.controller.model.name;
      }
    }
    const std::string per_condition = fmt::format("0.0A: {}, 2.5A: {}, pulse: {}", models_of["0.0A"],
                                                  models_of["2.5A"], models_of["pulse"]);
    for (const auto& x : Table2ExtendedControllers("0.0A", pi_lead)) {
      std::string text = x.design;
      if (x.name == "none") text = "u = r (Table 2's \"None\")";
      if (x.name == "ff") {
        text = fmt::format("Eq. 19 on the condition's model ({}): Table 2's \"{}\", \"{}\", \"{}\"", per_condition,
                           ff_rows["0.0A"], ff_rows["2.5A"], ff_rows["pulse"]);
      }
      if (x.name == "ff_lqg") text = fmt::format("{} (Table 2's \"{}\")", x.design, x.table2_row);
      if (x.name == "ambc") {
        text = fmt::format("start = \"model\" on the condition's G_FF model ({}), the other keys AmbcConfig's "
                           "defaults (RobustAMBCvRTHS: Gamma = 10^[8.4, 6.2, 2.1, 0.8] SI, a 20 Hz 4th-order "
                           "filter, backward differences of r)",
                           per_condition);
      }
      md << fmt::format("- `{}`: {}\n", x.name, text);
    }
  }
  md << "\n## pi_lead: the design rule and its numbers\n\n```\n" << pi_lead.Describe() << "```\n\n";

  md << "## Eq. 31 tracking error [%]\n\n"
     << "| Condition | Controller | 0-5 Hz | 0-5 Hz 2nd half | 0-5 Hz peak [mm] | 0-15 Hz | 0-15 Hz 2nd half | 0-15 Hz "
        "peak [mm] | Stopped |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& c : conditions) {
    for (const auto& n : names) {
      const Table2ExtendedRow* a = FindExt(rows, c, "0-5", n);
      const Table2ExtendedRow* b = FindExt(rows, c, "0-15", n);
      if (!a || !b) continue;
      std::string stop;
      for (const auto* r : {a, b}) {
        if (r->stopped != "no") stop += fmt::format("{}{} Hz at {} of {} steps: {}", stop.empty() ? "" : "; ", r->band,
                                                    r->steps, r->steps_planned, r->stopped);
      }
      md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", c, n, Pct(a->ours_pct),
                        Pct(a->second_half_pct), Pct(a->peak_error_mm), Pct(b->ours_pct), Pct(b->second_half_pct),
                        Pct(b->peak_error_mm), stop.empty() ? "no" : stop);
    }
  }
  md << "\n## Order, best first (a stopped run last)\n\n| Condition | Band | Order |\n|---|---|---|\n";
  for (const auto& c : conditions) {
    for (const char* band : {"0-5", "0-15"}) {
      std::vector<const Table2ExtendedRow*> sel;
      for (const auto& r : rows) {
        if (r.condition == c && r.band == band) sel.push_back(&r);
      }
      std::stable_sort(sel.begin(), sel.end(), [](auto* x, auto* y) {
        const bool sx = x->stopped != "no" || !std::isfinite(x->ours_pct);
        const bool sy = y->stopped != "no" || !std::isfinite(y->ours_pct);
        return sx != sy ? sy : (!sx && x->ours_pct < y->ours_pct);
      });
      std::string order;
      for (auto* r : sel) order += fmt::format("{}{} {}", order.empty() ? "" : " < ", r->controller, Pct(r->ours_pct));
      md << fmt::format("| {} | {} Hz | {} |\n", c, band, order);
    }
  }
  md << "\n## Where the adaptive controllers ended\n\n"
     << "The coefficients of u = a0 x_t + a1 x_t' + a2 x_t'' (+ a3 x_t''') used at the last step, beside those of "
        "the condition's design model (Eq. 19: the inverse of G = K/((s + p)(s^2 + b s + c)): a0 = pc/K, "
        "a1 = (pb + c)/K, a2 = (p + b)/K, a3 = 1/K); \"started\" is when the coefficients first left their "
        "start values.\n\n"
     << "| Condition | Band | Controller | a0 [-] | a1 [ms] | a2 [s^2] | a3 [s^3] | started [s] |\n"
        "|---|---|---|---:|---:|---:|---:|---:|\n";
  for (const auto& c : conditions) {
    const auto ctrls = Table2ExtendedControllers(c, pi_lead);
    const auto ff = std::find_if(ctrls.begin(), ctrls.end(), [](const auto& x) { return x.name == "ff"; });
    const control::FeedforwardCoefficients a = control::MakeFeedforwardCoefficients(ff->controller.model);
    md << fmt::format("| {} | | Eq. 19, {} model | {:.4g} | {:.4g} | {:.4g} | {:.4g} | |\n", c,
                      ff->controller.model.name, a.a0, 1e3 * a.a1, a.a2, a.a3);
    for (const char* band : {"0-5", "0-15"}) {
      for (const auto& r : rows) {
        if (r.condition != c || r.band != band || r.final_coefficients.empty()) continue;
        const auto& k = r.final_coefficients;
        md << fmt::format("| {} | {} Hz | {} | {:.4g} | {:.4g} | {:.4g} | {} | {} |\n", c, band, r.controller, k[0],
                          1e3 * k[1], k.size() > 2 ? k[2] : std::nan(""),
                          k.size() > 3 ? fmt::format("{:.4g}", k[3]) : "-",
                          r.adapt_start_s >= 0 ? fmt::format("{:.3f}", r.adapt_start_s) : "never");
      }
    }
  }
  md.close();
  if (!md) throw Error(file.string(), "write failed");
  WriteFigure(opts, rows);
}

}  // namespace rths::report
