// Table 2 (docs/experiments.md E3): tracking of predefined BLWN displacement histories, 36 lockstep
// runs (3 conditions x 6 controllers x 2 bands), Eq. 31 on the logged r_k, y_k.
#include "studies/table2.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "core/error.h"
#include "io/csv.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::CsvWriter;
using io::FormatSig;

namespace {

constexpr double kBands[] = {5.0, 15.0};
constexpr double kFullDurationS = 60.0;   // docs/models.md section 9: at least 60 s
// --quick: 6 s for the compensated rows; 20 s for the "None" rows, whose check against the paper
// (within 2.5 points) needs a steadier number: with seed 1 the 20 s None errors on the linear plants
// are within 0.5 points of the 60 s ones, and over 30 seeds their spread is 0.6-1.1 points (sd).
constexpr double kQuickDurationS = 6.0;
constexpr double kQuickNoneDurationS = 20.0;
constexpr double kTaperS = 0.5;           // raised-cosine fade-in of the desired record


std::string BandText(double band_hz) { return band_hz < 10 ? "0-5" : "0-15"; }

const Table2Row* Find(const std::vector<Table2Row>& rows, const std::string& cond, const std::string& name,
                      const std::string& band) {
  for (const auto& r : rows) {
    if (r.condition == cond && r.controller == name && r.band == band) return &r;
  }
  return nullptr;
}

// Three significant digits, trailing zeros kept ("12.0", "0.340"), as the paper prints them.
std::string Pct(double v) { return std::isfinite(v) ? fmt::format("{:#.3g}", v) : FormatSig(v); }

}  // namespace

std::vector<Table2Controller> Table2Controllers() {
  // Table 2 of the paper, in its order; names as in Table 1 (short names).
  return {
      {"0.0A", "None", 16.0, 42.9, "16.0", "42.9", ControllerKind("none")},
      {"0.0A", "3rd Poly 8ms", 1.22, 12.8, "1.22", "12.8", ControllerDelay("poly3", 8.0)},
      {"0.0A", "Lead Comp 8ms", 1.95, 13.3, "1.95", "13.3", ControllerDelay("lead", 8.0)},
      {"0.0A", "G_FF,0.0A + LP", 1.01, 4.27, "1.01", "4.27", ControllerModel("ff_lp", "0.0A")},
      {"0.0A", "G_FF,0.0A", 0.942, 3.45, "0.942", "3.45", ControllerModel("ff", "0.0A")},
      {"0.0A", "G_FF,avgA + LQG", 1.16, 3.89, "1.16", "3.89", ControllerModel("ff_lqg", "avg")},
      {"2.5A", "None", 20.1, 51.7, "20.1", "51.7", ControllerKind("none")},
      {"2.5A", "3rd Poly 10ms", 2.04, 25.9, "2.04", "25.9", ControllerDelay("poly3", 10.0)},
      {"2.5A", "Lead Comp 10ms", 3.34, 15.1, "3.34", "15.1", ControllerDelay("lead", 10.0)},
      {"2.5A", "G_FF,2.5A + LP", 2.55, 9.40, "2.55", "9.40", ControllerModel("ff_lp", "2.5A")},
      {"2.5A", "G_FF,2.5A", 2.27, 4.68, "2.27", "4.68", ControllerModel("ff", "2.5A")},
      {"2.5A", "G_FF,avgA + LQG", 1.41, 5.57, "1.41", "5.57", ControllerModel("ff_lqg", "avg")},
      {"pulse", "None", 18.1, 49.2, "18.1", "49.2", ControllerKind("none")},
      {"pulse", "3rd Poly 9ms", 1.80, 18.3, "1.80", "18.3", ControllerDelay("poly3", 9.0)},
      {"pulse", "Lead Comp 9ms", 2.97, 16.0, "2.97", "16.0", ControllerDelay("lead", 9.0)},
      {"pulse", "Bumpless + LP", 2.04, 8.45, "2.04", "8.45", ControllerKind("bumpless_lp")},
      {"pulse", "G_FF,avgA", 1.93, 6.35, "1.93", "6.35", ControllerModel("ff", "avg")},
      {"pulse", "G_FF,avgA + LQG", 1.09, 4.72, "1.09", "4.72", ControllerModel("ff_lqg", "avg")},
  };
}

