#pragma once
/// @file The benchmark control problem for RTHS (Silva, Gomez, Maghareh, Dyke & Spencer, Mech.
/// Syst. Signal Process. 2020; docs/benchmark.md) as its reference code runs it, as a study of our
/// testbed: `rths reproduce benchmark`.
///
/// What it does, as a lab would:
///   1. identification: a band-limited white noise command (no controller) through the nominal
///      benchmark plant, with its sensor noise; a 3-pole model of Eq. 15 fitted to G_yu by the
///      code of `rths identify` (ident::Identify);
///   2. design: the benchmark's example controller (PI + phase lead, an `lti`), `ff` and `ff_lqg`
///      on the fitted model, `poly3` and `lead` compensating the model's low-frequency lag, `ats`
///      and `ambc` with their published parameters, `none`;
///   3. runs: each of the four partitioning cases (scenarios/benchmark/caseN_example.toml: the
///      3-story reference minus the experimental substructure at floor 1, the padded El Centro
///      record x 0.4, 41.18 s at 4096 Hz), every controller on the nominal plant and on
///      `perturbed` plants drawn from the benchmark's uncertainty (models::PerturbedBenchmarkParams,
///      seeds 1..perturbed); as in the reference code, the numerical substructure of a perturbed
///      run is the reference minus the perturbed specimen (its k_e, c_e); J1-J9 of every run;
///   4. the loop: the example controller's nominal runs again through studies/benchmark_loop, closed
///      as the reference code closes it, one difference at a time, beside the published values.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "control/controller_config.h"
#include "ident/actuator_fit.h"
#include "ident/identify.h"
#include "models/benchmark_plant.h"
#include "studies/study.h"
#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"
#include "signal/stats.h"

