#include "studies/marths.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "core/error.h"
#include "core/interrupt.h"
#include "ident/design_model.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/source_tree.h"
#include "models/marths_files.h"
#include "signal/history.h"
#include "signal/stats.h"
#include "studies/marths_lockstep.h"
#include "studies/marths_loop.h"

namespace rths::studies {

namespace mm = models::marths;

namespace {

constexpr std::uint64_t kPlantSeed = 47;     // the perturbed plants' draws, in order
constexpr std::uint64_t kNominalNoise = 123;  // the reference code's nominal seed; perturbed i: 123 + i

MarthsCompensator KindOf(const std::string& name) {
  return ValueOf(control::kMarthsCompensatorNames, name).value_or(MarthsCompensator::kNone);
}

std::string MarthsData(const ReproduceOptions& opts, const std::string& file) {
  return io::FindSourceFile("data/marths/" + file, opts.source_dir).string();
}

/// --quick: the records' first 20 s (the strong motion of each lies within it).
constexpr double kQuickSeconds = 20.0;

/// A benchmark record x 0.4 at t_k = k dt for every t_k up to its last time (as Simulink's From
/// File and the model's stop time give it); --quick: up to kQuickSeconds.
std::vector<double> MarthsGround(const ReproduceOptions& opts, const std::string& file, double dt_s) {
  const signal::HistoryRecord rec = signal::ReadHistoryFile(MarthsData(opts, file), 0.0);
  const double end_s = opts.quick ? std::min(kQuickSeconds, rec.t.back()) : rec.t.back();
  const auto n = static_cast<std::size_t>(std::floor(end_s / dt_s + 1e-9)) + 1;
  return signal::ResampleHistory(rec, 0.0, 0.4, dt_s, n, 0.0);
}

/// The benchmark's records: name and file.
const std::pair<const char*, const char*> kMarthsRecords[3] = {
    {"El Centro", "elcentro_m_s2.txt"}, {"Kobe", "kobe_m_s2.txt"}, {"Morgan Hill", "morgan_hill_m_s2.txt"}};

/// The configuration every run shares (data read once).
MarthsLoopConfig SharedConfig(const ReproduceOptions& opts) {
  auto data = [&](const char* file) { return MarthsData(opts, file); };
  MarthsLoopConfig c;
  c.K_ref = mm::ReadMatrixCsv(data("reference_K_N_per_m.csv"));
  c.M_ref = mm::ReadMatrixCsv(data("reference_M_kg.csv"));
  c.ag_m_s2 = MarthsGround(opts, kMarthsRecords[0].second, c.dt_s);
  c.rig.noise_mm = mm::SensorNoiseMm(c.dt_s);
  const mm::RodeacInitialParameters p = mm::ReadRodeacParameters(data("rodeac_initial_parameters.txt"));
  const auto models = ident::MarthsDesignModels(c.compensators.design_plant, c.dt_s);
  for (int i = 0; i < 2; ++i) {
    c.compensators.rodeac[i] = control::MakeRodeacDesign(p.theta0[i], p.P0[i], 1.0 / c.dt_s);
    c.compensators.per_actuator[i].model = models[i];
  }
  return c;
}

void WriteRows(const std::filesystem::path& file, const std::vector<MarthsRow>& rows) {
  std::vector<std::string> header = {"compensator", "run"};
  for (const auto& [k, v] : rows.front().j.Items()) header.push_back(k);
  for (const char* h : {"max_V_1", "max_V_2", "saturated"}) header.push_back(h);
  io::CsvWriter csv(file, header);
  for (const MarthsRow& r : rows) {
    std::vector<std::string> f = {r.compensator, r.run};
    for (const auto& [k, v] : r.j.Items()) f.push_back(fmt::format("{:.6g}", v));
    f.push_back(fmt::format("{:.4f}", r.max_volts[0]));
    f.push_back(fmt::format("{:.4f}", r.max_volts[1]));
    f.push_back(r.saturated ? "yes" : "no");
    csv.Row(f);
  }
  csv.Close();
}

void WriteSummary(const ReproduceOptions& opts, const MarthsStudy& s) {
  const auto keys = s.rows.front().j.Items();
  io::CsvWriter csv(opts.out_dir / "marths_summary.csv", {"compensator", "criterion", "nominal", "perturbed_mean",
                                                          "perturbed_std", "perturbed_n"});
  std::ofstream md(opts.out_dir / "marths.md");
  md << "# maRTHS benchmark, El Centro x 0.4, 1024 Hz, sensor noise on (rths reproduce marths)\n\n"
     << fmt::format("Nominal plant, and the mean (sample std) over {} perturbed plants. J1 in ms, the rest in %. "
                    "docs/marths.md explains every column.\n\n",
                    s.perturbed);
  md << "| criterion |";
  for (const auto& c : MarthsCompensatorNames()) md << " " << c << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < MarthsCompensatorNames().size(); ++i) md << "---|";
  md << "\n";
  for (const auto& [key, unused] : keys) {
    md << "| " << key << " |";
    for (const auto& c : MarthsCompensatorNames()) {
      const double nom = MarthsNominalValue(s.rows, c, key);
      const signal::Spread sp = MarthsPerturbedSpread(s.rows, c, key);
      csv.Row({c, key, fmt::format("{:.6g}", nom), fmt::format("{:.6g}", sp.mean), fmt::format("{:.6g}", sp.std),
               std::to_string(sp.n)});
      md << fmt::format(" {:.2f}; {:.2f} ({:.2f}) |", nom, sp.mean, sp.std);
    }
    md << "\n";
  }
  csv.Close();
  md << "\nLargest command [V] (nominal run) and whether any run's commands exceeded 3.8 V on both actuators:\n\n";
  for (const auto& c : MarthsCompensatorNames()) {
    bool any = false;
    double v1 = 0, v2 = 0;
    for (const MarthsRow& r : s.rows) {
      if (r.compensator != c) continue;
      any = any || r.saturated;
      if (r.run == "nominal") v1 = r.max_volts[0], v2 = r.max_volts[1];
    }
    md << fmt::format("- {}: {:.3f} V, {:.3f} V; {}\n", c, v1, v2, any ? "NOT realizable" : "realizable");
  }
  md << "\n";
  for (const Claim& c : s.claims) md << ClaimMarkdown(c);
}

void WriteFigure(const ReproduceOptions& opts, const MarthsStudy& s) {
  const auto& names = MarthsCompensatorNames();
  auto series = [&](const std::string& title, const std::string& key, bool nominal, const std::string& color) {
    io::Series x = io::MakeSeries(title, color);
    for (const auto& c : names) x.y.push_back(nominal ? MarthsNominalValue(s.rows, c, key) : MarthsPerturbedSpread(s.rows, c, key).mean);
    return x;
  };
  const auto& col = io::ReadableColors();
  io::Figure f;
  f.name = "marths";
  f.title = fmt::format("maRTHS, El Centro x 0.4: nominal plant and mean of {} perturbed plants", s.perturbed);
  f.gnuplot = opts.gnuplot;
  f.columns = 1;
  f.panels.push_back(io::MakeBarPanel("Tracking: J2 (std of x_m - x_t over std of x_t)", "J2 [%]", names,
                                      {series("actuator 1, nominal", "J2_1_pct", true, col[0]),
                                       series("actuator 1, perturbed mean", "J2_1_pct", false, col[5]),
                                       series("actuator 2, nominal", "J2_2_pct", true, col[1]),
                                       series("actuator 2, perturbed mean", "J2_2_pct", false, col[3])}));
  f.panels.push_back(io::MakeBarPanel("Interface against the reference structure: J7", "J7 [%]", names,
                                      {series("translation, nominal", "J7_X_pct", true, col[0]),
                                       series("translation, perturbed mean", "J7_X_pct", false, col[5]),
                                       series("rotation, nominal", "J7_TH_pct", true, col[1]),
                                       series("rotation, perturbed mean", "J7_TH_pct", false, col[3])}));
  for (auto& p : f.panels) {
    p.log_y = true;
    p.key = "outside right top";
    p.right_margin_chars = io::KeyMarginChars({&p});
  }
  io::Plot(f, opts.out_dir);
}

/// marths_history.png: the nominal El Centro runs in time: each actuator's target and the tracking
/// errors of rodeac, ff_lqg and mimo_ff (none's, 20-50 times larger, would hide them: its J2 is in the
/// title), and the interface rotation against the reference structure's (every 2nd sample drawn).
void WriteHistory(const ReproduceOptions& opts, const std::vector<MarthsRow>& rows,
                  const std::vector<MarthsLoopResult>& results) {
  const auto& col = io::ReadableColors();
  const std::vector<std::string> shown = {"rodeac", "ff_lqg", "mimo_ff"};
  auto nominal = [&](const std::string& c) -> const signal::MarthsSignals& {
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i].compensator == c && rows[i].run == "nominal") return results[i].signals;
    throw Error("rths reproduce marths", "no nominal run of " + c);
  };
  auto line = [&](const std::string& title, const std::string& color, const std::vector<double>& a,
                  const std::vector<double>* minus, double dt_s) {
    io::Series x = io::MakeSeries(title, color);
    for (std::size_t k = 0; k < a.size(); k += 2) {
      x.x.push_back(static_cast<double>(k) * dt_s);
      x.y.push_back(minus ? a[k] - (*minus)[k] : a[k]);
    }
    return x;
  };
  io::Figure f;
  f.name = "marths_history";
  f.title = "maRTHS, El Centro x 0.4, nominal plant, sensor noise on";
  f.gnuplot = opts.gnuplot;
  f.columns = 1;
  const signal::MarthsSignals& ref = nominal("none");
  for (int a = 0; a < 2; ++a) {
    io::Panel t = io::MakePanel(fmt::format("Actuator {}: target x_t", a + 1), "t [s]", "x_t [mm]");
    t.series.push_back(line("target (none's run)", col[0], a == 0 ? ref.xa1_t : ref.xa2_t, nullptr, ref.dt_s));
    t.key = "outside right top";
    f.panels.push_back(t);
    io::Panel e = io::MakePanel(
        fmt::format("Actuator {}: tracking error x_m - x_t (none: J2 = {:.1f} %, not drawn)", a + 1,
                    MarthsNominalValue(rows, "none", a == 0 ? "J2_1_pct" : "J2_2_pct")),
        "t [s]", "error [mm]");
    for (std::size_t i = 0; i < shown.size(); ++i) {
      const signal::MarthsSignals& g = nominal(shown[i]);
      e.series.push_back(line(shown[i], col[i + 1], a == 0 ? g.xa1_m : g.xa2_m, a == 0 ? &g.xa1_t : &g.xa2_t, g.dt_s));
    }
    e.key = "outside right top";
    f.panels.push_back(e);
  }
  io::Panel r = io::MakePanel("Interface rotation: estimated from the strokes (mimo_ff) and the reference structure's",
                              "t [s]", "rotation [rad]");
  r.series.push_back(line("reference", col[0], ref.r_ref, nullptr, ref.dt_s));
  r.series.push_back(line("estimated, mimo_ff", col[3], nominal("mimo_ff").r_hat, nullptr, ref.dt_s));
  r.key = "outside right top";
  f.panels.push_back(r);
  std::vector<const io::Panel*> all;
  for (const auto& p : f.panels) all.push_back(&p);
  const int margin = io::KeyMarginChars(all);
  for (auto& p : f.panels) p.right_margin_chars = margin;
  io::Plot(f, opts.out_dir);
}

