#pragma once
/// @file The table of the paper's reproductions (`rths reproduce NAME`, docs/experiments.md): one
/// row per study — its name, how to reproduce it, and the standing of its claims (whether the
/// test suite requires them or the reproduction reports them). The tool's name list, its dispatch
/// and bench-compare --outputs' list of studies all read this table.
///
/// Every study's result carries its claims (Claim: text, holds, detail); Reproduce here turns it
/// into a StudyReport: a brief report (the table printed before the claims), the claims, and what
/// is printed after them. `rths reproduce` prints it (ClaimLine for each claim).
#include <functional>
#include <string>
#include <vector>

#include "studies/study.h"

namespace rths::studies {

/// What `rths reproduce NAME` prints of a study: `brief`, then one ClaimLine per claim, then
/// `after`. Text ends in '\n' where it is not empty.
struct StudyReport {
  std::string brief;          ///< the study's table (or one line), before the claims
  std::vector<Claim> claims;  ///< the paper's claims checked on our numbers
  std::string after;          ///< after the claims (table2 --extended: the extended table)
};

/// One study of the table.
struct Study {
  std::string name;  ///< "fig5", "fig6", ..., "nonlinear"
  /// Runs the study into opts.out_dir (its files) and returns what the tool prints.
  std::function<StudyReport(const ReproduceOptions&)> reproduce;
  /// The standing of its claims on `plant` ("physical" | "linear"): "required: the test suite
  /// asserts ..." or "reported: ...".
  std::function<std::string(const std::string& plant)> claims;
  /// Whether --quick changes its numbers (fig5: no, it has no records to shorten).
  bool quick_matters = true;
};

/// The studies, in the order of `rths reproduce --help`.
const std::vector<Study>& Studies();

/// The study named `name`; throws rths::Error ("reproduce NAME") listing the names.
const Study& StudyNamed(const std::string& name);

/// The names of Studies(), in order.
std::vector<std::string> StudyNames();

/// The standing of `study`'s claims as printed under each: its `claims` text, and "; --quick:
/// shorter records, noisier numbers than the full run" when quick and it matters.
std::string Standing(const Study& study, const std::string& plant, bool quick);

/// One claim as printed: "[holds] TEXT" or "[does not hold] TEXT", then "    DETAIL" and
/// "    (STANDING)", each line ending in '\n'.
std::string ClaimLine(const Claim& c, const std::string& standing);

}  // namespace rths::studies
