#pragma once
/// @file Internal to lib/scenario: the schema of [run] and [structure] (with its signals), walked by the
/// visitors of fields.h (Reader, Writer, Checker): every key once, in file order, with its range.
#include "models/structure_file.h"
#include "scenario/ranges.h"
#include "scenario/scenario.h"
#include "signal/history.h"

namespace rths::scenario::detail {

template <typename V>
void SignalFields(V& v, signal::SignalSpec& s, std::string_view rms_key, const Context& cx) {
  v.Choice("kind", s.kind, signal::kSignalKindNames);
  v.Number("band_hz", s.band_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
  v.Number(rms_key, s.rms, Open(0.0, kInf));
  v.Integer("seed", s.seed);
  v.Number("discard_s", s.discard_s, Closed(0.0, 60.0));
  v.String("file", s.file);
  v.Number("file_dt_s", s.file_dt_s, Closed(0.0, 10.0));
  v.Number("scale", s.scale, kAny);  // finite and not 0: ValidateSignal
  v.Number("taper_s", s.taper_s, Closed(0.0, 60.0));
  v.Number("start_s", s.start_s, Closed(0.0, 3600.0));
}

template <typename V>
void RunFields(V& v, RunConfig& r, const Context&) {
  v.String("name", r.name);
  v.Number("dt_s", r.dt_s, Closed(1e-5, 0.01));
  v.Number("duration_s", r.duration_s, OpenClosed(0.0, 36000.0));
  v.Integer("csv_every", r.csv_every, Closed(0.0, 1e9));
}

/// [structure.spring]: an SDOF's story spring (models/story_spring.h); k is the SDOF's m w^2, not a key.
template <typename V>
void SpringFields(V& v, models::SpringParams& p) {
  v.Choice("kind", p.kind, models::kSpringKindNames);
  v.Number("alpha", p.alpha, ClosedOpen(0.0, 1.0));
  v.Number("x_y_mm", p.x_y_mm, OpenClosed(0.0, 1e6));
  v.Number("n", p.n, Closed(1.0, 20.0));
  v.Number("beta", p.beta, Closed(0.0, 10.0));
  v.Number("gamma", p.gamma, Closed(-10.0, 10.0));
  v.Number("delta_nu", p.delta_nu, Closed(0.0, 10.0));
  v.Number("delta_eta", p.delta_eta, Closed(0.0, 10.0));
  v.Number("b", p.b, ClosedOpen(0.0, 1.0));
  v.Number("f_y_kN", p.f_y_kN, OpenClosed(0.0, 1e9));
}

template <typename V>
void StructureFields(V& v, models::StructureConfig& st, const Context& cx) {
  v.Choice("mode", st.mode, models::kStructureModeNames);
  v.Number("mass_kg", st.mass_kg, OpenClosed(0.0, 1e9));
  // Central difference is stable for omega dt < 2, i.e. f < 1 / (pi dt).
  v.Number("frequency_hz", st.frequency_hz,
           {0.0, 1.0 / (kPi * cx.dt_s), true, true, "central-difference stability limit 1/(pi run.dt_s)"});
  v.Number("damping_ratio", st.damping_ratio, ClosedOpen(0.0, 1.0));
  v.Number("specimen_count", st.specimen_count, Closed(0.0, 1000.0));
  v.Choice("derivatives", st.derivatives, models::kDerivativesNames);
  v.Choice("kind", st.kind, models::kStructureKindNames);
  v.Choice("integrator", st.integrator.kind, models::kIntegratorKindNames);
  v.Integer("substeps", st.integrator.substeps, Closed(1.0, 1000.0));  // 1 unless cr/central_difference: validate.cpp
  v.Number("alpha_os_alpha", st.integrator.alpha, Closed(-1.0 / 3.0, 0.0));
  v.Integer("newton_iterations", st.integrator.newton_iterations, Closed(1.0, 100.0));
  v.String("file", st.file);
  v.String("reference_file", st.reference_file);  // ValidateStructure: only with kind = "file"
  v.Integer("actuator_dof", st.actuator_dof);  // ValidateStructure: when kind = "file"
  v.Bool("subtract_specimen", st.subtract_specimen);  // ValidateStructure: with a reference_file, a benchmark plant
  v.Table("spring", [&](V& t) { SpringFields(t, st.spring); });
  v.Table("ground", [&](V& t) { SignalFields(t, st.ground, "rms_mm_s2", cx); });
  v.Table("desired", [&](V& t) { SignalFields(t, st.desired, "rms_mm", cx); });
}

}  // namespace rths::scenario::detail
