// The RTHS benchmark problem (Silva et al. 2020) as a study: identification, design, nominal and
// perturbed El Centro runs, J1-J9 (report/benchmark_study.h, docs/benchmark.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>

#include <fmt/format.h>

#include "core/error.h"
#include "io/benchmark_run.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/run_log.h"
#include "io/source_tree.h"
#include "report/benchmark_study.h"
#include "report/figures.h"

namespace rths::report {

namespace fs = std::filesystem;

namespace {

constexpr std::array<const char*, 9> kJNames = {"J1_ms",  "J2_pct", "J3_pct", "J4_pct", "J5_pct",
                                                "J6_pct", "J7_pct", "J8_pct", "J9_pct"};

double JValue(const signal::BenchmarkCriteria& j, int i) {
  switch (i) {
    case 0: return j.J1_ms;
    case 1: return j.J2_pct;
    case 2: return j.J3_pct;
    case 3: return j.J4_pct;
    case 4: return j.J5_pct;
    case 5: return j.J6_pct;
    case 6: return j.J7_pct;
    case 7: return j.J8_pct;
    default: return j.J9_pct;
  }
}

/// J1 to 0.1 ms, the others to 0.01 % (the benchmark's rounding), as text.
std::string JText(double v, int i) {
  if (!std::isfinite(v)) return "nan";
  return i == 0 ? fmt::format("{:.1f}", v) : fmt::format("{:.2f}", v);
}

/// Text for a Markdown table cell: '|' escaped.
std::string MdCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

/// The identification record: BLWN command through the nominal plant, no controller.
scenario::Scenario IdentificationScenario(const scenario::Scenario& base, double duration_s) {
  scenario::Scenario s = base;
  s.path.clear();
  s.sha256.clear();
  s.run.name = "benchmark-identification";
  s.run.duration_s = duration_s;
  s.run.csv_every = 0;
  s.structure.mode = models::StructureMode::kPredefined;
  s.structure.reference_file.clear();
  s.structure.desired = signal::SignalSpec{};
  s.structure.desired.kind = signal::SignalKind::kBlwn;
  s.structure.desired.band_hz = kBenchmarkIdBandHz;
  s.structure.desired.rms = 1.0;
  s.structure.desired.seed = 11;
  s.structure.desired.discard_s = 2.0;
  s.structure.desired.taper_s = 0.5;
  s.controller = control::ControllerConfig{};
  s.controller.kind = control::ControllerKind::kNone;
  s.plant.benchmark.params = models::BenchmarkPlantParams{};
  return s;
}

BenchmarkIdentification Identify(const scenario::Scenario& base, const ReproduceOptions& opts) {
  BenchmarkIdentification id;
  const double duration = opts.quick ? 20.0 : 60.0;
  id.run_dir = opts.out_dir / "runs" / "identification";
  std::vector<RunSpec> specs{{"identification (BLWN, no controller)", IdentificationScenario(base, duration), id.run_dir}};
  Preflight(&specs, opts.overrides, opts.log);
  if (opts.log) {
    opts.log(fmt::format("benchmark: identification record, BLWN 0-{:g} Hz command, RMS 1 mm, {:g} s, no controller",
                         kBenchmarkIdBandHz, duration));
  }
  const auto results = RunBatch(specs, 1, opts.progress);
  if (!results[0].ok) throw Error("benchmark identification", results[0].error);
  const Trace t = ReadTrace(id.run_dir);
  ident::IdentifyOptions io;
  io.fit.poles = 3;
  io.fit.band_lo_hz = 0.5;
  io.fit.band_hi_hz = kBenchmarkFitHiHz;
  io.fit.zoh_dt_s = 0.0;  // a design model: the hold's half-sample lag included (as `rths identify`'s [controller] model)
  const double dt = specs[0].scenario.run.dt_s;
  id.fit = ident::Identify(t.u_mm, t.y_mm, dt, io);
  id.model = id.fit.fit.model.ToServoModel3();
  id.model.name = "custom";
  id.model_lag_ms = 1e3 * id.fit.fit.model.DcLagS();
  id.compensated_delay_ms = std::round(10.0 * id.model_lag_ms) / 10.0;
  const auto plant = models::BenchmarkPlant::Make(specs[0].scenario.plant.benchmark.params, dt);
  id.plant_dc_gain = plant.DcGain();
  id.plant_lag_ms = 1e3 * models::TimeLagS(plant, 1.0, false);

  {  // what `rths identify --out` writes, and its report
    ident::IdentifyOptions zo = io;
    zo.fit.zoh_dt_s = dt;
    const ident::IdentifyResult zoh = ident::Identify(t.u_mm, t.y_mm, dt, zo);
    std::ofstream(opts.out_dir / "identify.toml")
        << ident::ScenarioFragment(id.fit, zoh, "benchmark plant (nominal), BLWN identification record");
    std::ofstream(opts.out_dir / "identify.txt") << id.fit.Report();
  }
  if (opts.log) {
    opts.log(fmt::format("benchmark: fitted K = {:.5g}, p = {:.5g}, b = {:.5g}, c = {:.5g}: DC gain {:.4f}, lag {:.2f} ms "
                         "(the plant: {:.4f}, {:.2f} ms at 1 Hz)",
                         id.model.K, id.model.p, id.model.b, id.model.c, id.fit.fit.model.DcGain(), id.model_lag_ms,
                         id.plant_dc_gain, id.plant_lag_ms));
  }
  return id;
}

BenchmarkSpread Spread(const std::vector<double>& v) {
  BenchmarkSpread s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) {
    s.mean = s.std = s.min = s.max = std::nan("");
    return s;
  }
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / s.n;
  double ss = 0.0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.std = s.n > 1 ? std::sqrt(ss / (s.n - 1)) : 0.0;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

}  // namespace

std::vector<std::string> BenchmarkControllerNames() { return {"none", "poly3", "lead", "ff", "ff_lqg"}; }

control::ControllerConfig BenchmarkController(const std::string& name, const BenchmarkIdentification& id) {
  control::ControllerConfig c;
  c.kind = ParseName(control::kControllerKindNames, name, "benchmark controller");
  c.model = id.model;
  // poly3 and lead compensate the identified low-frequency lag. It exceeds the usual 15 ms bound
  // on delay_ms (extrapolation amplifies noise): the bound is raised for this study.
  c.delay_ms = id.compensated_delay_ms;
  c.max_delay_ms = std::max(c.max_delay_ms, std::ceil(id.compensated_delay_ms + 5.0));
  return c;
}

scenario::Scenario BenchmarkScenario(const scenario::Scenario& base, const std::string& label,
                                     const control::ControllerConfig& controller,
                                     const models::BenchmarkPlantParams& plant, std::uint64_t noise_seed,
                                     double duration_s) {
  scenario::Scenario s = base;
  s.path.clear();
  s.sha256.clear();
  s.run.name = Slug("benchmark " + label);
  s.run.duration_s = duration_s;
  s.controller = controller;
  s.plant.benchmark.params = plant;
  s.plant.noise_seed = noise_seed;
  return s;
}

BenchmarkResult ReproduceBenchmark(const ReproduceOptions& opts, bool keep_logs) {
  const auto t0 = std::chrono::steady_clock::now();
  PrepareOutDir(opts.out_dir);
  const fs::path base_file = io::FindSourceFile("scenarios/benchmark_base.toml");
  const scenario::Scenario base = scenario::LoadScenario(base_file.string());
  if (base.plant.kind != models::PlantKind::kBenchmark) {
    throw Error(base_file.string(), "plant.kind must be \"benchmark\" for this study");
  }

  BenchmarkResult res;
  res.duration_s = opts.quick ? kBenchmarkQuickS : kBenchmarkFullS;
  res.perturbed = opts.quick ? kBenchmarkQuickPerturbed : kBenchmarkFullPerturbed;
  res.id = Identify(base, opts);

  const models::BenchmarkPlantParams nominal = base.plant.benchmark.params;
  std::vector<RunSpec> specs;
  for (const std::string& name : BenchmarkControllerNames()) {
    const control::ControllerConfig c = BenchmarkController(name, res.id);
    for (int i = 0; i <= res.perturbed; ++i) {
      BenchmarkRow row;
      row.controller = name;
      row.run = i == 0 ? "nominal" : std::to_string(i);
      row.seed = static_cast<std::uint64_t>(i);
      row.plant = i == 0 ? nominal : models::PerturbedBenchmarkParams(nominal, row.seed);
      row.run_dir = opts.out_dir / "runs" / fmt::format("{}-{}", name, row.run);
      const std::string label = fmt::format("{} {}", name, row.run);
      // The same sensor noise for every controller on the same plant (common random numbers).
      specs.push_back({label, BenchmarkScenario(base, label, c, row.plant, 100 + row.seed, res.duration_s), row.run_dir});
      res.rows.push_back(row);
    }
  }
  Preflight(&specs, opts.overrides, opts.log);
  if (opts.log) {
    opts.log(fmt::format("benchmark: {} lockstep runs ({} controllers x nominal + {} perturbed plants) of {:g} s at "
                         "4096 Hz, {} at a time (base {}){}",
                         specs.size(), BenchmarkControllerNames().size(), res.perturbed, res.duration_s, opts.jobs,
                         base_file.string(), keep_logs ? "" : "; the perturbed runs' logs are removed once scored"));
  }

  // Score each run as it ends (the callback is serialised), then drop a perturbed run's log: 105
  // full runs would hold several GB, and `rths run DIR/scenario.toml` gives any of them back.
  std::mutex mu;
  const auto results = RunBatch(specs, opts.jobs, opts.progress, [&](std::size_t done, std::size_t total,
                                                                     const RunResult& r) {
    std::lock_guard<std::mutex> lock(mu);
    auto it = std::find_if(res.rows.begin(), res.rows.end(), [&](const BenchmarkRow& row) { return row.run_dir == r.dir; });
    if (it == res.rows.end()) return;
    BenchmarkRow& row = *it;
    row.steps = r.steps;
    row.stopped = StoppedText(r);
    std::string note;
    try {
      const scenario::Scenario s = scenario::LoadScenario((r.dir / "scenario.toml").string());
      row.j = io::BenchmarkCriteriaOfRun((r.dir / "log.lcm").string(), s);
      row.criteria_ok = true;
    } catch (const std::exception& e) {
      note = fmt::format("  (no criteria: {})", e.what());
    }
    if (!keep_logs && row.run != "nominal") {
      std::error_code ec;
      fs::remove(r.dir / "log.lcm", ec);
    }
    if (opts.log) {
      opts.log(fmt::format("  [{:3}/{}] {:<14} J1 {:>5} ms  J2 {:>7} %  J4 {:>7} %  ({:.1f} s){}{}", done, total, r.label,
                           JText(row.j.J1_ms, 0), JText(row.j.J2_pct, 1), JText(row.j.J4_pct, 3), r.wall_s,
                           r.ok ? "" : "  STOPPED: " + row.stopped, note));
    }
  });
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (results[i].steps == 0 && !results[i].ok) {
      throw Error("benchmark", fmt::format("{} did not run: {}", results[i].label, results[i].error));
    }
  }