scenario::Scenario Table2Scenario(const Table2Controller& row, double band_hz, const std::string& plant,
                                  double duration_s) {
  scenario::Scenario s;
  s.run.name = Slug(fmt::format("table2 {} {}hz {}", row.condition, BandText(band_hz), row.name));
  s.run.dt_s = kTable2DtS;
  s.run.duration_s = duration_s;
  s.structure.mode = models::StructureMode::kPredefined;
  s.structure.derivatives = models::Derivatives::kExtrapolated;  // Eqs. 20-22, the causal RTHS path
  // docs/models.md section 9: 8th-order Butterworth BLWN, 2 s discarded, fixed seed; faded in over
  // 0.5 s so that the actuator is not asked for a step at k = 0 (docs/safety.md).
  s.structure.desired = signal::SignalSpec{};
  s.structure.desired.kind = signal::SignalKind::kBlwn;
  s.structure.desired.band_hz = band_hz;
  s.structure.desired.rms = band_hz < 10 ? 2.78 : 0.595;
  s.structure.desired.seed = 1;
  s.structure.desired.discard_s = 2.0;
  s.structure.desired.taper_s = kTaperS;
  s.controller = row.controller;
  s.plant.kind = ParseName(models::kPlantKindNames, plant, "--plant");
  s.plant.actuator = models::ServoPreset(row.condition == "0.0A"   ? "0.0A"
                                           : row.condition == "2.5A" ? "2.5A"
                                                                     : "avg");
  s.plant.specimen = models::Specimen::kMrDamper;
  if (row.condition == "0.0A") {
    s.semiactive.mode = control::SemiactiveMode::kPassiveOff;
  } else if (row.condition == "2.5A") {
    s.semiactive.mode = control::SemiactiveMode::kPassiveOn;
  } else {
    s.semiactive.mode = control::SemiactiveMode::kPulse;  // 0.5 Hz, 50 % duty between 0 and 2.5 A
    s.semiactive.pulse_hz = 0.5;
    s.semiactive.pulse_duty = 0.5;
  }
  s.semiactive.max_current_A = 2.5;
  return s;
}

