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
// docs/identification.md. Exit 0 ok, 2 bad input, 3 a damper fit that failed (did not converge, or
// a parameter on a bound of its range; ident/fit_status.h) unless --accept-unconverged; a failed fit
// or an implausible value (ident/plausible_range.h: a warning) prints what to try
// (ident/fit_advice.h) and marks the --plot figure's title.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "core/error.h"
#include "core/progress.h"
#include "ident/damper_figure.h"
#include "ident/damper_model.h"
#include "ident/identify.h"
#include "io/output_folder.h"
#include "io/plot.h"
#include "io/column_record.h"
#include "io/rig_record.h"
#include "io/utfsm.h"
#include "signal/spectral.h"

namespace {

namespace fs = std::filesystem;
using rths::Error;

/// "LO-HI" [Hz] -> (lo, hi).
std::pair<double, double> ParseBand(const std::string& s) {
  const auto dash = s.find('-', 1);
  char* e1 = nullptr;
  char* e2 = nullptr;
  if (dash == std::string::npos) throw Error("--band", fmt::format("\"{}\": expected LO-HI in Hz, e.g. 0.5-40", s));
  const std::string a = s.substr(0, dash), b = s.substr(dash + 1);
  const double lo = std::strtod(a.c_str(), &e1), hi = std::strtod(b.c_str(), &e2);
  if (a.empty() || b.empty() || *e1 || *e2 || !(lo >= 0.0) || !(hi > lo) || !std::isfinite(hi))
    throw Error("--band", fmt::format("\"{}\": expected LO-HI in Hz with 0 <= LO < HI, e.g. 0.5-40", s));
  return {lo, hi};
}

/// Model phase unwrapped from DC along a fine grid up to f [rad].
double ModelPhase(const std::function<std::complex<double>(double)>& g, double f_hz) {
  const int n = 16 + static_cast<int>(std::ceil(8.0 * f_hz));
  double ph = std::arg(g(0.0));
  std::complex<double> prev = g(0.0);
  for (int i = 1; i <= n; ++i) {
    const auto cur = g(f_hz * i / n);
    ph += std::arg(cur / prev);
    prev = cur;
  }
  return ph;
}

/// Draws `fig` with io::Plot in a private temporary folder and puts only its PNG at `png` (the
/// user asked for a picture, not gnuplot's data and script).
void PlotTo(rths::io::Figure fig, const std::string& png) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rths_identify_{}", ::getpid());
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  fig.name = "plot";
  try {
    const auto files = rths::io::Plot(fig, dir);
    fs::copy_file(files.png, png, fs::copy_options::overwrite_existing, ec);
    if (ec) throw Error(png, "cannot write the plot: " + ec.message());
  } catch (...) {
    fs::remove_all(dir, ec);
    throw;
  }
  fs::remove_all(dir, ec);
}

/// The measured H1 up to fmax [Hz] as four series (magnitude, phase [deg], time lag [ms],
/// coherence): the excited points (fitted or not), phase unwrapped over them.
std::array<rths::io::Series, 4> MeasuredSeries(const rths::ident::IdentifyResult& rc, double fmax) {
  const double deg = 180.0 / std::numbers::pi;
  rths::io::Series m_mag = rths::io::MakeSeries("measured H1", rths::io::ReadableColors()[0]);
  m_mag.width = 2.0;
  rths::io::Series m_ph = m_mag, m_lag = m_mag, m_coh = m_mag;
  double peak = 0.0;
  for (std::size_t i = 0; i < rc.s_uu.size(); ++i)
    if (rc.frf.f_hz[i] <= fmax) peak = std::max(peak, rc.s_uu[i]);
  double ph = 0.0;
  std::complex<double> prev = 0.0;
  for (std::size_t i = 1; i < rc.frf.f_hz.size() && rc.frf.f_hz[i] <= fmax; ++i) {
    if (rc.s_uu[i] < rc.options.min_excitation * peak || std::abs(rc.frf.h[i]) == 0.0) continue;
    const auto h = rc.frf.h[i];
    ph = prev == 0.0 ? std::arg(h) : ph + std::arg(h / prev);
    prev = h;
    const double f = rc.frf.f_hz[i];
    for (rths::io::Series* s : {&m_mag, &m_ph, &m_lag, &m_coh}) s->x.push_back(f);
    m_mag.y.push_back(std::abs(h));
    m_ph.y.push_back(ph * deg);
    m_lag.y.push_back(-ph / (2.0 * std::numbers::pi * f) * 1e3);
    m_coh.y.push_back(rc.frf.coherence[i]);
  }
  return {m_mag, m_ph, m_lag, m_coh};
}

