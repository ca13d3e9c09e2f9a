#pragma once
/// @file `rths reproduce marths` (docs/marths.md): the maRTHS benchmark's criteria J1-J10 for every
/// compensator (none, RoDeAC, the paper's ff and ff_lqg per actuator, the MIMO feedforward) on the
/// nominal plant and on perturbed plants (20; --quick: 2, and the records' first 20 s), El Centro
/// x 0.4 at 1024 Hz, sensor
/// noise on, each run closed as the reference code closes its loop (studies/marths_loop.h).
///
/// Files: marths.csv (a row per run), marths_summary.csv (per compensator: the nominal run, and
/// the perturbed runs' mean and sample standard deviation of every criterion), marths.md (the
/// tables), marths.png (J2 per actuator, J5 and J7 per interface DOF, nominal and perturbed mean),
/// marths_history.png (the nominal runs in time: targets, tracking errors, the interface rotation),
/// marths_decisions.csv and .md (none, rodeac and mimo_ff on the nominal plant with each of the
/// reference code's ambiguous choices switched alone), marths_records.csv and .md (every
/// compensator on the nominal plant under El Centro, Kobe and Morgan Hill, each x 0.4),
/// marths_lockstep.csv and .md (the shipped scenarios scenarios/marths/elcentro_*.toml run through
/// the lockstep beside the loop's nominal runs: studies/marths_lockstep.h).
#include <string>
#include <vector>

#include "signal/marths_criteria.h"
#include "signal/stats.h"
#include "studies/study.h"

namespace rths::studies {

/// One run of the study.
struct MarthsRow {
  std::string compensator;  ///< "none", "rodeac", "ff", "ff_lqg", "mimo_ff"
  std::string run;          ///< "nominal" or "perturbed_<i>" (i = 1 ..)
  signal::MarthsCriteria j;
  double max_volts[2] = {0.0, 0.0};
  bool saturated = false;
};

/// One run of the decisions table: a compensator on the nominal plant with one of the reference
/// code's ambiguous choices switched (docs/marths.md "Decisions").
struct MarthsDecisionRow {
  std::string compensator;
  std::string variant;  ///< "as coded", "exact inverse", "independent noise", "force one sample late",
                        ///< "derivatives from rest", "no noise"
  signal::MarthsCriteria j;
};

struct MarthsStudy {
  std::vector<MarthsRow> rows;
  std::vector<MarthsDecisionRow> decisions;
  /// Every compensator on the nominal plant under each of the benchmark's three records x 0.4
  /// (variant: "El Centro", "Kobe", "Morgan Hill").
  std::vector<MarthsDecisionRow> records;
  std::vector<Claim> claims;
  int perturbed = 0;  ///< perturbed plants per compensator
  double wall_s = 0.0;
};

/// The compensators, in the tables' order.
const std::vector<std::string>& MarthsCompensatorNames();

/// The nominal run's value of criterion `key` (a MarthsCriteria::Items key) for `compensator`;
/// NaN if there is none.
double MarthsNominalValue(const std::vector<MarthsRow>& rows, const std::string& compensator, const std::string& key);

/// The spread of criterion `key` over `compensator`'s perturbed runs.
signal::Spread MarthsPerturbedSpread(const std::vector<MarthsRow>& rows, const std::string& compensator,
                                     const std::string& key);

/// Runs the study into opts.out_dir. Reads data/marths/ (io::FindSourceFile with opts.source_dir).
MarthsStudy ReproduceMarths(const ReproduceOptions& opts);

}  // namespace rths::studies
