// rths diagnose --train A [B ...] --test C [D ...] [--model MODEL.toml] [--out DIR] [--detrend] [--brief]
// The sim-to-real gap diagnosis (docs/rig_record.md, docs/diagnosis.md): reads rig
// records (CSV rig records, our LCM logs, UTFSM files; any CSV or .mat file through --columns),
// predicts them with the nominal model, localises the residual, fits every effect of the library
// on the training records, selects greedily, scores the shrink on the test records. Writes DIR/diagnosis.json and DIR/report.html (+ PNG plots), prints a
// summary (--brief: the verdict and each channel's shrink only). Exit 0 ok, 2 bad input (a bad
// record names its file and line), 5 other failure (core/exit_code.h).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "core/error.h"
#include "core/progress.h"
#include "diagnosis/diagnosis.h"
#include "diagnosis/model_file.h"
#include "diagnosis/tuning.h"
#include "report/diagnosis_page.h"
#include "io/output_folder.h"
#include "io/column_record.h"
#include "io/rig_record.h"

namespace fs = std::filesystem;

namespace {

/// DIR/fitted_model.toml (the nominal model and the selected effects); returns the line saying
/// where, or a warning if it could not be written.
std::string WriteFittedModel(const rths::diagnosis::NominalModel& model, const rths::diagnosis::Result& r,
                             const fs::path& dir) {
  try {
    const fs::path model_path = dir / "fitted_model.toml";
    std::ofstream f(model_path);
    if (!(f << rths::diagnosis::FittedModelToml(model, r))) throw rths::Error(model_path.string(), "cannot write");
    return fmt::format("fitted model: {} (nominal + selected effects; rths run / design take it)\n", model_path.string());
  } catch (const std::exception& e) {
    return fmt::format("warning: fitted_model.toml: {}\n", e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths diagnose: where the model is wrong, which unmodelled effect, how far the gap shrinks"};
  std::vector<std::string> train, test;
  std::string model_file, out;
  rths::diagnosis::Options o;
  bool brief = false;
  app.add_option("--train", train, "training records (CSV rig records, LCM logs, UTFSM files, or with --columns any CSV "
                                   "with named columns or .mat file)")
      ->required()
      ->expected(1, -1);
  app.add_option("--test", test, "held-out test records")->required()->expected(1, -1);
  app.add_option("--model", model_file, "nominal model: a scenario TOML or a file written by rths identify "
                                        "(default: the paper's Eq. 30, Table 3, Eq. 40 + 75 Hz)");
  app.add_option("--out", out, "output folder (default: a new folder under runs/)");
  app.add_flag("--detrend", o.detrend,
               fmt::format("remove a slow sensor drift (below {:g} Hz) from the measured y and f, found in their "
                           "residuals under the nominal model and then under the effects selected; the command u is "
                           "left as it drove the rig (a channel whose whole excess is that slow gets it anyway)",
                           rths::diagnosis::tuning::kDriftHz));
  app.add_option("--none-ratio", o.none_ratio, "residual/noise-floor power ratio [-] at or below which a channel is noise (>= 1)")
      ->capture_default_str();
  app.add_option("--smooth-hz", o.smooth_hz, "zero-phase smoothing of the y residual for the force channel's motion [Hz]")
      ->capture_default_str();
  std::string columns;
  rths::tools::AddColumnsOption(app, &columns);
  std::optional<double> current_A;
  app.add_option("--current", current_A,
                 "with --columns: the constant damper current [A] of records mapped without a current or voltage "
                 "column (the map's i=VALUE does the same)");
  bool time_from_header = false;
  app.add_flag("--time-from-header", time_from_header,
               "take the step from the record's '# dt_s' line; the time column need only lie within half a step "
               "of t_0 + k dt_s (for a rounded time column)");
  app.add_flag("--brief", brief, "print only the verdict and each channel's shrink (the files are the same)");
  rths::tools::NameCommand(app, "diagnose");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  std::vector<rths::io::RigRecord> tr, te;
  rths::diagnosis::NominalModel model;
  const auto axis = time_from_header ? rths::io::TimeAxis::kHeader : rths::io::TimeAxis::kColumn;
  try {
    if (!out.empty()) rths::io::RequireNewOrEmptyFolder(out, "an earlier diagnosis or a run");
    std::optional<rths::io::ColumnMap> map;
    if (!columns.empty()) map = rths::io::ParseColumnMap(columns);
    if (current_A) {
      if (!map) throw rths::Error("--current", "only with --columns (our own formats carry their current)");
      if (map->Find('i') || map->Find('v') || map->current_A || map->voltage_V)
        throw rths::Error("--current", "the map already gives the damper command (i or v)");
      if (!(*current_A >= 0.0 && *current_A <= rths::io::kMaxAbsCurrentA))
        throw rths::Error("--current", fmt::format("{} A: must be in [0, {:g}] A", *current_A, rths::io::kMaxAbsCurrentA));
      map->current_A = *current_A;
    }
    const rths::io::ColumnMap* m = map ? &*map : nullptr;
    for (const auto& p : train) tr.push_back(rths::io::ReadAnyRecord(p, m, axis));
    for (const auto& p : test) te.push_back(rths::io::ReadAnyRecord(p, m, axis));
    model = model_file.empty() ? rths::diagnosis::PaperModel() : rths::diagnosis::LoadModel(model_file);
    if (!(o.none_ratio >= 1.0)) throw rths::Error("--none-ratio", fmt::format("{}: must be >= 1", o.none_ratio));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths diagnose: %s\n", e.what());
    return rths::kExitUsage;
  }
  try {
    rths::diagnosis::Traces traces;
    rths::ProgressLine progress("rths diagnose");
    if (progress.enabled()) {
      o.progress = [&progress](double done, double total, std::string_view what) { progress.Update(done, total, what); };
    }
    const auto r = rths::diagnosis::Diagnose(tr, te, model, o, &traces);
    progress.Finish();
    const fs::path dir = out.empty() ? rths::io::NewOutputFolder("diagnose") : fs::path(out);
    fs::create_directories(dir);
    {
      std::ofstream f(dir / "diagnosis.json");
      if (!(f << rths::diagnosis::ToJson(r).dump(2) << "\n"))
        throw rths::Error((dir / "diagnosis.json").string(), "cannot write");
    }
    std::string report_note;
    try {
      rths::report::WriteDiagnosisReport(r, traces, dir);
    } catch (const std::exception& e) {
      report_note = fmt::format("warning: report.html: {}\n", e.what());
    }
    const std::string model_note = WriteFittedModel(model, r, dir);
    const auto detail = brief ? rths::diagnosis::SummaryDetail::kBrief : rths::diagnosis::SummaryDetail::kFull;
    std::printf("rths diagnose\n%s%s%s", rths::diagnosis::Summary(r, detail).c_str(), report_note.c_str(),
                model_note.c_str());
    std::printf("output: %s\n", dir.string().c_str());
  } catch (const rths::Interrupted& e) {  // Ctrl-C, e.g. while gnuplot draws
    std::fprintf(stderr, "rths diagnose: %s (interrupted; nothing after it was written)\n", e.what());
    return rths::kExitInterrupted;
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "rths diagnose: %s\n", e.what());
    return rths::kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths diagnose: %s\n", e.what());
    return rths::kExitInternal;
  }
  return 0;
}
