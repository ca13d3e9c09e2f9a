#pragma once
// `rths identify`'s command line read at the edge into plain structs (tools/identify.cpp): the
// actuator fit's band, poles, segment and weights; the --damper mode's options and measurement
// effects (--skew, --inertia).
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/error.h"
#include "core/names.h"
#include "ident/damper_options.h"
#include "ident/identify.h"
#include "ident/measurement_fit.h"
#include "io/column_record.h"
#include "io/rig_record.h"

namespace rths::tools {

/// "LO-HI" [Hz] -> (lo, hi).
inline std::pair<double, double> ParseBand(const std::string& s) {
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

/// Options of the --damper mode beyond the fits' own.
struct DamperCli {
  std::vector<std::string> records, checks;
  std::string out, plot;
  io::TimeAxis time = io::TimeAxis::kColumn;
  bool accept_unconverged = false;      ///< exit 0 for a failed fit (ident/fit_status.h)
  const io::ColumnMap* map = nullptr;   ///< --columns, or null
  ident::MeasurementOptions measurement;  ///< --skew, --inertia
};

/// --skew / --inertia: "auto" (fitted), a number (held at it), or "" (off).
inline void ParseMeasurement(const std::string& skew, const std::string& inertia, ident::MeasurementOptions* m) {
  auto parse = [](const std::string& text, const char* flag, const char* unit, ident::MeasurementMode* mode,
                  double* value) {
    if (text.empty()) return;
    if (text == "auto") {
      *mode = ident::MeasurementMode::kAuto;
      return;
    }
    char* end = nullptr;
    *value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(*value))
      throw Error(flag, fmt::format("\"{}\": expected auto or a number [{}]", text, unit));
    *mode = ident::MeasurementMode::kGiven;
  };
  parse(skew, "--skew", "ms", &m->skew, &m->skew_ms);
  parse(inertia, "--inertia", "kg", &m->inertia, &m->mass_kg);
}

/// The actuator fit's command line.
struct ActuatorCli {
  std::string record, band = "0.5-40", weights = "inverse-variance", out, plot;
  int poles = 3;
  double segment_s = 0.0;  ///< Welch segment [s]; 0 = the default
  io::TimeAxis time = io::TimeAxis::kColumn;
  const io::ColumnMap* map = nullptr;  ///< --columns, or null

  /// Adds --band, --poles, --segment-s and --weights.
  void Add(CLI::App* app) {
    app->add_option("--band", band, "frequency band fitted, LO-HI [Hz] (the paper's range)")->capture_default_str();
    app->add_option("--poles", poles, "number of poles N of Eq. 15")->capture_default_str();
    app->add_option("--segment-s", segment_s, "Welch segment length [s] (0: min(4 s, 2/9 of the record))")
        ->capture_default_str();
    app->add_option("--weights", weights, "frequency weights")
        ->check(CLI::IsMember({"inverse-variance", "coherence", "uniform"}))
        ->capture_default_str();
  }

  /// The fit's options, checked (rths::Error naming the flag otherwise).
  ident::IdentifyOptions Options() const {
    ident::IdentifyOptions o;
    std::tie(o.fit.band_lo_hz, o.fit.band_hi_hz) = ParseBand(band);
    o.fit.poles = poles;
    o.segment_s = segment_s;
    if (weights == "inverse-variance") {
      o.fit.weighting = ident::Weighting::kInverseVariance;
    } else if (weights == "coherence") {
      o.fit.weighting = ident::Weighting::kCoherence;
    } else if (weights == "uniform") {
      o.fit.weighting = ident::Weighting::kUniform;
    } else {
      throw Error("--weights", fmt::format("\"{}\": allowed inverse-variance, coherence, uniform", weights));
    }
    if (segment_s < 0.0) throw Error("--segment-s", fmt::format("{}: must be > 0 (0 = default)", segment_s));
    std::string why;
    if (!o.fit.IsValid(&why)) throw Error("--poles/--band", why);
    return o;
  }
};

/// The --damper flags as written (their checks beyond DamperFitOptions::IsValid in main).
struct DamperFlags {
  double current_A = 0.0;
  std::string input, filter = "first_order", skew, inertia;
  bool no_offset = false;
  std::vector<std::string> hold;

  /// Sets *o from the flags (o->current_A already set from --current), checked: with --current no
  /// --input, --filter (`filter_given`) or --no-offset; the --hold values parsed.
  void Apply(bool filter_given, ident::DamperFitOptions* o) const {
    if (o->current_A) {
      if (!(*o->current_A >= 0.0)) throw Error("--current", fmt::format("{} A: must be >= 0", *o->current_A));
      if (!input.empty() || filter_given || no_offset)
        throw Error("--input/--filter/--no-offset", "only for the fit with any input history (without --current)");
    }
    o->input = input == "voltage"   ? ident::DamperInput::kVoltage
               : input == "current" ? ident::DamperInput::kCurrent
                                    : ident::DamperInput::kAuto;
    o->filter = *ValueOf(ident::kControlFilterNames, filter);
    o->accumulator = !no_offset;
    for (const auto& h : hold) o->hold.push_back(ident::ParseHold(h));
  }

  /// Adds the flags, the fit's own into *o.
  void Add(CLI::App* app, ident::DamperFitOptions* o) {
    app->add_option("--current", current_A, "--damper: fit at this one current [A] (the records' constant current)");
    app->add_option("--A", o->A, "--damper: Bouc-Wen A [-], held fixed (Table 3)")->capture_default_str();
    app->add_option("--velocity-cutoff-hz", o->velocity_cutoff_hz,
                    "--damper: cutoff of the zero-phase smoothing differentiator [Hz] (0: 4 x the band edge of each "
                    "record's velocity, at least 50 Hz, at most 0.45 / dt)")
        ->capture_default_str();
    app->add_option("--input", input,
                    "--damper without --current: the control input, current (column i_A) or voltage (column v_V) "
                    "(default: current if the records have i_A)")
        ->check(CLI::IsMember({"current", "voltage"}));
    app->add_option("--filter", filter,
                    "--damper without --current: control filter between command and parameters: first_order "
                    "(u' = -eta (u - v), eta fitted; default), eq40 (the paper's Eq. 40 + 75 Hz low-pass, fixed), none")
        ->check(CLI::IsMember({"first_order", "eq40", "none"}));
    app->add_flag("--no-offset", no_offset,
                  "--damper without --current: hold k1 = x0 = 0 and no force offset (no accumulator, no load-cell "
                  "zero)");
    app->add_option("--threads", o->threads, "--damper without --current: threads for the Jacobian (0: one per core)")
        ->capture_default_str();
    app->add_option("--hold", hold,
                    "--damper: hold a parameter at a value, not fitted: NAME=VALUE in the model file's names and "
                    "units (alpha_c=6, c0_b=0.01, eta_1_s=100; at one current alpha, c0, c1, k0, beta, gamma); "
                    "repeatable")
        ->type_name("NAME=VALUE")
        ->allow_extra_args(false);
    app->add_option("--skew", skew,
                    "--damper: the force channel's lag behind the displacement channel (channel_skew): auto (fitted, "
                    "with its uncertainty) or MS held (default: none)");
    app->add_option("--inertia", inertia,
                    "--damper: the mass between the load cell and the damper (load_cell_inertia, f += m x''): auto "
                    "(fitted, with its uncertainty) or KG held (default: none)");
  }
};

}  // namespace rths::tools