  // Spread over the perturbed runs.
  const auto names = BenchmarkControllerNames();
  res.spread.assign(names.size(), std::vector<BenchmarkSpread>(9));
  for (std::size_t c = 0; c < names.size(); ++c) {
    for (int j = 0; j < 9; ++j) {
      std::vector<double> v;
      for (const auto& row : res.rows) {
        if (row.controller == names[c] && row.run != "nominal" && row.criteria_ok) v.push_back(JValue(row.j, j));
      }
      res.spread[c][j] = Spread(v);
    }
  }

  // benchmark.csv: the columns, the benchmark's rounding.
  {
    std::vector<std::string> header{"controller", "run"};
    for (const char* n : kJNames) header.push_back(n);
    io::CsvWriter csv(opts.out_dir / "benchmark.csv", header);
    for (const auto& row : res.rows) {
      std::vector<std::string> f{row.controller, row.run};
      for (int j = 0; j < 9; ++j) f.push_back(row.criteria_ok ? JText(JValue(row.j, j), j) : "nan");
      csv.Row(f);
    }
    csv.Close();
  }
  {
    io::CsvWriter csv(opts.out_dir / "benchmark_plants.csv",
                      {"run", "seed", "b1_per_s", "b2_per_s2", "a3_per_s", "k_e_N_per_m", "dc_gain", "lag_1hz_ms"});
    for (const auto& row : res.rows) {
      if (row.controller != names[0]) continue;
      const auto m = models::BenchmarkPlant::Make(row.plant, kBenchmarkDtS);
      csv.Row({row.run, std::to_string(row.seed), fmt::format("{:.6g}", row.plant.b1), fmt::format("{:.6g}", row.plant.b2),
               fmt::format("{:.6g}", row.plant.a3), fmt::format("{:.6g}", row.plant.k_e_N_per_m),
               fmt::format("{:.5f}", m.DcGain()), fmt::format("{:.3f}", 1e3 * models::TimeLagS(m, 1.0, false))});
    }
    csv.Close();
  }

