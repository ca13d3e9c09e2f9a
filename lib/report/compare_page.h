#pragma once
/// @file Runs side by side (`rths compare RUN_A RUN_B [RUN_C ...]`, docs/compare.md): one
/// self-contained HTML page with the runs' summary figures in one table, the scenario keys that
/// differ between them, and figures that overlay them, aligned by step (t = k dt):
///   compare_error.png      e = r - y of every run [mm] over the run, and r with every y over the
///                          0.5 s around the largest |e| of any run
///   compare_histories.png  y of every run with r of the first [mm], each other run's y minus the
///                          first's [mm]; f of every run [kN], each other run's f minus the first's [kN]
///   compare_loops.png      f against y [kN, mm] and against y' [mm/s] (run_figures::LoopVelocity),
///                          every run
/// The run with the largest tracking error is drawn first (beneath); one legend per figure, above.
///   compare_spectra.png    Welch PSDs of e [mm^2/Hz] over the band that carries r
#include <filesystem>
#include <string>
#include <vector>

#include "report/run_report.h"
#include "scenario/flat_keys.h"

namespace rths::report {

struct CompareOptions {
  std::filesystem::path out_dir;          ///< compare.html and figures/ go here (must be given)
  std::string gnuplot = "gnuplot";
  std::vector<std::string> labels;        ///< one per run; empty: the run folders' names
  std::size_t max_plot_points = 4000;     ///< per time-history curve (min/max decimated, peaks kept)
  std::size_t max_loop_points = 6000;     ///< per loop (strided)
  double welch_segment_s = 2.0;           ///< Welch segments aimed at [s]
};

struct CompareFiles {
  std::filesystem::path html;                  ///< OUT/compare.html
  std::vector<std::filesystem::path> figures;  ///< OUT/figures/*.png
  std::vector<std::string> differing_keys;     ///< scenario keys whose values differ ("a.b")
  std::int64_t aligned_steps = 0;              ///< steps every run has (the overlays' common span)
};

/// The keys whose values differ between the texts (or that some lack), in the first text's order
/// then the others'.
std::vector<std::string> DifferingKeys(const std::vector<std::string>& toml_texts);

/// Writes the comparison of `runs` (at least 2, each from LoadRunData) into options.out_dir.
/// Throws rths::Error if fewer than 2 runs are given, labels are not one per run, the runs' dt
/// differ, gnuplot is missing, or a file cannot be written.
CompareFiles WriteComparison(const std::vector<RunData>& runs, const CompareOptions& options);

}  // namespace rths::report