namespace {

/// Our number of a row, NaN if the table has none.
double Ours(const std::vector<Table2Row>& rows, const std::string& c, const std::string& n, const std::string& b) {
  const Table2Row* r = Find(rows, c, n, b);
  return r ? r->ours_pct : std::nan("");
}

Claim ProposedBeatsBaselines(const std::vector<Table2Row>& rows) {
  auto ours = [&](const std::string& c, const std::string& n, const std::string& b) { return Ours(rows, c, n, b); };
  const std::map<std::string, std::vector<std::string>> names{
      {"0.0A", {"G_FF,0.0A", "None", "3rd Poly 8ms", "Lead Comp 8ms"}},
      {"2.5A", {"G_FF,2.5A", "None", "3rd Poly 10ms", "Lead Comp 10ms"}},
      {"pulse", {"G_FF,avgA", "None", "3rd Poly 9ms", "Lead Comp 9ms"}}};
  Claim c{"(1) at 0-15 Hz the proposed FF for the condition (G_FF,0.0A; G_FF,2.5A; G_FF,avgA "
          "under the pulse) beats None, the polynomial and the lead",
          true, ""};
  for (const char* cond : {"0.0A", "2.5A", "pulse"}) {
    const auto& n = names.at(cond);
    const double ff = ours(cond, n[0], "0-15");
    std::string beaten, not_beaten;
    for (std::size_t j = 1; j < n.size(); ++j) {
      const double other = ours(cond, n[j], "0-15");
      const bool beats = ff < other;
      c.holds = c.holds && beats;
      std::string& list = beats ? beaten : not_beaten;
      list += fmt::format("{}{} {}", list.empty() ? "" : ", ", n[j], Pct(other));
    }
    std::string d = fmt::format("{}: {} {}", cond, n[0], Pct(ff));
    if (!beaten.empty()) d += " beats " + beaten;
    if (!not_beaten.empty()) d += (beaten.empty() ? " does not beat " : " but not ") + not_beaten;
    c.detail += (c.detail.empty() ? "" : "; ") + d;
  }
  return c;
}

Claim LqgBeatsFfUnderPulse(const std::vector<Table2Row>& rows) {
  auto ours = [&](const std::string& c, const std::string& n, const std::string& b) { return Ours(rows, c, n, b); };
  Claim c{"(2) under the pulse, G_FF,avgA + LQG beats G_FF,avgA in both bands", true, ""};
  for (const char* band : {"0-5", "0-15"}) {
    const double lqg = ours("pulse", "G_FF,avgA + LQG", band), ff = ours("pulse", "G_FF,avgA", band);
    c.holds = c.holds && lqg < ff;
    c.detail += fmt::format("{}{} Hz: {} {} {}", c.detail.empty() ? "" : "; ", band, Pct(lqg),
                            lqg < ff ? "<" : ">=", Pct(ff));
  }
  return c;
}

Claim EveryCompensatorBeatsNone(const std::vector<Table2Row>& rows) {
  auto ours = [&](const std::string& c, const std::string& n, const std::string& b) { return Ours(rows, c, n, b); };
  Claim c{"(3) every compensator beats None", true, ""};
  std::vector<std::string> fails;
  for (const auto& r : rows) {
    if (r.controller == "None") continue;
    const double none = ours(r.condition, "None", r.band);
    if (!(r.ours_pct < none)) {
      c.holds = false;
      fails.push_back(fmt::format("{} {} Hz {}: {} >= None {}", r.condition, r.band, r.controller,
                                  Pct(r.ours_pct), Pct(none)));
    }
  }
  if (fails.empty()) {
    c.detail = "every one of the 30 compensated rows is below its condition's None row";
  } else {
    for (const auto& f : fails) c.detail += (c.detail.empty() ? "" : "; ") + f;
  }
  return c;
}

Claim NoneRowsMatchPaper(const std::vector<Table2Row>& rows) {
  Claim c{"(4) the \"None\" rows within 2.5 points of the paper", true, ""};
  for (const auto& r : rows) {
    if (r.controller != "None") continue;
    const double diff = r.ours_pct - r.paper_pct;
    const bool ok = std::abs(diff) <= 2.5;
    c.holds = c.holds && ok;
    c.detail += fmt::format("{}{} {} Hz: {} vs {} ({:+.1f}{})", c.detail.empty() ? "" : "; ", r.condition,
                            r.band, Pct(r.ours_pct), r.paper_text, diff, ok ? "" : ", outside");
  }
  return c;
}

}  // namespace

std::vector<Claim> CheckTable2Claims(const std::vector<Table2Row>& rows) {
  return {ProposedBeatsBaselines(rows), LqgBeatsFfUnderPulse(rows), EveryCompensatorBeatsNone(rows),
          NoneRowsMatchPaper(rows)};
}