  // benchmark.png: each criterion per controller, nominal and perturbed runs.
  if (io::GnuplotAvailable(opts.gnuplot)) {
    io::Figure fig;
    fig.name = "benchmark";
    fig.width_px = 1400;
    fig.panel_height_px = 330;
    const std::array<std::pair<int, const char*>, 4> panels = {
        {{0, "J1: time delay [ms]"}, {1, "J2: RMS tracking error [%]"}, {3, "J4: RMS error vs the reference [%]"},
         {6, "J7: RMS error of floor 3 vs the reference [%]"}}};
    for (const auto& [j, title] : panels) {
      io::Panel p = io::MakePanel(fmt::format("{} ({} plant runs per controller{})", title, res.perturbed + 1,
                                              opts.quick ? ", --quick" : ""),
                                  "controller (1 none, 2 poly3, 3 lead, 4 ff, 5 ff_lqg)",
                                  fmt::format("J{} [{}]", j + 1, j == 0 ? "ms" : "%"));
      p.x_range = std::make_pair(0.5, names.size() + 0.5);
      p.key = "outside right top";
      p.log_y = j != 0;
      io::Series nom, pert;
      nom.title = "nominal plant";
      nom.with = "points pt 7 ps 2";
      nom.color = "#0072B2";
      pert.title = "perturbed plants";
      pert.with = "points pt 6 ps 1";
      pert.color = "#E69F00";
      for (std::size_t c = 0; c < names.size(); ++c) {
        for (const auto& row : res.rows) {
          if (row.controller != names[c] || !row.criteria_ok) continue;
          const double v = JValue(row.j, j);
          if (p.log_y && !(v > 0)) continue;
          io::Series& s = row.run == "nominal" ? nom : pert;
          s.x.push_back(static_cast<double>(c + 1) + (row.run == "nominal" ? 0.0 : 0.15));
          s.y.push_back(v);
        }
      }
      p.series = {pert, nom};
      p.right_margin_chars = io::KeyMarginChars({&p});
      fig.panels.push_back(p);
    }
    fig.gnuplot = opts.gnuplot;
    io::Plot(fig, opts.out_dir);
  } else if (opts.log) {
    opts.log("benchmark: gnuplot not found, no benchmark.png (apt-get install gnuplot-nox)");
  }

  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  {
    const auto& id = res.id;
    std::ofstream md(opts.out_dir / "benchmark.md");
    md << "# The RTHS benchmark problem (Silva et al. 2020): J1-J9\n\n"
       << fmt::format("Made by `rths reproduce benchmark{}`: {} runs of {:g} s of El Centro x 0.4 at 4096 Hz in {:.0f} s "
                      "wall time ({} at a time). Criteria: docs/benchmark.md; J1 [ms], J2-J9 [%]. J1 searches lags of 0-49 "
                      "samples (0-11.96 ms at 4096 Hz): a run lagging more reads 12.0 ms, the cap.\n\n",
                      opts.quick ? " --quick" : "", res.rows.size(), res.duration_s, res.wall_s, opts.jobs)
       << "## Identification and design\n\n"
       << fmt::format("A BLWN command (0-{:g} Hz, RMS 1 mm, no controller) through the nominal plant with its sensor "
                      "noise (runs/identification); a 3-pole model of Eq. 15 fitted to G_yu over 0.5-{:g} Hz "
                      "(identify.txt, identify.toml):\n\n",
                      kBenchmarkIdBandHz, kBenchmarkFitHiHz)
       << fmt::format("    G(s) = {:.5g} / ((s + {:.5g})(s^2 + {:.5g} s + {:.5g}))\n\n", id.model.K, id.model.p, id.model.b,
                      id.model.c)
       << fmt::format("DC gain {:.4f} (the plant: {:.4f}); low-frequency lag {:.2f} ms (the plant at 1 Hz: {:.2f} ms); "
                      "worst magnitude error over the band {:.2f} %, phase {:.2f} deg.\n\n",
                      id.fit.fit.model.DcGain(), id.plant_dc_gain, id.model_lag_ms, id.plant_lag_ms,
                      id.fit.fit.max_mag_error_pct, id.fit.fit.max_phase_error_deg)
       << "Three poles because the model inverse of `ff` (Eqs. 16-22) uses the derivatives of the desired "
          "displacement up to the model's relative degree: the integrator provides r', r'' and r''' (Eqs. 20-22), "
          "and a fifth-order inverse would need r'''' and r''''' extrapolated from a noisy state. Over the band "
          "the excitation and El Centro drive, the three poles reproduce the measured response (errors above).\n\n"
       << fmt::format("Controllers: `ff` and `ff_lqg` (default LQG weights, docs/controllers.md) on that model; `poly3` "
                      "and `lead` compensating {:.1f} ms (the model's lag; the bound max_delay_ms raised from 15 to "
                      "{:g} ms for this study); `none`.\n\n",
                      id.compensated_delay_ms, BenchmarkController("poly3", id).max_delay_ms)
       << "## Nominal plant\n\n| controller |";
    for (const char* n : kJNames) md << " " << n << " |";
    md << " stopped |\n|---|";
    for (std::size_t j = 0; j < kJNames.size(); ++j) md << "---:|";
    md << "---|\n";
    for (const auto& row : res.rows) {
      if (row.run != "nominal") continue;
      md << "| " << row.controller << " |";
      for (int j = 0; j < 9; ++j) md << " " << (row.criteria_ok ? JText(JValue(row.j, j), j) : "nan") << " |";
      md << " " << MdCell(row.stopped) << " |\n";
    }
    md << fmt::format("\n## {} perturbed plants: mean +/- standard deviation [min, max]\n\n", res.perturbed)
       << "Plants drawn from the benchmark's uncertainty (b1, b2, a3, k_e; seeds 1.." << res.perturbed
       << ", benchmark_plants.csv); the numerical substructure stays nominal.\n\n| controller | runs scored |";
    for (const char* n : kJNames) md << " " << n << " |";
    md << "\n|---|---:|";
    for (std::size_t j = 0; j < kJNames.size(); ++j) md << "---:|";
    md << "\n";
    for (std::size_t c = 0; c < names.size(); ++c) {
      md << "| " << names[c] << " | " << res.spread[c][0].n << " |";
      for (int j = 0; j < 9; ++j) {
        const auto& s = res.spread[c][j];
        md << " " << JText(s.mean, j) << " +/- " << JText(s.std, j) << " [" << JText(s.min, j) << ", "
           << JText(s.max, j) << "] |";
      }
      md << "\n";
    }
    int stopped = 0;
    for (const auto& row : res.rows) stopped += row.stopped != "no";
    md << fmt::format("\n{} of {} runs stopped before the end (criteria over the steps they ran).\n", stopped,
                      res.rows.size());
    for (const auto& row : res.rows) {
      if (row.stopped != "no") md << fmt::format("- {} {}: {} (after {} steps)\n", row.controller, row.run, row.stopped, row.steps);
    }
    md << "\n## Published values\n\n"
       << "The benchmark paper reports J1-J9 for its own example controller; its tables are not part of this "
          "repository, so no published number is quoted here. Put these rows beside the paper's, whose criteria "
          "and rounding are those of benchmark.csv (docs/benchmark.md says where the definitions come from and "
          "what differs in this implementation).\n";
  }
  return res;
}

}  // namespace rths::report
