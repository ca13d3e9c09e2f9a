#pragma once
/// @file Internal to lib/scenario: the schema of [controller], walked by the
/// visitors of fields.h (Reader, Writer, Checker): every key once, in file order, with its range.
#include "control/ambc.h"
#include "control/ats.h"
#include "control/controller_config.h"
#include "control/lti_controller.h"
#include "scenario/ranges.h"

namespace rths::scenario::detail {

template <typename V>
void LqgFields(V& t, control::LqgConfig& q) {
  t.Number("q", q.q, OpenClosed(0.0, 1e12));
  t.Number("w_f_hz", q.w_f_hz, OpenClosed(0.0, 1000.0));
  t.Number("xi_f", q.xi_f, OpenClosed(0.0, 10.0));
  t.Number("eta_f", q.eta_f, Closed(0.0, 100.0));
  t.Number("W", q.W, OpenClosed(0.0, 1e12));
  t.Number("V", q.V, OpenClosed(0.0, 1e12));
}

template <typename V>
void LtiFields(V& t, control::LtiConfig& l) {
  t.Tf("feedback", l.feedback);
  t.Tf("reference", l.reference);
  t.Choice("domain", l.domain, control::kTfDomainNames);
  t.Choice("discretisation", l.discretisation, control::kDiscretisationNames);
  t.Bool("allow_unstable", l.allow_unstable);
  t.Number("saturation_mm", l.saturation_mm, {0.0, 1e6, false, false, "0 for no limit"});
  t.Number("rate_limit_mm_s", l.rate_limit_mm_s, {0.0, 1e9, false, false, "0 for no limit"});
}

/// [controller.ats]: per-key ranges here; bounds against each other and the initial values, the
/// window against dt: ValidateController (the design's own checks).
template <typename V>
void AtsFields(V& t, control::AtsConfig& a, const Context& cx) {
  t.Numbers("initial", a.initial, Closed(-1e6, 1e6));
  t.Numbers("lower", a.lower, Closed(-1e6, 1e6));
  t.Numbers("upper", a.upper, Closed(-1e6, 1e6));
  t.Numbers("max_rate_per_s", a.max_rate_per_s, OpenClosed(0.0, 1e12));
  t.Number("window_s", a.window_s, OpenClosed(0.0, 100.0));
  t.Integer("skip", a.skip, Closed(1, 1e6));
  t.Number("filter_hz", a.filter_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
  t.Integer("filter_order", a.filter_order, Closed(1, 8));
  t.Number("threshold_mm", a.threshold_mm, Closed(0.0, 1e4));
  t.Choice("derivatives", a.derivatives, control::kTargetDerivativesNames);
}

/// [controller.ambc]: as AtsFields.
template <typename V>
void AmbcFields(V& t, control::AmbcConfig& a, const Context& cx) {
  t.Choice("start", a.start, control::kAmbcStartNames);
  t.Numbers("initial", a.initial, Closed(-1e6, 1e6));
  t.Numbers("gain_log10", a.gain_log10, Closed(-30.0, 30.0));
  t.Numbers("lower", a.lower, Closed(-1e12, 1e12));
  t.Numbers("upper", a.upper, Closed(-1e12, 1e12));
  t.Number("filter_hz", a.filter_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
  t.Integer("filter_order", a.filter_order, Closed(1, 8));
  t.Choice("derivatives", a.derivatives, control::kTargetDerivativesNames);
}

template <typename V>
void ControllerFields(V& v, control::ControllerConfig& c, const Context& cx) {
  v.Choice("kind", c.kind, control::kControllerKindNames);
  v.Servo("model", c.model);
  v.Bool("half_step_ahead", c.half_step_ahead);
  v.Number("delay_ms", c.delay_ms,
           {0.0, c.max_delay_ms, true, false,
            "extrapolation beyond controller.max_delay_ms amplifies noise too much; raise that bound "
            "deliberately if you mean it"});
  v.Number("max_delay_ms", c.max_delay_ms, OpenClosed(0.0, 100.0));
  v.Number("lead_tp_ms", c.lead_tp_ms, OpenClosed(0.0, 100.0));
  const bool uses_lp = c.kind == control::ControllerKind::kFfLp || c.kind == control::ControllerKind::kBumplessLp;
  v.Number("lp_cutoff_hz", c.lp_cutoff_hz,
           {0.0, uses_lp ? 0.5 / cx.dt_s : kInf, true, true, uses_lp ? "below the Nyquist frequency 0.5/run.dt_s" : ""});
  v.Integer("lp_order", c.lp_order, {3, 8, false, false, "the three-pole inverse needs at least order 3 to be proper"});
  v.Servo("model_low", c.model_low);
  v.Servo("model_high", c.model_high);
  v.Number("current_high_A", c.current_high_A, OpenClosed(0.0, 5.0));
  v.Table("lqg", [&](V& t) { LqgFields(t, c.lqg); });
  v.Table("lti", [&](V& t) { LtiFields(t, c.lti); });
  v.Table("ats", [&](V& t) { AtsFields(t, c.ats, cx); });
  v.Table("ambc", [&](V& t) { AmbcFields(t, c.ambc, cx); });
}

}  // namespace rths::scenario::detail