namespace {

std::string PlantDescription(const std::string& plant) {
  if (plant == "linear") {
    return "the linear three-pole servohydraulic models, ZOH-discretised at 2 kHz: Eq. 28 for "
           "0.0 A, Eq. 29 for 2.5 A, Eq. 30 (average) under the pulse; the MR damper (Eqs. 32-40) is "
           "attached and driven, but a linear plant's displacement does not feel its force";
  }
  return "the physics-based servohydraulic actuator (docs/models.md section 5: servovalve, oil column, "
         "piston) loaded by the MR damper (Eqs. 32-40) at the condition's current";
}

/// The section "Order of the controllers, best first": the paper's and ours per condition and band.
void WriteOrder(std::ostream& md, const std::vector<Table2Row>& rows) {
  md << "\n## Order of the controllers, best first\n\n"
     << "Where ours differs from the paper's order it is a finding about the plant, not a failure "
        "(docs/experiments.md E3; docs/models.md section 10: on a linear plant FF + LP falls behind the "
        "polynomial and the lead at 0-15 Hz).\n\n"
     << "| Condition | Band | Paper | Ours | Same order |\n|---|---|---|---|---|\n";
  for (const char* cond : {"0.0A", "2.5A", "pulse"}) {
    for (const char* band : {"0-5", "0-15"}) {
      std::vector<const Table2Row*> sel;
      for (const auto& r : rows) {
        if (r.condition == cond && r.band == band) sel.push_back(&r);
      }
      auto paper = sel, ours = sel;
      std::stable_sort(paper.begin(), paper.end(), [](auto* x, auto* y) { return x->paper_pct < y->paper_pct; });
      std::stable_sort(ours.begin(), ours.end(), [](auto* x, auto* y) { return x->ours_pct < y->ours_pct; });
      auto join = [](const std::vector<const Table2Row*>& v) {
        std::string s;
        for (auto* r : v) s += (s.empty() ? "" : " < ") + r->controller;
        return s;
      };
      md << fmt::format("| {} | {} Hz | {} | {} | {} |\n", cond, band, join(paper), join(ours),
                        join(paper) == join(ours) ? "yes" : "no");
    }
  }
}

void WriteMarkdown(const fs::path& file, const ReproduceOptions& opts, const std::vector<Table2Row>& rows,
                   const std::vector<Claim>& claims, double quick_s) {
  std::ofstream md(file);
  if (!md) throw Error(file.string(), "cannot open for writing");
  const std::string stamp = UtcStamp();
  md << "# Table 2: tracking performance for predefined displacement histories\n\n"
     << fmt::format("Made by `rths reproduce table2{} --plant {}` on {}.\n\n", opts.quick ? " --quick" : "",
                    opts.plant, stamp)
     << "**Plant: " << opts.plant << "** — " << PlantDescription(opts.plant) << ".\n\n"
     << "Each number is Eq. 31, the RMS error of the measured displacement y_k against the desired "
        "r_k over every step of one lockstep run (2 kHz). Desired displacement: band-limited white "
        "noise (docs/models.md section 9: 8th-order Butterworth, 2 s discarded, seed 1, faded in over 0.5 s), "
        "0-5 Hz RMS "
        "2.78 mm or 0-15 Hz RMS 0.595 mm, "
     << (opts.quick ? fmt::format("{:g} s records (--quick; the \"None\" rows {:g} s)", quick_s, kQuickNoneDurationS)
                    : fmt::format("{:g} s records", kFullDurationS))
     << ". Current: 0.0 A, 2.5 A, or a 0.5 Hz pulse between 0.0 and 2.5 A (50 % duty), through "
        "the driver dynamics of Eq. 40. Every run's folder (scenario.toml, log.lcm, summary.json) "
        "is under `runs/`.\n\n"
     << "| Condition | Controller | 0-5 Hz paper [%] | 0-5 Hz ours [%] | 0-15 Hz paper [%] | 0-15 Hz ours [%] |\n"
     << "|---|---|---:|---:|---:|---:|\n";
  for (const auto& row : Table2Controllers()) {
    const Table2Row* a = Find(rows, row.condition, row.name, "0-5");
    const Table2Row* b = Find(rows, row.condition, row.name, "0-15");
    md << fmt::format("| {} | {} | {} | {} | {} | {} |\n", row.condition, row.name, row.paper_text_5,
                      a ? Pct(a->ours_pct) : "-", row.paper_text_15, b ? Pct(b->ours_pct) : "-");
  }
  md << "\n## The paper's claims (docs/experiments.md E3), checked on this table\n\n";
  for (const auto& c : claims) {
    md << ClaimMarkdown(c);
  }
  WriteOrder(md, rows);
}

}  // namespace