std::vector<Claim> MarthsClaims(const MarthsStudy& s) {
  std::vector<Claim> claims;
  auto j2 = [&](const std::string& c, const std::string& run, int a) {
    for (const MarthsRow& r : s.rows)
      if (r.compensator == c && r.run == run) return a == 1 ? r.j.J2_1_pct : r.j.J2_2_pct;
    return std::nan("");
  };
  {
    Claim c{"every compensator tracks both actuators better than none (J2, nominal plant)", true, ""};
    for (const auto& name : MarthsCompensatorNames()) {
      if (name == "none") continue;
      for (int a = 1; a <= 2; ++a) c.holds = c.holds && j2(name, "nominal", a) < j2("none", "nominal", a);
      c.detail += fmt::format("{} {:.2f} / {:.2f} %; ", name, j2(name, "nominal", 1), j2(name, "nominal", 2));
    }
    c.detail += fmt::format("none {:.2f} / {:.2f} %", j2("none", "nominal", 1), j2("none", "nominal", 2));
    claims.push_back(c);
  }
  {
    Claim c{"inverting the coupled 2 x 2 plant (mimo_ff) tracks better than the paper's feedforward per actuator (ff) "
            "on every plant: the actuators' coupling is what a decentralised inverse misses",
            true, ""};
    int better = 0, n = 0;
    for (const MarthsRow& r : s.rows) {
      if (r.compensator != "mimo_ff") continue;
      ++n;
      const bool b = r.j.J2_1_pct < j2("ff", r.run, 1) && r.j.J2_2_pct < j2("ff", r.run, 2);
      better += b;
      c.holds = c.holds && b;
    }
    c.detail = fmt::format("{} of {} plants", better, n);
    claims.push_back(c);
  }
  return claims;
}

