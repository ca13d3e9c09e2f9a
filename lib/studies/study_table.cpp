// The table of the paper's reproductions and their brief reports (studies/study_table.h).
#include "studies/study_table.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.h"
#include "studies/benchmark.h"
#include "studies/marths.h"
#include "studies/fig11.h"
#include "studies/fig5.h"
#include "studies/fig6.h"
#include "studies/fig78.h"
#include "studies/fig9.h"
#include "studies/nonlinear_delay.h"
#include "studies/table2.h"

namespace rths::studies {

namespace {

/// Appends printf-formatted text to *s (the reports keep the tool's former printf formats).
void Appendf(std::string* s, const char* format, ...) __attribute__((format(printf, 2, 3)));
void Appendf(std::string* s, const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n > 0) {
    std::string text(static_cast<std::size_t>(n) + 1, '\0');
    std::vsnprintf(text.data(), text.size(), format, args);
    text.resize(static_cast<std::size_t>(n));
    *s += text;
  }
  va_end(args);
}

StudyReport Fig5(const ReproduceOptions& opts) {
  auto r = ReproduceFig5(opts);
  return {"", std::move(r.claims), ""};
}

StudyReport Fig6(const ReproduceOptions& opts) {
  auto r = ReproduceFig6(opts);
  std::string s;
  Appendf(&s, "\n%-5s %-3s %12s %12s %8s\n", "cond", "", "paper", "ours", "diff");
  for (const auto& m : r.models) {
    const auto q = m.fit.model.ToServoModel3();
    for (auto [n, p, v] : {std::tuple{"K", m.paper.K, q.K}, {"p", m.paper.p, q.p}, {"b", m.paper.b, q.b},
                           {"c", m.paper.c, q.c}}) {
      Appendf(&s, "%-5s %-3s %12.5g %12.5g %+7.2f%%\n", m.condition.c_str(), n, p, v, 100 * (v / p - 1));
    }
  }
  s += "\n";
  return {s, std::move(r.claims), ""};
}

StudyReport Fig78(const ReproduceOptions& opts, const std::string& figure) {
  auto r = ReproduceFig78(opts, figure);
  return {"\n", std::move(r.claims), ""};
}

/// The extended table: Eq. 31 in both bands per condition and controller, and why a run stopped.
std::string Table2Extended(const Table2Result& r) {
  std::string s;
  Appendf(&s,
          "\nextended table (Eq. 31 [%%]; table2_extended.md has the peaks, the second halves and the "
          "adaptive coefficients)\n%-6s %-8s %9s %9s  %s\n",
          "cond", "ctrl", "0-5 Hz", "0-15 Hz", "stopped");
  for (const auto& a : r.extended) {
    if (a.band != "0-5") continue;
    for (const auto& b : r.extended) {
      if (b.condition != a.condition || b.controller != a.controller || b.band != "0-15") continue;
      std::string stop;
      for (const auto* x : {&a, &b}) {
        if (x->stopped != "no") stop += fmt::format("{}{} Hz: {}", stop.empty() ? "" : "; ", x->band, x->stopped);
      }
      Appendf(&s, "%-6s %-8s %9.3f %9.3f  %s\n", a.condition.c_str(), a.controller.c_str(), a.ours_pct, b.ours_pct,
              stop.empty() ? "no" : stop.c_str());
    }
  }
  return s;
}

StudyReport Table2(const ReproduceOptions& opts) {
  auto r = ReproduceTable2(opts);
  std::string s;
  Appendf(&s, "\n%-6s %-18s %7s %9s %7s %9s\n", "cond", "controller", "paper5", "ours5", "paper15", "ours15");
  for (std::size_t i = 0; i + 1 < r.rows.size(); i += 2) {
    const auto& a = r.rows[i];
    const auto& b = r.rows[i + 1];
    Appendf(&s, "%-6s %-18s %7s %9.3f %7s %9.3f\n", a.condition.c_str(), a.controller.c_str(), a.paper_text.c_str(),
            a.ours_pct, b.paper_text.c_str(), b.ours_pct);
  }
  s += "\n";
  return {s, r.claims, opts.extended ? Table2Extended(r) : ""};
}

StudyReport Fig9(const ReproduceOptions& opts) {
  const auto r = ReproduceFig9(opts);  // table in fig9.md
  std::string s;
  Appendf(&s, "fig9: %zu runs in %.1f s; fig9.csv, fig9.md, fig9.png\n", r.rows.size(), r.wall_s);
  return {s, {}, ""};
}

StudyReport Fig11(const ReproduceOptions& opts) {
  auto r = ReproduceFig11(opts);  // table in fig11.md
  std::string s;
  Appendf(&s, "fig11: %zu RTHS + %zu numerical runs in %.1f s; fig11_summary.json, fig11.md, PNGs\n\n", r.runs.size(),
          r.numerical.size(), r.wall_s);
  return {s, std::move(r.claims), ""};
}

/// J1 [ms] with one decimal, J2-J9 [%] with two, each in 8 columns.
void AppendCriteria(std::string* s, const std::function<double(int)>& j) {
  for (int i = 0; i < 9; ++i) Appendf(s, " %7.*f", i == 0 ? 1 : 2, j(i));
}

StudyReport Benchmark(const ReproduceOptions& opts) {
  auto r = ReproduceBenchmark(opts, opts.keep_logs);
  const auto& published = PublishedExampleCriteria();
  std::string s;
  for (int c = 1; c <= 4; ++c) {
    Appendf(&s, "\ncase %d, nominal plant (J1 [ms], J2-J9 [%%]; benchmark.md has the perturbed spread)\n%-17s", c, "");
    for (int j = 1; j <= 9; ++j) Appendf(&s, " %7s", fmt::format("J{}", j).c_str());
    Appendf(&s, "\n%-17s", "example published");
    AppendCriteria(&s, [&](int j) { return published[static_cast<std::size_t>(c - 1)][static_cast<std::size_t>(j)]; });
    // The example closed as the reference code closes its loop: the row to hold against the
    // published one; the controllers below are lockstep runs (docs/benchmark.md says why J4-J9 differ).
    for (const auto& l : r.loops) {
      if (l.case_number != c || l.variant != "reference code") continue;
      Appendf(&s, "\n%-17s", "example ref. loop");
      AppendCriteria(&s, [&](int j) { return l.j.At(j); });
    }
    s += "\n  lockstep runs:\n";
    for (const auto& row : r.rows) {
      if (row.run != "nominal" || row.case_number != c) continue;
      Appendf(&s, "%-17s", row.controller.c_str());
      AppendCriteria(&s, [&](int j) { return row.j.At(j); });
      s += row.stopped == "no" ? "\n" : "  (stopped)\n";
    }
  }
  Appendf(&s,
          "\n%zu runs in %.1f s; benchmark.csv, benchmark_summary.csv, benchmark_loop.csv, benchmark.md, "
          "benchmark.png\n\n",
          r.rows.size(), r.wall_s);
  return {s, std::move(r.claims), ""};
}

/// The maRTHS benchmark (issue 47): J1-J3 per actuator, J5 and J7 per interface DOF.
StudyReport Marths(const ReproduceOptions& opts) {
  auto r = ReproduceMarths(opts);
  std::string s;
  Appendf(&s, "\nmaRTHS, El Centro x 0.4, noise on: nominal plant; perturbed mean over %d plants in [ ] "
              "(J1 [ms], the rest [%%])\n%-9s %15s %15s %15s %15s %15s %15s\n",
          r.perturbed, "", "J2,1", "J2,2", "J5,X", "J5,TH", "J7,X", "J7,TH");
  for (const auto& c : MarthsCompensatorNames()) {
    Appendf(&s, "%-9s", c.c_str());
    for (const char* key : {"J2_1_pct", "J2_2_pct", "J5_X_pct", "J5_TH_pct", "J7_X_pct", "J7_TH_pct"}) {
      Appendf(&s, " %6.2f [%6.2f]", MarthsNominalValue(r.rows, c, key), MarthsPerturbedSpread(r.rows, c, key).mean);
    }
    s += "\n";
  }
  Appendf(&s,
          "\n%zu runs (and the decisions', the records' and 4 through the lockstep) in %.1f s; marths.csv, "
          "marths_summary.csv, marths.md, marths.png, marths_history.png, marths_decisions.*, marths_records.*, "
          "marths_lockstep.*\n\n",
          r.rows.size(), r.wall_s);
  return {s, std::move(r.claims), ""};
}

/// The critical-delay table (issue 44): tau_cr [ms] per integrator and structure.
StudyReport Nonlinear(const ReproduceOptions& opts) {
  auto r = ReproduceNonlinear(opts);
  auto cell = [](const CriticalDelay& c) {
    return c.found ? fmt::format("{:.3f}", 1e3 * c.tau_s) : fmt::format("> {:.0f}", 1e3 * c.tau_s);
  };
  std::string s;
  Appendf(&s, "\ncritical delay [ms] (critical_delay.md explains the columns)\n%-18s %-9s %8s %10s %8s %8s %8s %9s\n",
          "integrator", "structure", "none", "diverges", "poly3", "lead", "ff", "analytic");
  for (const auto& row : r.rows) {
    Appendf(&s, "%-18s %-9s %8s %10s %8s %8s %8s %9s\n", row.integrator.c_str(), row.yielding ? "yielding" : "linear",
            cell(row.none).c_str(), cell(row.none_divergence).c_str(), cell(row.poly3).c_str(),
            cell(row.lead).c_str(), cell(row.ff).c_str(),
            row.yielding ? "" : fmt::format("{:.3f}", 1e3 * row.analytic.tau_s).c_str());
  }
  Appendf(&s, "\n%zu searches in %.1f s; critical_delay.csv, critical_delay.md, critical_delay.png\n\n",
          r.rows.size() * NonlinearDelayColumns().size(), r.wall_s);
  return {s, std::move(r.claims), ""};
}

std::string Fig678Standing(const std::string& plant) {
  return plant == "linear" ? "required on the linear plant: the test suite asserts it (with --quick)"
                           : "reported on the physical plant: docs/experiments.md says which hold there and why";
}
std::string PaperClaimStanding(const std::string&) {
  return "reported: the paper's claim checked on our numbers (docs/experiments.md)";
}

}  // namespace