namespace {

/// The specs of the paper's 36 rows (condition x controller x band, in the paper's order) and the
/// rows, in the same order.
std::vector<RunSpec> Table2Specs(const ReproduceOptions& opts, std::vector<Table2Row>* rows) {
  std::vector<RunSpec> specs;
  for (const auto& row : Table2Controllers()) {
    for (double band : kBands) {
      const double duration = !opts.quick ? kFullDurationS : row.name == "None" ? kQuickNoneDurationS : kQuickDurationS;
      Table2Row r;
      r.condition = row.condition;
      r.controller = row.name;
      r.band = BandText(band);
      r.paper_pct = band < 10 ? row.paper_pct_5 : row.paper_pct_15;
      r.paper_text = band < 10 ? row.paper_text_5 : row.paper_text_15;
      r.duration_s = duration;
      r.run_dir = opts.out_dir / "runs" / Slug(fmt::format("{} {}hz {}", row.condition, r.band, row.name));
      specs.push_back({fmt::format("{} {} Hz {}", row.condition, r.band, row.name),
                       Table2Scenario(row, band, opts.plant, duration), r.run_dir});
      rows->push_back(r);
    }
  }
  return specs;
}

/// --extended: its rows, and per row the index in the specs of the run it reads.
struct ExtendedPlan {
  std::vector<Table2ExtendedRow> rows;
  std::vector<std::size_t> source;
};

/// The extended row of controller `c`: a Table 2 row's run (none, ff, ff_lqg), or a new run
/// appended to `specs` (ats, ambc, pi_lead).
Table2ExtendedRow ExtendedRow(const ReproduceOptions& opts, const Table2ExtendedController& c, double band,
                              const std::vector<Table2Row>& rows, std::vector<RunSpec>* specs, ExtendedPlan* plan) {
  Table2ExtendedRow e;
  e.condition = c.condition;
  e.band = BandText(band);
  e.controller = c.name;
  e.table2_row = c.table2_row;
  if (!c.table2_row.empty()) {
    std::size_t i = 0;
    while (i < rows.size() &&
           !(rows[i].condition == e.condition && rows[i].controller == c.table2_row && rows[i].band == e.band)) {
      ++i;
    }
    if (i == rows.size()) throw Error("table2 --extended", "no Table 2 row " + c.table2_row);
    e.duration_s = rows[i].duration_s;
    e.run_dir = rows[i].run_dir;
    plan->source.push_back(i);
    return e;
  }
  e.duration_s = opts.quick ? kQuickDurationS : kFullDurationS;
  e.run_dir = opts.out_dir / "runs" / Slug(fmt::format("{} {}hz {}", c.condition, e.band, c.name));
  Table2Controller row{c.condition, c.name, 0.0, 0.0, "", "", c.controller};
  plan->source.push_back(specs->size());
  specs->push_back({fmt::format("{} {} Hz {}", c.condition, e.band, c.name),
                    Table2Scenario(row, band, opts.plant, e.duration_s), e.run_dir});
  return e;
}

/// The extended table's rows, condition x band x controller; its new runs appended to `specs`,
/// after the paper's.
ExtendedPlan ExtendedSpecs(const ReproduceOptions& opts, const PiLeadDesign& pi_lead,
                           const std::vector<Table2Row>& rows, std::vector<RunSpec>* specs) {
  ExtendedPlan plan;
  for (const char* cond : {"0.0A", "2.5A", "pulse"}) {
    const auto ctrls = Table2ExtendedControllers(cond, pi_lead);
    for (double band : kBands) {
      for (const auto& c : ctrls) plan.rows.push_back(ExtendedRow(opts, c, band, rows, specs, &plan));
    }
  }
  return plan;
}

/// The specs' indices, longest run first (stable), so that the threads finish together.
std::vector<std::size_t> LongestFirst(const std::vector<RunSpec>& specs) {
  std::vector<std::size_t> order(specs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return specs[a].scenario.run.duration_s > specs[b].scenario.run.duration_s;
  });
  return order;
}

/// The table: Eq. 31 of each of the paper's rows (results[j] ran specs[order[j]]). Throws
/// rths::Error naming every paper row that failed.
void Table2Table(const std::vector<RunResult>& results, const std::vector<std::size_t>& order,
                 const ReproduceOptions& opts, std::vector<Table2Row>* rows) {
  std::vector<std::string> failed;
  for (std::size_t j = 0; j < results.size(); ++j) {
    if (order[j] >= rows->size()) continue;  // an extended run: its row says how it went
    (*rows)[order[j]].ours_pct = results[j].tracking_pct;
    if (!results[j].ok) failed.push_back(fmt::format("  {}: {}", results[j].label, results[j].error));
  }
  if (failed.empty()) return;
  std::string msg = fmt::format("{} of {} runs failed (their folders are under {}):", failed.size(), rows->size(),
                                (opts.out_dir / "runs").string());
  for (const auto& f : failed) msg += "\n" + f;
  throw Error("table2", msg);
}