void Configure(const std::string& compensator, MarthsLoopConfig* c) { c->compensators.kind = KindOf(compensator); }

/// The decisions table's runs (rows appended to `rows`, configs returned in the same order).
std::vector<MarthsLoopConfig> DecisionConfigs(const MarthsLoopConfig& shared, std::vector<MarthsDecisionRow>* rows) {
  std::vector<MarthsLoopConfig> out;
  for (const char* comp : {"none", "rodeac", "mimo_ff"}) {
    for (const char* variant : {"as coded", "exact inverse", "independent noise", "force one sample late",
                                "derivatives from rest", "no noise"}) {
      MarthsLoopConfig c = shared;
      c.rig.noise_seed = kNominalNoise;
      Configure(comp, &c);
      const std::string v = variant;
      if (v == "exact inverse") c.rig.inverse = mm::InverseForm::kExact;
      if (v == "independent noise") c.rig.identical_noise = false;
      if (v == "force one sample late") c.rig.force_delay_steps = 1;
      if (v == "derivatives from rest") c.rig.derivatives_from_rest = true;
      if (v == "no noise") c.rig.noise_mm = 0.0;
      rows->push_back({comp, v, {}});
      out.push_back(std::move(c));
    }
  }
  return out;
}

/// Runs every config, opts.jobs at a time; a run's records are kept only where keep_signals says
/// (6 MB a run), the others scored and dropped. Throws rths::Interrupted on Ctrl-C, rths::Error
/// naming the first run that failed.
std::vector<MarthsLoopResult> RunAll(const std::vector<MarthsLoopConfig>& configs, const ReproduceOptions& opts,
                                     const std::vector<bool>& keep_signals) {
  std::vector<MarthsLoopResult> results(configs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::string failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (std::size_t i; !stop && (i = next++) < configs.size();) {
      if (InterruptRequested()) {
        stop = true;
        return;
      }
      try {
        results[i] = RunMarthsLoop(configs[i]);
        if (!keep_signals[i]) results[i].signals = {};
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (failure.empty()) failure = fmt::format("run {}: {}", i + 1, e.what());
        stop = true;
      }
      if (opts.log && (i + 1) % 20 == 0) opts.log(fmt::format("marths: {} of {} runs started", i + 1, configs.size()));
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < std::max(1, opts.jobs); ++t) threads.emplace_back(work);
  for (auto& t : threads) t.join();
  if (InterruptRequested()) throw Interrupted("reproduce marths", "interrupted");
  if (!failure.empty()) throw Error("reproduce marths", failure);
  return results;
}

/// `stem`.csv (every criterion) and `stem`.md (a selection) of variant runs.
void WriteVariants(const std::filesystem::path& stem, const std::vector<MarthsDecisionRow>& rows,
                   const std::string& title, const std::string& intro) {
  std::vector<std::string> header = {"compensator", "variant"};
  for (const auto& [k, v] : rows.front().j.Items()) header.push_back(k);
  io::CsvWriter csv(stem.string() + ".csv", header);
  std::ofstream md(stem.string() + ".md");
  md << "# maRTHS: " << title << "\n\n" << intro << " J1 in ms, the rest in %.\n\n"
     << "| compensator | variant | J1,1 | J2,1 | J2,2 | J5,X | J5,TH | J7,X | J7,TH | J8,X2 | J10,X3 |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MarthsDecisionRow& r : rows) {
    std::vector<std::string> f = {r.compensator, r.variant};
    for (const auto& [k, v] : r.j.Items()) f.push_back(fmt::format("{:.6g}", v));
    csv.Row(f);
    md << fmt::format("| {} | {} | {:.2f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} |\n",
                      r.compensator, r.variant, r.j.J1_1_ms, r.j.J2_1_pct, r.j.J2_2_pct, r.j.J5_X_pct, r.j.J5_TH_pct,
                      r.j.J7_X_pct, r.j.J7_TH_pct, r.j.J8_X2_pct, r.j.J10_X3_pct);
  }
  csv.Close();
}

}  // namespace