namespace rths::studies {

/// The study's loop rate: 4096 Hz (the benchmark's), dt = 1/4096 s exactly.
inline constexpr double kBenchmarkDtS = 1.0 / 4096.0;
/// Perturbed plants per controller and case: full 20 (the benchmark asks for at least 20), --quick 2.
inline constexpr int kBenchmarkFullPerturbed = 20;
inline constexpr int kBenchmarkQuickPerturbed = 2;
/// The identification record: BLWN command 0-kBenchmarkIdBandHz, RMS 1 mm; 60 s (--quick 20 s);
/// the fit over 0.5-kBenchmarkFitHiHz.
inline constexpr double kBenchmarkIdBandHz = 30.0;
inline constexpr double kBenchmarkFitHiHz = 25.0;

/// The eight controllers, in the order of benchmark.csv: "example_pi_lead", "none", "poly3",
/// "lead", "ff", "ff_lqg", "ats", "ambc".
std::vector<std::string> BenchmarkControllerNames();

/// J1-J9 of the benchmark's example controller (PI + phase lead) on the nominal plant, El Centro,
/// as published: Table 3 of Silva et al., preprint V23 of 6 Feb 2019, in the benchmark's package
/// (github MECHS-RCN/BENCHMARKS, "RTHS code RT V23.zip", Benchmark_Control_Problem_for_Real_time_
/// Hybrid_Simulation_Updated_V23.pdf, p. 30). Index: case - 1; J1 [ms], J2-J9 [%].
const std::array<std::array<double, 9>, 4>& PublishedExampleCriteria();

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

/// The controller `name` of the study, designed from the identification (`example_pi_lead` is
/// the benchmark's own: C(s) = 2 + 95/s, T(s) = 50.83 (s + 168.6)/(s + 8570.4), Tustin).
control::ControllerConfig BenchmarkController(const std::string& name, const BenchmarkIdentification& id);

/// One El Centro run: `base` (scenarios/benchmark/caseN_example.toml) with the controller, the
/// plant's constants, the sensor-noise seed and, if not empty, another numerical substructure file.
scenario::Scenario BenchmarkScenario(const scenario::Scenario& base, const std::string& label,
                                     const control::ControllerConfig& controller,
                                     const models::BenchmarkPlantParams& plant, std::uint64_t noise_seed,
                                     const std::string& numerical_file = "");

/// One row of benchmark.csv.
struct BenchmarkRow {
  int case_number = 1;                 ///< 1 .. 4
  std::string controller;              ///< one of BenchmarkControllerNames()
  std::string run;                     ///< "nominal" or the perturbed run's index "1" .. "N"
  std::uint64_t seed = 0;              ///< the perturbation's seed (0: nominal)
  models::BenchmarkPlantParams plant;  ///< the plant it ran on
  signal::BenchmarkCriteria j;         ///< J1-J9 over the steps it ran
  bool criteria_ok = false;            ///< false if too few steps ran to compute them
  std::string stopped = "no";          ///< "no" or why it stopped
  bool stable = false;                 ///< ran every step and its criteria are finite
  std::int64_t steps = 0;
  std::filesystem::path run_dir;
};

/// Mean, sample standard deviation, min and max of one criterion over a controller's perturbed
/// runs in one case (those whose criteria could be computed).
using BenchmarkSpread = signal::Spread;

/// One closing of the example controller's nominal loop (studies/benchmark_loop.h).
struct BenchmarkLoopRow {
  int case_number = 1;
  std::string variant;   ///< "lockstep", "rk4", "rk4 + unit delay", "reference code"
  std::string label;     ///< LoopOptions::Label()
  signal::BenchmarkCriteria j;
};

struct BenchmarkResult {
  BenchmarkIdentification id;
  std::vector<BenchmarkRow> rows;      ///< case-major, then controller; nominal first, then 1..N
  int perturbed = 0;                   ///< perturbed runs per controller and case
  double duration_s = 0.0;             ///< El Centro run length [s]
  double wall_s = 0.0;
  /// spread[case - 1][c][j]: controller c (BenchmarkControllerNames order), criterion j (0 = J1).
  std::vector<std::vector<std::vector<BenchmarkSpread>>> spread;
  std::vector<BenchmarkLoopRow> loops;
  std::vector<Claim> claims;           ///< CheckBenchmarkClaims (also in benchmark.md)
};

/// What docs/benchmark.md says of the study, checked on its numbers:
///   (1) closed as the reference code closes it, the example controller's J1-J9 on the nominal plant
///       are the published ones (Table 3 of Silva et al.): J1 to 0.15 ms, J2-J9 within 0.6 points, in
///       every case;
///   (2) tracking (J1-J3) does not depend on how the loop is closed: lockstep and the reference
///       code's loop within 0.1 ms and 0.1 points in every case.
/// A criterion the run did not reach (--quick's short record) makes the claim "does not hold".
std::vector<Claim> CheckBenchmarkClaims(const BenchmarkResult& res);

/// Runs the study and writes into opts.out_dir: benchmark.csv (case,controller,run,J1_ms, ...,
/// J9_pct,stopped), benchmark_summary.csv (per case and controller: published, nominal, mean,
/// std, min, max of J1-J9 and the stable count), benchmark_loop.csv, benchmark.md,
/// benchmark_plants.csv, identify.txt and identify.toml, benchmark.png, structures/ (the perturbed
/// numerical substructures) and runs/ (each run keeps scenario.toml and summary.json; logs are
/// removed once scored, but for case 1's nominal runs, unless keep_logs: rerunning a scenario
/// gives its log back bit for bit). opts.quick: kBenchmarkQuickPerturbed. Throws rths::Error
/// before running if a run cannot be built.
BenchmarkResult ReproduceBenchmark(const ReproduceOptions& opts, bool keep_logs = false);

/// Writes benchmark.csv, benchmark_summary.csv, benchmark_loop.csv, benchmark_plants.csv,
/// benchmark.md and benchmark.png for `res` into opts.out_dir (ReproduceBenchmark's outputs).
void WriteBenchmarkOutputs(const BenchmarkResult& res, const ReproduceOptions& opts);

}  // namespace rths::studies
