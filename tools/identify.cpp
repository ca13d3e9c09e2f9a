// rths identify RECORD [--band LO-HI] [--poles N] [--segment-s S] [--weights W] [--out FILE.toml]
//                      [--plot FILE.png]
// Fits the servohydraulic model of Eq. 15 to a record of command u and measured y (a CSV rig
// record or an LCM run log of ours): H1 estimate with coherence, least-squares fit over a band,
// time-domain check. Prints the model as a scenario fragment; writes a Bode plot like the
// paper's Fig. 6 with gnuplot.
// rths identify --damper RECORD... --current A [--check RECORD...] [--A A] [--velocity-cutoff-hz F]
//                        [--skew auto|MS] [--inertia auto|KG] [--hold NAME=VALUE...] [--out FILE.toml]
// Fits the Spencer MR damper model (Eqs. 32-34) at one current to damper tests (rig records, LCM
// logs, or UTFSM damper files: x = y_mm, F = f_kN) by least squares on the force, or without
// --current its current- or voltage-dependent form (ident/damper_model.h); prints the parameters,
// the force error per record (and per held-out --check record) and the model as a TOML fragment.
// docs/identification.md. Exit 0 ok, 2 bad input, 13 a damper fit that failed (did not converge, or
// a parameter on a bound of its range; ident/fit_status.h) unless --accept-unconverged; a failed fit
// or an implausible value (ident/plausible_range.h: a warning) prints what to try
// (ident/fit_advice.h) and marks the --plot figure's title.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "cli.h"
#include "core/progress.h"
#include "identify_flags.h"
#include "ident/actuator_fit.h"
#include "ident/damper_figure.h"
#include "ident/damper_model.h"
#include "io/output_folder.h"
#include "io/plot.h"
#include "io/column_record.h"