const std::vector<std::string>& MarthsCompensatorNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& n : control::kMarthsCompensatorNames) out.emplace_back(n.name);
    return out;
  }();
  return names;
}

signal::Spread MarthsPerturbedSpread(const std::vector<MarthsRow>& rows, const std::string& comp, const std::string& key) {
  std::vector<double> v;
  for (const MarthsRow& r : rows) {
    if (r.compensator != comp || r.run == "nominal") continue;
    for (const auto& [k, x] : r.j.Items()) {
      if (k == key) v.push_back(x);
    }
  }
  return signal::SpreadOf(v);
}

double MarthsNominalValue(const std::vector<MarthsRow>& rows, const std::string& comp, const std::string& key) {
  for (const MarthsRow& r : rows) {
    if (r.compensator != comp || r.run != "nominal") continue;
    for (const auto& [k, x] : r.j.Items()) {
      if (k == key) return x;
    }
  }
  return std::nan("");
}

namespace {

/// marths_lockstep.csv and .md: the shipped scenarios through the lockstep beside the loop.
void WriteLockstep(const std::filesystem::path& stem, const std::vector<MarthsLockstepRow>& rows) {
  std::vector<std::string> header = {"compensator", "source", "steps"};
  for (const auto& [k, v] : rows.front().lockstep.Items()) header.push_back(k);
  for (const char* h : {"max_V_1", "max_V_2", "realizable", "max_rel_diff", "wall_s"}) header.push_back(h);
  io::CsvWriter csv(stem.string() + ".csv", header);
  std::ofstream md(stem.string() + ".md");
  md << "# maRTHS: the shipped scenarios through the lockstep (rths reproduce marths)\n\n"
     << "scenarios/marths/elcentro_<compensator>.toml run by the five participants in this process (memq), "
        "scored from their logs, beside the in-process loop's nominal run (docs/marths.md \"Through the "
        "lockstep\"). J in % (J1 in ms).\n\n"
     << "| compensator | steps | J2,1 lockstep | J2,1 loop | J2,2 lockstep | J2,2 loop | J5,TH lockstep | J5,TH loop | "
        "largest rel. difference, J1-J10 | largest V | wall [s] |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MarthsLockstepRow& r : rows) {
    for (int source = 0; source < 2; ++source) {
      const signal::MarthsCriteria& j = source == 0 ? r.lockstep : r.loop;
      std::vector<std::string> f = {r.compensator, source == 0 ? "lockstep" : "loop", std::to_string(r.steps)};
      for (const auto& [k, v] : j.Items()) f.push_back(fmt::format("{:.9g}", v));
      f.push_back(source == 0 ? fmt::format("{:.4f}", r.max_volts[0]) : "");
      f.push_back(source == 0 ? fmt::format("{:.4f}", r.max_volts[1]) : "");
      f.push_back(source == 0 ? (r.realizable ? "yes" : "no") : "");
      f.push_back(source == 0 ? fmt::format("{:.3g}", r.max_rel_diff) : "");
      f.push_back(source == 0 ? fmt::format("{:.2f}", r.wall_s) : "");
      csv.Row(f);
    }
    md << fmt::format("| {} | {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.2g} | {:.3f} / {:.3f} | {:.1f} |\n",
                      r.compensator, r.steps, r.lockstep.J2_1_pct, r.loop.J2_1_pct, r.lockstep.J2_2_pct,
                      r.loop.J2_2_pct, r.lockstep.J5_TH_pct, r.loop.J5_TH_pct, r.max_rel_diff, r.max_volts[0],
                      r.max_volts[1], r.wall_s);
  }
  csv.Close();
}

