#pragma once
/// @file `rths reproduce nonlinear` (docs/reproduce_nonlinear.md, issue 44 section 3): for each
/// integrator the critical delay of the RTHS loop (studies/critical_delay.h) of the reference SDOF
/// (scenarios/nonlinear/reference_sdof.toml) split into a numerical substructure and a linear
/// physical spring, for a linear and for the yielding (Bouc-Wen) numerical spring, without
/// compensation and with two tracking controllers designed for the delay; the closed-form delay
/// margin beside the linear rows.
///
/// Writes critical_delay.csv, critical_delay.md and critical_delay.png into opts.out_dir.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "io/plot.h"
#include "scenario/scenario.h"
#include "studies/critical_delay.h"
#include "studies/study.h"

namespace rths::studies {

/// The physical spring's share of the initial stiffness, rho (k_e = rho k).
inline constexpr double kNonlinearPhysicalFraction = 0.5;

/// What the full study and --quick run: the record's length, the tail, the search.
struct NonlinearDelaySettings {
  double record_s = 0.0;   ///< the record's first record_s seconds [s]; 0: the scenario's run.duration_s
  double tail_s = 20.0;    ///< free vibration after it [s]
  DelaySearch search{};
};
/// Full: the scenario's 40 s of El Centro, 20 s tail, 0.01 ms resolution. Quick: 8 s (the strong
/// motion), 8 s tail, 0.05 ms.
NonlinearDelaySettings NonlinearDelayDefaults(bool quick);

/// The loop of the reference SDOF `ref` (its mass, frequency, damping, spring, ground and dt) split
/// with rho = kNonlinearPhysicalFraction; `yielding` false: the numerical spring linear. The record
/// is cut to record_s [s] (0: ref.run.duration_s).
DelayLoop ReferenceDelayLoop(const scenario::Scenario& ref, bool yielding, const models::IntegratorConfig& integrator,
                             DelayCompensation compensation, double record_s, double tail_s);

/// The integrators compared: central_difference, cr, alpha_os (alpha = -0.05), newmark_implicit
/// (2 Newton iterations): each kind's defaults (models::IntegratorConfig).
std::vector<models::IntegratorConfig> NonlinearDelayIntegrators();

struct NonlinearDelayRow {
  std::string integrator;          ///< kIntegratorKindNames
  bool yielding = false;
  CriticalDelay none;              ///< no compensation, decay criterion
  CriticalDelay none_divergence;   ///< no compensation, divergence criterion
  CriticalDelay poly3, lead, ff;   ///< compensated (designed for the delay), decay criterion
  DelayMargin analytic;            ///< linear rows (the same elastic numbers for the yielding ones)
};
struct NonlinearDelayResult {
  std::vector<NonlinearDelayRow> rows;  ///< integrator-major, linear then yielding
  NonlinearDelaySettings settings;
  SplitSdof sdof;                       ///< the linear split (the yielding one has the scenario's spring)
  models::SpringParams spring;          ///< the yielding numerical spring's law (its k is (1 - rho) k)
  double dt_s = 0.0;                    ///< RTHS step [s]
  double wall_s = 0.0;
  /// The linear rows' critical delay (central_difference, cr, alpha_os; newmark_implicit holds the
  /// force one sample late, so its margin is one dt shorter) within 2 % of the closed-form margin.
  std::vector<Claim> claims;
};

/// Runs the study with `settings` (jobs searches at a time) from the scenario `ref`, without writing.
NonlinearDelayResult RunNonlinearDelay(const scenario::Scenario& ref, const NonlinearDelaySettings& settings, int jobs,
                                       const std::function<void(std::string_view)>& log = {});

/// One column of the study: a compensation and a criterion, and where its result goes in a row.
struct NonlinearDelayColumn {
  const char* name;                          ///< "none", "none_divergence", "poly3", "lead", "ff"
  DelayCompensation compensation;
  DelayCriterion criterion;
  CriticalDelay NonlinearDelayRow::*result;
};
/// The five columns, in table order.
const std::vector<NonlinearDelayColumn>& NonlinearDelayColumns();

/// The figure: critical delay per integrator, one panel per structure, one marker per column, the
/// closed-form margin dashed on the linear panel.
io::Figure NonlinearDelayFigure(const NonlinearDelayResult& r, bool quick);

/// `rths reproduce nonlinear`: RunNonlinearDelay on scenarios/nonlinear/reference_sdof.toml (found
/// as io::FindSourceFile finds it), then the CSV, the Markdown and (gnuplot installed) the PNG.
NonlinearDelayResult ReproduceNonlinear(const ReproduceOptions& opts);

}  // namespace rths::studies