/// Fig. 6 style: magnitude, phase [deg], time lag [ms] and coherence vs frequency 0-50 Hz, measured
/// H1 beside the continuous fit and the ZOH-consistent fit's discrete response; the fitted band shaded.
void PlotBode(const std::string& png, const std::string& title, const rths::ident::IdentifyResult& rc,
              const rths::ident::IdentifyResult& rz) {
  using rths::io::MakePanel;
  using rths::io::MakeSeries;
  using rths::io::Series;
  const double fmax = std::min(50.0, 0.5 / rc.dt_s);
  const double deg = 180.0 / std::numbers::pi;
  const auto [m_mag, m_ph, m_lag, m_coh] = MeasuredSeries(rc, fmax);
  // Models on a fine grid.
  Series c_mag = MakeSeries("Eq. 15 fit", "#000000", 2);
  c_mag.width = 2.0;
  Series z_mag = MakeSeries("ZOH-consistent fit", rths::io::ReadableColors()[1], 3);
  z_mag.width = 3.5;
  Series c_ph = c_mag, c_lag = c_mag, z_ph = z_mag, z_lag = z_mag;
  double lag_lo = 1e300, lag_hi = -1e300;  // the models' time-lag range [ms], for the lag axis
  {
    const auto gc = [&](double f) { return rc.fit.model.Response(f); };
    const auto zoh = rths::ident::Discretise(rz.fit.model, rz.dt_s);
    const auto gz = [&](double f) { return rths::ident::ZohResponse(zoh, f); };
    for (int i = 1; i <= 500; ++i) {
      const double f = fmax * i / 500.0, w = 2.0 * std::numbers::pi * f;
      const double pc = ModelPhase(gc, f), pz = ModelPhase(gz, f);
      for (Series* s : {&c_mag, &c_ph, &c_lag, &z_mag, &z_ph, &z_lag}) s->x.push_back(f);
      c_mag.y.push_back(std::abs(gc(f)));
      z_mag.y.push_back(std::abs(gz(f)));
      c_ph.y.push_back(pc * deg);
      z_ph.y.push_back(pz * deg);
      c_lag.y.push_back(-pc / w * 1e3);
      z_lag.y.push_back(-pz / w * 1e3);
      lag_lo = std::min({lag_lo, c_lag.y.back(), z_lag.y.back()});
      lag_hi = std::max({lag_hi, c_lag.y.back(), z_lag.y.back()});
    }
  }
  rths::io::Figure fig;
  fig.title = title;
  fig.width_px = 1100;
  fig.panel_height_px = 270;
  auto mag = MakePanel("", "Frequency [Hz]", "Magnitude |G_yu| [mm/mm]");
  mag.series = {m_mag, c_mag, z_mag};
  auto pha = MakePanel("", "Frequency [Hz]", "Phase [deg]");
  pha.series = {m_ph, c_ph, z_ph};
  auto lag = MakePanel("", "Frequency [Hz]", "Time lag -phase/ω [ms]");
  lag.series = {m_lag, c_lag, z_lag};
  lag.y_range = std::make_pair(0.7 * lag_lo, 1.3 * lag_hi);
  auto coh = MakePanel("", "Frequency [Hz]", "Coherence γ² [-]");
  coh.series = {m_coh};
  coh.y_range = std::make_pair(0.0, 1.05);
  // One legend, beside the first panel; every panel the same margins so the axes line up.
  const int right = rths::io::KeyMarginChars({&mag});
  for (auto* p : {&mag, &pha, &lag, &coh}) {
    p->x_range = std::make_pair(0.0, fmax);
    p->shade_x = std::make_pair(rc.fitted_lo_hz, rc.fitted_hi_hz);
    p->key = p == &mag ? "outside right top" : "off";
    p->left_margin_chars = 12;
    p->right_margin_chars = right;
  }
  mag.title = fmt::format("shaded: the fitted band, {:.4g}-{:.4g} Hz", rc.fitted_lo_hz, rc.fitted_hi_hz);
  fig.panels = {mag, pha, lag, coh};
  PlotTo(std::move(fig), png);
}

/// Options of the --damper mode beyond the fits' own.
struct DamperCli {
  std::vector<std::string> records, checks;
  std::string out, plot;
  rths::io::TimeAxis time = rths::io::TimeAxis::kColumn;
  bool accept_unconverged = false;  ///< exit 0 for a failed fit (ident/fit_status.h)
  const rths::io::ColumnMap* map = nullptr;  ///< --columns, or null
  rths::ident::MeasurementOptions measurement;  ///< --skew, --inertia
};