Claim LockstepClaim(const std::vector<MarthsLockstepRow>& rows) {
  Claim c{"the shipped scenarios through the lockstep give the loop's J1-J10 (relative difference below 1e-9)", true,
          ""};
  double worst = 0.0;
  for (const MarthsLockstepRow& r : rows) {
    worst = std::max(worst, r.max_rel_diff);
    c.holds = c.holds && r.max_rel_diff < 1e-9;
  }
  c.detail = fmt::format("{} scenarios, largest relative difference {:.2g}", rows.size(), worst);
  return c;
}

}  // namespace

MarthsStudy ReproduceMarths(const ReproduceOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  MarthsStudy s;
  s.perturbed = opts.quick ? 2 : 20;
  const MarthsLoopConfig shared = SharedConfig(opts);
  std::vector<mm::PlantZpk> plants = {shared.compensators.design_plant};
  signal::GaussianState g = signal::MakeGaussian(kPlantSeed);
  for (int i = 0; i < s.perturbed; ++i) plants.push_back(mm::PerturbedPlantZpk(shared.compensators.design_plant, &g));
  for (const auto& comp : MarthsCompensatorNames()) {
    for (std::size_t p = 0; p < plants.size(); ++p) {
      MarthsRow r;
      r.compensator = comp;
      r.run = p == 0 ? "nominal" : fmt::format("perturbed_{}", p);
      s.rows.push_back(r);
    }
  }
  std::vector<MarthsLoopConfig> configs;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    MarthsLoopConfig c = shared;
    const std::size_t p = i % plants.size();
    c.plant = plants[p];
    c.rig.noise_seed = kNominalNoise + p;
    Configure(s.rows[i].compensator, &c);
    configs.push_back(std::move(c));
  }
  const auto decision_configs = DecisionConfigs(shared, &s.decisions);
  configs.insert(configs.end(), decision_configs.begin(), decision_configs.end());
  for (const auto& [record, file] : kMarthsRecords) {
    const std::vector<double> ag = MarthsGround(opts, file, shared.dt_s);
    for (const auto& comp : MarthsCompensatorNames()) {
      MarthsLoopConfig c = shared;
      c.ag_m_s2 = ag;
      c.rig.noise_seed = kNominalNoise;
      Configure(comp, &c);
      s.records.push_back({comp, record, {}});
      configs.push_back(std::move(c));
    }
  }
  std::vector<bool> keep(configs.size(), false);  // the nominal runs: marths_history.png
  for (std::size_t i = 0; i < s.rows.size(); ++i) keep[i] = s.rows[i].run == "nominal";
  const std::vector<MarthsLoopResult> results = RunAll(configs, opts, keep);
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    s.rows[i].j = results[i].j;
    s.rows[i].max_volts[0] = results[i].max_volts[0];
    s.rows[i].max_volts[1] = results[i].max_volts[1];
    s.rows[i].saturated = results[i].saturated;
  }
  for (std::size_t i = 0; i < s.decisions.size(); ++i) s.decisions[i].j = results[s.rows.size() + i].j;
  for (std::size_t i = 0; i < s.records.size(); ++i) {
    s.records[i].j = results[s.rows.size() + s.decisions.size() + i].j;
  }
  s.claims = MarthsClaims(s);
  std::filesystem::create_directories(opts.out_dir);
  const std::vector<MarthsLockstepRow> lockstep = RunMarthsScenarios(opts, s.rows, shared.ag_m_s2.size(), shared.dt_s);
  WriteLockstep(opts.out_dir / "marths_lockstep", lockstep);
  s.claims.push_back(LockstepClaim(lockstep));
  WriteRows(opts.out_dir / "marths.csv", s.rows);
  WriteSummary(opts, s);
  WriteFigure(opts, s);
  WriteHistory(opts, s.rows, results);
  WriteVariants(opts.out_dir / "marths_decisions", s.decisions,
                "what each of the reference code's ambiguous choices changes (nominal plant, El Centro x 0.4)",
                "Each row switches one choice of docs/marths.md \"Decisions\" away from the reference code's "
                "(\"as coded\").");
  WriteVariants(opts.out_dir / "marths_records", s.records, "the benchmark's three records x 0.4 (nominal plant)",
                "Every compensator under El Centro, Kobe and Morgan Hill, each scaled by 0.4, sensor noise on.");
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

}  // namespace rths::studies
