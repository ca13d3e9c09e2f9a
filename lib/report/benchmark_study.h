#pragma once
/// @file The benchmark control problem for RTHS (Silva, Gomez, Maghareh, Dyke & Spencer, Mech.
/// Syst. Signal Process. 2020; docs/benchmark.md) as a study of our testbed: `rths reproduce
/// benchmark`.
///
/// What it does, as a lab would:
///   1. identification: a band-limited white noise command (no controller) through the nominal
///      benchmark plant, with its sensor noise; a 3-pole model of Eq. 15 fitted to G_yu by the
///      code of `rths identify` (ident::Identify);
///   2. design: `ff` and `ff_lqg` on that model; `poly3` and `lead` compensating the model's
///      low-frequency lag (d1/d0, about 25 ms: beyond the usual 15 ms bound, which the study
///      raises); `none`;
///   3. runs: the 3-story partition (numerical floors 1-3 minus the experimental substructure at
///      floor 1) under El Centro x 0.4 at 4096 Hz, every controller on the nominal plant and on
///      `perturbed` plants drawn from the benchmark's uncertainty (models::PerturbedBenchmarkParams,
///      seeds 1..perturbed); J1-J9 of every run against the monolithic reference structure.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "control/controller_config.h"
#include "ident/identify.h"
#include "models/benchmark_plant.h"
#include "report/reproduce.h"
#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"

namespace rths::report {

/// The study's loop rate: 4096 Hz (the benchmark's), dt = 1/4096 s exactly.
inline constexpr double kBenchmarkDtS = 1.0 / 4096.0;
/// El Centro record lengths [s]: full, the whole record (31.2 s); --quick, its strong first 10 s.
inline constexpr double kBenchmarkFullS = 31.2;
inline constexpr double kBenchmarkQuickS = 10.0;
/// Perturbed plants per controller: full 20 (the issue), --quick 2.
inline constexpr int kBenchmarkFullPerturbed = 20;
inline constexpr int kBenchmarkQuickPerturbed = 2;
/// The identification record: BLWN command 0-kBenchmarkIdBandHz, RMS 1 mm; 60 s (--quick 20 s);
/// the fit over 0.5-kBenchmarkFitHiHz.
inline constexpr double kBenchmarkIdBandHz = 30.0;
inline constexpr double kBenchmarkFitHiHz = 25.0;

/// The five controllers, in the order of benchmark.csv.
std::vector<std::string> BenchmarkControllerNames();

/// The identification step's outcome.
struct BenchmarkIdentification {
  ident::IdentifyResult fit;           ///< the 3-pole fit (continuous, hold lag included: a design model)
  models::ServoModel3 model;           ///< fit.fit.model as K, p, b, c ("custom")
  double model_lag_ms = 0.0;           ///< the model's low-frequency lag d1/d0 [ms]
  double plant_lag_ms = 0.0;           ///< the true nominal plant's lag at 1 Hz (continuous) [ms]
  double plant_dc_gain = 0.0;          ///< the true nominal plant's DC gain [mm/mm]
  double compensated_delay_ms = 0.0;   ///< what poly3 and lead compensate: model_lag_ms to 0.1 ms
  std::filesystem::path run_dir;       ///< the BLWN run
};

/// The controller `name` of the study, designed from the identification.
control::ControllerConfig BenchmarkController(const std::string& name, const BenchmarkIdentification& id);

/// One El Centro run: `base` (scenarios/benchmark_base.toml) with the controller, the plant's
/// constants, the sensor-noise seed and the duration [s].
scenario::Scenario BenchmarkScenario(const scenario::Scenario& base, const std::string& label,
                                     const control::ControllerConfig& controller,
                                     const models::BenchmarkPlantParams& plant, std::uint64_t noise_seed,
                                     double duration_s);

/// One row of benchmark.csv.
struct BenchmarkRow {
  std::string controller;              ///< one of BenchmarkControllerNames()
  std::string run;                     ///< "nominal" or the perturbed run's index "1" .. "N"
  std::uint64_t seed = 0;              ///< the perturbation's seed (0: nominal)
  models::BenchmarkPlantParams plant;  ///< the plant it ran on
  signal::BenchmarkCriteria j;         ///< J1-J9 over the steps it ran
  bool criteria_ok = false;            ///< false if too few steps ran to compute them
  std::string stopped = "no";          ///< "no" or why it stopped
  std::int64_t steps = 0;
  std::filesystem::path run_dir;
};

/// Mean, sample standard deviation, min and max of one criterion over a controller's perturbed
/// runs (those whose criteria could be computed).
struct BenchmarkSpread {
  double mean = 0.0, std = 0.0, min = 0.0, max = 0.0;
  int n = 0;
};

struct BenchmarkResult {
  BenchmarkIdentification id;
  std::vector<BenchmarkRow> rows;      ///< controller-major; nominal first, then 1..N
  int perturbed = 0;                   ///< perturbed runs per controller
  double duration_s = 0.0;             ///< El Centro run length [s]
  double wall_s = 0.0;
  /// spread[c][j]: controller c (BenchmarkControllerNames order), criterion j (0 = J1 .. 8 = J9).
  std::vector<std::vector<BenchmarkSpread>> spread;
};

/// Runs the study and writes into opts.out_dir: benchmark.csv (controller,run,J1_ms,J2_pct, ...,
/// J9_pct), benchmark.md (identification, design, nominal table, mean and spread over the
/// perturbed runs, published values), benchmark_plants.csv (the perturbed constants), identify.txt
/// and identify.toml (as `rths identify` writes them), benchmark.png and runs/ (the perturbed runs
/// keep scenario.toml and summary.json; their logs are removed unless keep_logs, since rerunning
/// the scenario gives them back bit for bit). opts.quick: kBenchmarkQuickS and
/// kBenchmarkQuickPerturbed. Throws rths::Error before running if a run cannot be built.
BenchmarkResult ReproduceBenchmark(const ReproduceOptions& opts, bool keep_logs = false);

}  // namespace rths::report