/// --skew / --inertia: "auto" (fitted), a number (held at it), or "" (off).
void ParseMeasurement(const std::string& skew, const std::string& inertia, rths::ident::MeasurementOptions* m) {
  auto parse = [](const std::string& text, const char* flag, const char* unit, rths::ident::MeasurementMode* mode,
                  double* value) {
    if (text.empty()) return;
    if (text == "auto") {
      *mode = rths::ident::MeasurementMode::kAuto;
      return;
    }
    char* end = nullptr;
    *value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(*value))
      throw Error(flag, fmt::format("\"{}\": expected auto or a number [{}]", text, unit));
    *mode = rths::ident::MeasurementMode::kGiven;
  };
  parse(skew, "--skew", "ms", &m->skew, &m->skew_ms);
  parse(inertia, "--inertia", "kg", &m->inertia, &m->mass_kg);
}

std::vector<rths::io::RigRecord> ReadDamperRecords(const std::vector<std::string>& paths, rths::io::TimeAxis time,
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

std::string Names(const std::vector<std::string>& paths) {
  std::string names;
  for (const auto& r : paths) names += (names.empty() ? "" : " ") + fs::path(r).filename().string();
  return names;
}

/// The --damper mode (file comment): at one current (--current) or with any input history.
int RunDamper(const DamperCli& c, rths::ident::DamperFitOptions o) {
  const auto recs = ReadDamperRecords(c.records, c.time, c.map);
  const auto held = ReadDamperRecords(c.checks, c.time, c.map);
  rths::ProgressLine progress("rths identify --damper");
  if (progress.enabled()) {
    o.progress = [&progress](double done, double total, std::string_view what) { progress.Update(done, total, what); };
  }
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
  if (fit.at_current) {
    std::printf("rths identify --damper: %zu record(s) at %g A\n%s", recs.size(), *o.current_A, fit.Report().c_str());
  } else {
    std::printf("rths identify --damper: %zu record(s), %s input %g to %g %s\n%s", recs.size(), input,
                fit.any_input->input_min, fit.any_input->input_max, voltage ? "V" : "A", fit.Report().c_str());
  }
  if (!held.empty()) {
    std::printf("  held-out force error (Eq. 31 on f), same model:\n");
    const int width = fit.at_current ? 6 : 7;
    for (const auto& h : held) {
      const auto sc = fit.Score(h);
      if (std::isfinite(sc.nrmse_f_pct)) {
        std::printf("    %-40s %*zu samples at %g s, peak %.4g kN: %.3f %%\n", sc.source.c_str(), width, sc.samples,
                    sc.dt_s, sc.peak_force_kN, sc.nrmse_f_pct);
        continue;
      }
      // The prediction stopped being finite: say where, not "inf %".
      const auto F = fit.PredictForce(h);
      std::size_t k = 0;
      while (k < F.size() && std::isfinite(F[k])) ++k;
      std::printf("    %-40s %*zu samples at %g s, peak %.4g kN: no score: the model's force stops being finite at "
                  "t = %.4g s (sample %zu): the model is too stiff for this record's motion (more than %d substeps a "
                  "sample) or its state diverges there\n",
                  sc.source.c_str(), width, sc.samples, sc.dt_s, sc.peak_force_kN, static_cast<double>(k) * h.dt_s, k,
                  rths::ident::kMaxSpencerSubsteps);
    }
  }
  WriteModel(fit.ModelToml(fit.at_current
                               ? fmt::format("rths identify --damper {} --current {}", Names(c.records), *o.current_A)
                               : fmt::format("rths identify --damper {} ({} input)", Names(c.records), input)),
             c.out);
  // A failed fit (ident/fit_status.h) is written, marked, and exits kExitFitFailed unless accepted;
  // an implausible value is a warning. Either way, what to try (ident/fit_advice.h).
  const auto& status = fit.status();
  int code = 0;
  for (const auto& p : status.implausible) std::fprintf(stderr, "rths identify: warning: %s\n", p.Warning().c_str());
  if (const auto advice = fit.Advice(); !advice.empty()) {
    std::fprintf(stderr, "rths identify: what to try (docs/identification.md \"When a fit fails\"):\n");
    for (const auto& a : advice) std::fprintf(stderr, "  - %s\n", a.c_str());
  }
  if (!status.Ok()) {
    std::fprintf(stderr, "rths identify: fit status: %s\n", status.Summary().c_str());
    if (c.accept_unconverged) {
      std::fprintf(stderr, "rths identify: --accept-unconverged: exit 0 all the same\n");
    } else {
      std::fprintf(stderr,
                   "rths identify: exit %d (the model file says FIT FAILED; --accept-unconverged exits 0; "
                   "docs/identification.md \"When a fit fails\")\n",
                   rths::ident::kExitFitFailed);
      code = rths::ident::kExitFitFailed;
    }
  }
  if (c.plot.empty()) return code;
  PlotTo(rths::ident::DamperFitFigure(
             fit, recs, held,
             fit.at_current ? fmt::format("at {} A", *o.current_A) : (voltage ? "(voltage input)" : "(current input)")),
         c.plot);
  std::printf("wrote %s\n", c.plot.c_str());
  return code;
}

/// The actuator fit's command line (file comment).
struct ActuatorCli {
  std::string record, band = "0.5-40", weights = "inverse-variance", out, plot;
  int poles = 3;
  double segment_s = 0.0;
  rths::io::TimeAxis time = rths::io::TimeAxis::kColumn;
  const rths::io::ColumnMap* map = nullptr;  ///< --columns, or null
};

/// The actuator options of the command line, checked.
rths::ident::IdentifyOptions ActuatorOptions(const ActuatorCli& a) {
  rths::ident::IdentifyOptions o;
  std::tie(o.fit.band_lo_hz, o.fit.band_hi_hz) = ParseBand(a.band);
  o.fit.poles = a.poles;
  o.segment_s = a.segment_s;
  if (a.weights == "inverse-variance") {
    o.fit.weighting = rths::ident::Weighting::kInverseVariance;
  } else if (a.weights == "coherence") {
    o.fit.weighting = rths::ident::Weighting::kCoherence;
  } else if (a.weights == "uniform") {
    o.fit.weighting = rths::ident::Weighting::kUniform;
  } else {
    throw Error("--weights", fmt::format("\"{}\": allowed inverse-variance, coherence, uniform", a.weights));
  }
  if (a.segment_s < 0.0) throw Error("--segment-s", fmt::format("{}: must be > 0 (0 = default)", a.segment_s));
  std::string why;
  if (!o.fit.IsValid(&why)) throw Error("--poles/--band", why);
  return o;
}

/// The actuator fit (file comment): the two fits, their report, the model file and the Bode plot.
int RunActuator(const ActuatorCli& a) {
  const rths::ident::IdentifyOptions o = ActuatorOptions(a);
  const auto rec = rths::io::ReadAnyRecord(a.record, a.map, a.time);
  for (const auto& w : rec.warnings) std::fprintf(stderr, "rths identify: warning: %s\n", w.c_str());

  // The model as the paper fits it (continuous, Eq. 15) and the one whose ZOH simulation at the
  // record's step reproduces the record (docs/identification.md, "Two fits").
  const auto rc = rths::ident::Identify(rec.u_mm, rec.y_mm, rec.dt_s, o);
  auto oz = o;
  oz.fit.zoh_dt_s = rec.dt_s;
  const auto rz = rths::ident::Identify(rec.u_mm, rec.y_mm, rec.dt_s, oz);

  std::printf("rths identify: %s\n%s", a.record.c_str(), rc.Report().c_str());
  std::printf("\nZOH-consistent fit (the continuous model whose zero-order-hold discretisation at dt = %g s matches "
              "the measured response):\n%s",
              rec.dt_s, rz.fit.Report().c_str());
  std::printf("time domain: Eq. 31 error of the predicted y %.3f %%\n", rz.prediction.model_error_pct);
  WriteModel(rths::ident::ScenarioFragment(
                 rc, rz,
                 fmt::format("rths identify {} (band {}-{} Hz, {} poles, {} weights)",
                             fs::path(a.record).filename().string(), o.fit.band_lo_hz, o.fit.band_hi_hz, a.poles,
                             a.weights)),
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
  PlotBode(plot, fmt::format("G_yu: {} ({} poles; measured H1, fitted models)", shown, a.poles), rc, rz);
  std::printf("wrote %s\n", plot.c_str());
  return 0;
}

/// The --damper options of the command line (their checks beyond DamperFitOptions::IsValid).
void AddDamperOptions(CLI::App* app, rths::ident::DamperFitOptions* o, double* current_A, std::string* input,
                      std::string* filter, bool* no_offset, std::string* skew, std::string* inertia,
                      std::vector<std::string>* hold) {
  app->add_option("--current", *current_A, "--damper: fit at this one current [A] (the records' constant current)");
  app->add_option("--A", o->A, "--damper: Bouc-Wen A [-], held fixed (Table 3)")->capture_default_str();
  app->add_option("--velocity-cutoff-hz", o->velocity_cutoff_hz,
                  "--damper: cutoff of the zero-phase smoothing differentiator [Hz] (0: 4 x the band edge of each "
                  "record's velocity, at least 50 Hz, at most 0.45 / dt)")
      ->capture_default_str();
  app->add_option("--input", *input,
                  "--damper without --current: the control input, current (column i_A) or voltage (column v_V) "
                  "(default: current if the records have i_A)")
      ->check(CLI::IsMember({"current", "voltage"}));
  app->add_option("--filter", *filter,
                  "--damper without --current: control filter between command and parameters: first_order "
                  "(u' = -eta (u - v), eta fitted; default), eq40 (the paper's Eq. 40 + 75 Hz low-pass, fixed), none")
      ->check(CLI::IsMember({"first_order", "eq40", "none"}));
  app->add_flag("--no-offset", *no_offset,
                "--damper without --current: hold k1 = x0 = 0 and no force offset (no accumulator, no load-cell zero)");
  app->add_option("--threads", o->threads, "--damper without --current: threads for the Jacobian (0: one per core)")
      ->capture_default_str();
  app->add_option("--hold", *hold,
                  "--damper: hold a parameter at a value, not fitted: NAME=VALUE in the model file's names and units "
                  "(alpha_c=6, c0_b=0.01, eta_1_s=100; at one current alpha, c0, c1, k0, beta, gamma); repeatable")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
  app->add_option("--skew", *skew,
                  "--damper: the force channel's lag behind the displacement channel (channel_skew): auto (fitted, "
                  "with its uncertainty) or MS held (default: none)");
  app->add_option("--inertia", *inertia,
                  "--damper: the mass between the load cell and the damper (load_cell_inertia, f += m x''): auto "
                  "(fitted, with its uncertainty) or KG held (default: none)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths identify: fit the servohydraulic model of Eq. 15 to a record of command u and measured y"};
  std::vector<std::string> records, checks;
  bool damper = false, time_from_header = false, no_offset = false, accept_unconverged = false;
  ActuatorCli ac;
  rths::ident::DamperFitOptions fo;
  std::string input, filter = "first_order", skew, inertia;
  std::vector<std::string> hold;
  double current_A = 0.0;
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
  AddDamperOptions(&app, &fo, &current_A, &input, &filter, &no_offset, &skew, &inertia, &hold);
  app.add_flag("--accept-unconverged", accept_unconverged,
               "--damper: exit 0 for a fit that did not converge or has a parameter on a bound of its range (it is "
               "written, marked FIT FAILED, either way; without this flag the exit code is 3)");
  app.add_option("--band", ac.band, "frequency band fitted, LO-HI [Hz] (the paper's range)")->capture_default_str();
  app.add_option("--poles", ac.poles, "number of poles N of Eq. 15")->capture_default_str();
  app.add_option("--segment-s", ac.segment_s, "Welch segment length [s] (0: min(4 s, 2/9 of the record))")
      ->capture_default_str();
  app.add_option("--weights", ac.weights, "frequency weights")
      ->check(CLI::IsMember({"inverse-variance", "coherence", "uniform"}))
      ->capture_default_str();
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
    if (app.count("--current") > 0) fo.current_A = current_A;
    // A file mapped without a current or voltage column was run at the one current of --current.
    if (map && fo.current_A && !map->Find('i') && !map->Find('v') && !map->current_A && !map->voltage_V)
      map->current_A = *fo.current_A;
    if (damper) {
      if (fo.current_A) {
        if (!(*fo.current_A >= 0.0)) throw Error("--current", fmt::format("{} A: must be >= 0", *fo.current_A));
        if (!input.empty() || app.count("--filter") > 0 || no_offset)
          throw Error("--input/--filter/--no-offset", "only for the fit with any input history (without --current)");
      }
      fo.input = input == "voltage"   ? rths::ident::DamperInput::kVoltage
                 : input == "current" ? rths::ident::DamperInput::kCurrent
                                      : rths::ident::DamperInput::kAuto;
      fo.filter = *rths::ValueOf(rths::ident::kControlFilterNames, filter);
      fo.accumulator = !no_offset;
      for (const auto& h : hold) fo.hold.push_back(rths::ident::ParseHold(h));
      DamperCli dc{records, checks, ac.out, ac.plot, ac.time, accept_unconverged, ac.map, {}};
      ParseMeasurement(skew, inertia, &dc.measurement);
      return RunDamper(dc, fo);
    }
    if (!skew.empty() || !inertia.empty() || !hold.empty()) throw Error("--skew/--inertia/--hold", "only with --damper");
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