void WriteCsv(const std::vector<Table2Row>& rows, const fs::path& file) {
  CsvWriter csv(file, {"condition", "controller", "band_hz", "paper_pct", "ours_pct"});
  for (const auto& r : rows) csv.Row({r.condition, r.controller, r.band, r.paper_text, FormatSig(r.ours_pct, 4)});
  csv.Close();
}

/// --extended: how each row's run went (after any --set), its measurements and its files.
std::vector<Table2ExtendedRow> FinishExtended(ExtendedPlan plan, const std::vector<std::size_t>& order,
                                              const std::vector<RunSpec>& ordered,
                                              const std::vector<RunResult>& results, const ReproduceOptions& opts,
                                              const PiLeadDesign& pi_lead) {
  std::vector<std::size_t> position(order.size());  // spec i ran as ordered[position[i]]
  for (std::size_t j = 0; j < order.size(); ++j) position[order[j]] = j;
  for (std::size_t i = 0; i < plan.rows.size(); ++i) {
    const std::size_t j = position[plan.source[i]];
    plan.rows[i].stopped = StoppedText(results[j]);
    plan.rows[i].steps_planned = ordered[j].scenario.steps();
    plan.rows[i].duration_s = ordered[j].scenario.run.duration_s;
  }
  MeasureExtendedRows(&plan.rows, opts.jobs);
  WriteTable2Extended(opts, plan.rows, pi_lead);
  return plan.rows;
}

PiLeadDesign LoggedPiLead(const ReproduceOptions& opts) {
  PiLeadDesign pi_lead = DesignPiLead(models::ServoPreset("avg"), kTable2DtS);
  if (opts.log) {
    std::string text = pi_lead.Describe();
    while (!text.empty() && text.back() == '\n') text.pop_back();
    opts.log(text);
  }
  return pi_lead;
}

}  // namespace

Table2Result ReproduceTable2(const ReproduceOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  RequirePlant(opts.plant, opts.out_dir);
  Table2Result res;
  std::vector<RunSpec> specs = Table2Specs(opts, &res.rows);
  // --extended: the new runs (ats, ambc, pi_lead) after the paper's; none, ff and ff_lqg are the
  // Table 2 rows' runs.
  ExtendedPlan plan;
  if (opts.extended) {
    res.pi_lead = LoggedPiLead(opts);
    plan = ExtendedSpecs(opts, *res.pi_lead, res.rows, &specs);
  }
  const std::vector<std::size_t> order = LongestFirst(specs);
  std::vector<RunSpec> ordered;
  for (std::size_t i : order) ordered.push_back(specs[i]);
  const std::string intro =
      fmt::format("table2: {} lockstep runs on the {} plant, {} at a time", ordered.size(), opts.plant, opts.jobs);
  const auto results = RunStudyBatch(&ordered, opts, intro, [&](std::size_t done, std::size_t total, const RunResult& r) {
    if (!opts.log) return;
    opts.log(r.ok ? fmt::format("  [{:2}/{}] {:<32} {:8.3f} %  ({:.1f} s)", done, total, r.label, r.tracking_pct,
                                r.wall_s)
                  : fmt::format("  [{:2}/{}] {:<32} FAILED: {}", done, total, r.label, r.error));
  });
  Table2Table(results, order, opts, &res.rows);
  res.claims = CheckTable2Claims(res.rows);
  WriteCsv(res.rows, opts.out_dir / "table2.csv");
  WriteMarkdown(opts.out_dir / "table2.md", opts, res.rows, res.claims, kQuickDurationS);
  if (opts.extended) res.extended = FinishExtended(std::move(plan), order, ordered, results, opts, *res.pi_lead);
  res.wall_s = SecondsSince(t0);
  return res;
}

}  // namespace rths::studies
