// The extended Table 2 (issue 25; docs/reproduce_table2.md "--extended"): beside the paper's
// proposed controllers (ff, ff_lqg as Table 2 designs them) and none, the field's adaptive
// compensators (ats, ambc with their published defaults) and a PI + phase lead designed for this
// plant by a written rule, in the manner of the RTHS benchmark's example controller.
#include "studies/table2_extended.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "control/feedforward.h"
#include "core/error.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/run_log.h"
#include "studies/table2.h"
#include "signal/metrics.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::CsvWriter;
using io::FormatSig;

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

std::string PctOrDash(double v) { return std::isfinite(v) ? fmt::format("{:#.3g}", v) : "-"; }

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

namespace {

void WriteCsv(const std::vector<Table2ExtendedRow>& rows, const fs::path& file) {
  CsvWriter csv(file, {"condition", "band_hz", "controller", "table2_row", "ours_pct", "second_half_pct", "peak_error_mm",
                       "steps", "steps_planned", "stopped", "a0", "a1_s", "a2_s2", "a3_s3", "adapt_start_s"});
  for (const auto& r : rows) {
    auto coef = [&](std::size_t i) { return i < r.final_coefficients.size() ? FormatSig(r.final_coefficients[i], 6) : ""; };
    csv.Row({r.condition, r.band, r.controller, r.table2_row, FormatSig(r.ours_pct, 4), FormatSig(r.second_half_pct, 4),
             FormatSig(r.peak_error_mm, 4), std::to_string(r.steps), std::to_string(r.steps_planned), r.stopped,
             coef(0), coef(1), coef(2), coef(3), r.adapt_start_s >= 0 ? FormatSig(r.adapt_start_s, 4) : ""});
  }
  csv.Close();
}

const std::vector<std::string> kConditions{"0.0A", "2.5A", "pulse"};

/// The section "The controllers": one line each, as set up for every condition.
void WriteControllers(std::ostream& md, const PiLeadDesign& pi_lead) {
  std::map<std::string, std::string> ff_rows, models_of;
  for (const auto& c : kConditions) {
    for (const auto& x : Table2ExtendedControllers(c, pi_lead)) {
      if (x.name == "ff") ff_rows[c] = x.table2_row, models_of[c] = x.controller.model.name;
    }
  }
  const std::string per_condition =
      fmt::format("0.0A: {}, 2.5A: {}, pulse: {}", models_of["0.0A"], models_of["2.5A"], models_of["pulse"]);
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

/// The section "Eq. 31 tracking error": both bands of each condition and controller on one line.
void WriteErrors(std::ostream& md, const std::vector<Table2ExtendedRow>& rows) {
  md << "## Eq. 31 tracking error [%]\n\n"
     << "| Condition | Controller | 0-5 Hz | 0-5 Hz 2nd half | 0-5 Hz peak [mm] | 0-15 Hz | 0-15 Hz 2nd half | 0-15 Hz "
        "peak [mm] | Stopped |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& c : kConditions) {
    for (const auto& n : ExtendedNames(rows)) {
      const Table2ExtendedRow* a = FindExt(rows, c, "0-5", n);
      const Table2ExtendedRow* b = FindExt(rows, c, "0-15", n);
      if (!a || !b) continue;
      std::string stop;
      for (const auto* r : {a, b}) {
        if (r->stopped != "no") stop += fmt::format("{}{} Hz at {} of {} steps: {}", stop.empty() ? "" : "; ", r->band,
                                                    r->steps, r->steps_planned, r->stopped);
      }
      md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", c, n, PctOrDash(a->ours_pct),
                        PctOrDash(a->second_half_pct), PctOrDash(a->peak_error_mm), PctOrDash(b->ours_pct), PctOrDash(b->second_half_pct),
                        PctOrDash(b->peak_error_mm), stop.empty() ? "no" : stop);
    }
  }
}

/// The section "Order, best first (a stopped run last)".
void WriteOrder(std::ostream& md, const std::vector<Table2ExtendedRow>& rows) {
  md << "\n## Order, best first (a stopped run last)\n\n| Condition | Band | Order |\n|---|---|---|\n";
  for (const auto& c : kConditions) {
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
      for (auto* r : sel) order += fmt::format("{}{} {}", order.empty() ? "" : " < ", r->controller, PctOrDash(r->ours_pct));
      md << fmt::format("| {} | {} Hz | {} |\n", c, band, order);
    }
  }
}

/// The section "Where the adaptive controllers ended": their last coefficients beside Eq. 19's.
void WriteCoefficients(std::ostream& md, const std::vector<Table2ExtendedRow>& rows, const PiLeadDesign& pi_lead) {
  md << "\n## Where the adaptive controllers ended\n\n"
     << "The coefficients of u = a0 x_t + a1 x_t' + a2 x_t'' (+ a3 x_t''') used at the last step, beside those of "
        "the condition's design model (Eq. 19: the inverse of G = K/((s + p)(s^2 + b s + c)): a0 = pc/K, "
        "a1 = (pb + c)/K, a2 = (p + b)/K, a3 = 1/K); \"started\" is when the coefficients first left their "
        "start values.\n\n"
     << "| Condition | Band | Controller | a0 [-] | a1 [ms] | a2 [s^2] | a3 [s^3] | started [s] |\n"
        "|---|---|---|---:|---:|---:|---:|---:|\n";
  for (const auto& c : kConditions) {
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
}

}  // namespace

void WriteTable2Extended(const ReproduceOptions& opts, const std::vector<Table2ExtendedRow>& rows,
                         const PiLeadDesign& pi_lead) {
  WriteCsv(rows, opts.out_dir / "table2_extended.csv");
  const fs::path file = opts.out_dir / "table2_extended.md";
  std::ofstream md(file);
  if (!md) throw Error(file.string(), "cannot open for writing");
  md << "# Table 2, extended: the field's adaptive compensators beside the paper's proposed controllers\n\n"
     << fmt::format("Made by `rths reproduce table2{} --extended --plant {}` on {}. The paper's 36 rows are in "
                    "table2.md, unchanged; this table adds runs, it does not replace any.\n\n",
                    opts.quick ? " --quick" : "", opts.plant, UtcStamp())
     << "Same lockstep runs as Table 2 (same records, currents, plant and Eq. 31 over every logged step); "
     << "`none`, `ff` and `ff_lqg` *are* Table 2's runs (the row named), the others are new runs of the same "
        "length as Table 2's compensated rows. \"2nd half\" is Eq. 31 over the second half of the run's steps (an "
        "adaptive controller has converged by then); \"peak\" is max |r_k - y_k| [mm]. A run the safety monitor "
        "stopped is a row with its reason; its numbers are over the steps before the stop.\n\n"
     << "## The controllers\n\n";
  WriteControllers(md, pi_lead);
  md << "\n## pi_lead: the design rule and its numbers\n\n```\n" << pi_lead.Describe() << "```\n\n";
  WriteErrors(md, rows);
  WriteOrder(md, rows);
  WriteCoefficients(md, rows, pi_lead);
  md.close();
  if (!md) throw Error(file.string(), "write failed");
  WriteFigure(opts, rows);
}

}  // namespace rths::studies