const std::vector<Study>& Studies() {
  static const std::vector<Study> studies = {
      {"fig5", Fig5, [](const std::string&) { return std::string("required: the test suite asserts E6 within 2 %"); },
       false},
      {"fig6", Fig6, Fig678Standing},
      {"fig7", [](const ReproduceOptions& o) { return Fig78(o, "fig7"); }, Fig678Standing},
      {"fig8", [](const ReproduceOptions& o) { return Fig78(o, "fig8"); }, Fig678Standing},
      {"fig9", Fig9, PaperClaimStanding},
      {"fig11", Fig11,
       [](const std::string&) {
         return std::string("reported: the paper's statement checked on our numbers (docs/reproduce_fig11.md)");
       }},
      {"table2", Table2, PaperClaimStanding},
      {"benchmark", Benchmark,
       [](const std::string&) { return std::string("reported: what docs/benchmark.md says, checked on these numbers"); }},
      {"marths", Marths,
       [](const std::string&) {
         return std::string("reported: the comparison of docs/marths.md, checked on these numbers");
       }},
      {"nonlinear", Nonlinear,
       [](const std::string&) {
         return std::string("required: the test suite asserts the linear rows against the closed form "
                            "(docs/reproduce_nonlinear.md)");
       }},
  };
  return studies;
}

std::vector<std::string> StudyNames() {
  std::vector<std::string> names;
  for (const auto& s : Studies()) names.push_back(s.name);
  return names;
}

const Study& StudyNamed(const std::string& name) {
  for (const auto& s : Studies()) {
    if (s.name == name) return s;
  }
  throw Error("reproduce " + name, fmt::format("no such study (one of {})", fmt::join(StudyNames(), ", ")));
}

std::string Standing(const Study& study, const std::string& plant, bool quick) {
  std::string s = study.claims(plant);
  if (quick && study.quick_matters) s += "; --quick: shorter records, noisier numbers than the full run";
  return s;
}

std::string ClaimLine(const Claim& c, const std::string& standing) {
  std::string s;
  Appendf(&s, "%s %s\n    %s\n    (%s)\n", c.holds ? "[holds]" : "[does not hold]", c.text.c_str(), c.detail.c_str(),
          standing.c_str());
  return s;
}

}  // namespace rths::studies