namespace {

namespace fs = std::filesystem;
using rths::Error;
using rths::tools::ActuatorCli, rths::tools::DamperCli;

std::vector<rths::io::RigRecord> ReadRecords(const std::vector<std::string>& paths, rths::io::TimeAxis time,
                                             const rths::io::ColumnMap* map) {
  std::vector<rths::io::RigRecord> recs;
  for (const auto& path : paths) {
    recs.push_back(rths::io::ReadAnyRecord(path, map, time));
    for (const auto& w : recs.back().warnings) std::fprintf(stderr, "rths identify: warning: %s\n", w.c_str());
  }
  return recs;
}

void WriteModel(const std::string& toml, const std::string& out) {
  std::printf("\n%s", toml.c_str());
  if (!out.empty()) {
    std::ofstream f(out);
    if (!(f << toml)) throw Error(out, "cannot write the model file");
    std::printf("\nwrote %s\n", out.c_str());
  }
}

std::string Names(const std::vector<std::string>& paths) {  // file names, space-separated
  std::string names;
  for (const auto& r : paths) names += (names.empty() ? "" : " ") + fs::path(r).filename().string();
  return names;
}

/// The --damper mode (file comment): at one current (--current) or with any input history.
int RunDamper(const DamperCli& c, rths::ident::DamperFitOptions o) {
  const auto recs = ReadRecords(c.records, c.time, c.map);
  const auto held = ReadRecords(c.checks, c.time, c.map);
  rths::ProgressLine progress("rths identify --damper");
  if (progress.enabled())
    o.progress = [&progress](double done, double total, std::string_view what) { progress.Update(done, total, what); };
  const auto fit = rths::ident::FitDamperModel(recs, o, c.measurement);
  progress.Finish();
  const bool voltage = fit.voltage();
  if (fit.any_input) {
    for (const auto& w : fit.any_input->warnings) std::fprintf(stderr, "rths identify: warning: %s\n", w.c_str());
    for (const auto& h : held)
      if (const auto c = rths::ident::CommandForModel(h, voltage); !c.warning.empty())
        std::fprintf(stderr, "rths identify: warning: %s\n", c.warning.c_str());
  }
  const char* input = voltage ? "voltage" : "current";
  if (fit.at_current)
    std::printf("rths identify --damper: %zu record(s) at %g A\n%s", recs.size(), *o.current_A, fit.Report().c_str());
  else
    std::printf("rths identify --damper: %zu record(s), %s input %g to %g %s\n%s", recs.size(), input,
                fit.any_input->input_min, fit.any_input->input_max, voltage ? "V" : "A", fit.Report().c_str());
  std::printf("%s", fit.HeldOutReport(held).c_str());
  WriteModel(fit.ModelToml(fit.at_current
                               ? fmt::format("rths identify --damper {} --current {}", Names(c.records), *o.current_A)
                               : fmt::format("rths identify --damper {} ({} input)", Names(c.records), input)),
             c.out);
  const auto verdict = fit.Judge("rths identify", c.accept_unconverged);
  std::fprintf(stderr, "%s", verdict.messages.c_str());
  if (c.plot.empty()) return verdict.exit_code;
  rths::io::PlotPng(rths::ident::DamperFitFigure(fit, recs, held,
                                                 fit.at_current ? fmt::format("at {} A", *o.current_A)
                                                                : (voltage ? "(voltage input)" : "(current input)")),
                    c.plot);
  std::printf("wrote %s\n", c.plot.c_str());
  return verdict.exit_code;
}

/// The actuator fit (file comment): the two fits, their report, the model file and the Bode plot.
int RunActuator(const ActuatorCli& a) {
  const rths::ident::IdentifyOptions o = a.Options();
  const auto rec = ReadRecords({a.record}, a.time, a.map)[0];
  // The model as the paper fits it (continuous, Eq. 15) and the one whose ZOH simulation at the
  // record's step reproduces the record (docs/identification.md, "Two fits").
  const auto fit = rths::ident::FitActuator(rec.u_mm, rec.y_mm, rec.dt_s, o);
  std::printf("rths identify: %s\n%s", a.record.c_str(), fit.Report().c_str());
  WriteModel(fit.ModelToml(fmt::format("rths identify {} (band {}-{} Hz, {} poles, {} weights)",
                                       fs::path(a.record).filename().string(), o.fit.band_lo_hz, o.fit.band_hi_hz,
                                       a.poles, a.weights)),
             a.out);
  // Plots go only where the user said: --plot, or beside --out.
  std::string plot = a.plot;
  if (plot.empty() && !a.out.empty()) plot = fs::path(a.out).replace_extension(".png").string();
  if (plot.empty()) {
    std::printf("(no plot: give --plot FILE.png or --out FILE.toml for a Bode plot beside it)\n");
    return 0;
  }
  const fs::path rp(a.record);
  const std::string shown = rp.filename() == "log.lcm" && !rp.parent_path().filename().empty()
                                ? (rp.parent_path().filename() / rp.filename()).string()
                                : rp.filename().string();
  rths::io::PlotPng(fit.Bode(fmt::format("G_yu: {} ({} poles; measured H1, fitted models)", shown, a.poles)), plot);
  std::printf("wrote %s\n", plot.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths identify: fit the servohydraulic model of Eq. 15 to a record of command u and measured y"};
  std::vector<std::string> records, checks;
  bool damper = false, time_from_header = false, accept_unconverged = false;
  ActuatorCli ac;
  rths::ident::DamperFitOptions fo;
  rths::tools::DamperFlags df;
  app.add_option("record", records,
                 "CSV rig record or LCM run log (log.lcm) of ours; with --damper one or more damper tests (also UTFSM "
                 "damper files)")
      ->required();
  std::string columns;
  rths::tools::AddColumnsOption(app, &columns);
  app.add_flag("--time-from-header", time_from_header,
               "take the step from the record's '# dt_s' line; the time column need only lie within half a step "
               "of t_0 + k dt_s (for a rounded time column)");
  app.add_flag("--damper", damper,
               "fit the Spencer MR damper model instead: at one current (--current) or, without it, its current- or "
               "voltage-dependent form (Eqs. 32-39) with a control filter, from records with any input history");
  app.add_option("--check", checks, "--damper: held-out records to score the fitted model on");
  df.Add(&app, &fo);
  app.add_flag("--accept-unconverged", accept_unconverged,
               "--damper: exit 0 for a fit that did not converge or has a parameter on a bound of its range (it is "
               "written, marked FIT FAILED, either way; without this flag the exit code is 3)");
  ac.Add(&app);
  app.add_option("--out", ac.out, "write the scenario fragment ([plant] actuator, [controller] model) here");
  app.add_option("--plot", ac.plot,
                 "Bode plot PNG (default: beside --out with the extension .png; none without --out); with --damper: "
                 "force against velocity and displacement per record (only if given)");
  rths::tools::NameCommand(app, "identify");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;

  try {
    {  // no output replaces a record being read, or what a run recorded (the scenario that ran, say)
      std::vector<fs::path> inputs(records.begin(), records.end());
      inputs.insert(inputs.end(), checks.begin(), checks.end());
      if (!ac.out.empty()) rths::io::RefuseToReplaceRecord(ac.out, inputs, "--out");
      if (!ac.plot.empty()) rths::io::RefuseToReplaceRecord(ac.plot, inputs, "--plot");
    }
    ac.time = time_from_header ? rths::io::TimeAxis::kHeader : rths::io::TimeAxis::kColumn;
    std::optional<rths::io::ColumnMap> map;
    if (!columns.empty()) map = rths::io::ParseColumnMap(columns);
    ac.map = map ? &*map : nullptr;
    if (app.count("--current") > 0) fo.current_A = df.current_A;
    // A file mapped without a current or voltage column was run at the one current of --current.
    if (map && fo.current_A && !map->Find('i') && !map->Find('v') && !map->current_A && !map->voltage_V)
      map->current_A = *fo.current_A;
    if (damper) {
      df.Apply(app.count("--filter") > 0, &fo);
      DamperCli dc{records, checks, ac.out, ac.plot, ac.time, accept_unconverged, ac.map, {}};
      rths::tools::ParseMeasurement(df.skew, df.inertia, &dc.measurement);
      return RunDamper(dc, fo);
    }
    if (!df.skew.empty() || !df.inertia.empty() || !df.hold.empty())
      throw Error("--skew/--inertia/--hold", "only with --damper");
    if (fo.current_A || !checks.empty() || accept_unconverged)
      throw Error("--current/--check/--accept-unconverged", "only with --damper");
    if (records.size() != 1)
      throw Error("record", fmt::format("{} records given: the actuator fit takes one (or use --damper)", records.size()));
    ac.record = records[0];
    return RunActuator(ac);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths identify: %s\n", e.what());
    return 2;
  }
}
