#pragma once
/// @file Internal to lib/scenario: the schema of [plant] and [semiactive], walked by the
/// visitors of fields.h (Reader, Writer, Checker): every key once, in file order, with its range.
#include "control/clipped_optimal.h"
#include "models/rig.h"
#include "scenario/ranges.h"

namespace rths::scenario::detail {

template <typename V>
void PhysicalFields(V& v, models::PhysicalActuatorConfig& p) {
  v.Number("area_m2", p.area_m2, OpenClosed(0, 1));
  v.Number("supply_pressure_Pa", p.supply_pressure_Pa, OpenClosed(0, 1e9));
  v.Number("volume_m3", p.volume_m3, OpenClosed(0, 1));
  v.Number("piston_mass_kg", p.piston_mass_kg, OpenClosed(0, 1e5));
  v.Number("piston_damping_N_s_m", p.piston_damping_N_s_m, Closed(0, 1e9));
  v.Number("valve_hz", p.valve_hz, OpenClosed(0, 1e4));
  v.Number("valve_zeta", p.valve_zeta, OpenClosed(0, 10));
  v.Number("kq_m3_s", p.kq_m3_s, OpenClosed(0, 10));
  v.Number("kp_per_m", p.kp_per_m, OpenClosed(0, 1e6));
  v.Number("beta_Pa", p.beta_Pa, OpenClosed(0, 1e12));
  v.Number("leakage_m3_s_Pa", p.leakage_m3_s_Pa, Closed(0, 1e-6));
}

/// Every MrDamperParams field; their ranges are the model's own (MrDamperParams::Validate).
template <typename V>
void DamperFields(V& v, models::MrDamperParams& d) {
  for (const models::MrDamperField& f : models::kMrDamperFields) v.Number(f.key, d.*f.member, kAny);
}

/// `[plant.benchmark]`: the benchmark's plant constants (SI, models::BenchmarkPlantParams) and
/// its DAQ. Per-key ranges here; Gp's stability is ValidatePlant's (ValidateBenchmarkParams).
template <typename V>
void BenchmarkFields(V& v, models::BenchmarkRigConfig& b) {
  models::BenchmarkPlantParams& p = b.params;
  v.Number("gain", p.gain, Open(0.0, kInf));
  v.Number("a1b0", p.a1b0, Open(0.0, kInf));
  v.Number("a2", p.a2, ClosedOpen(0.0, kInf));
  v.Number("a3", p.a3, {-kInf, kInf, true, true, "any finite value; Gp must stay stable"});
  v.Number("b1", p.b1, Open(0.0, kInf));
  v.Number("b2", p.b2, Open(0.0, kInf));
  v.Number("m_e_kg", p.m_e_kg, Open(0.0, kInf));
  v.Number("k_e_N_per_m", p.k_e_N_per_m, Open(0.0, kInf));
  v.Number("zeta_e", p.zeta_e, ClosedOpen(0.0, kInf));
  v.Table("daq", [&](V& t) {
    t.Bool("enabled", b.daq.enabled);
    t.Number("volts_per_m", b.daq.volts_per_m, Open(0.0, kInf));
    t.Number("saturation_V", b.daq.saturation_V, Open(0.0, kInf));
    t.Integer("bits", b.daq.bits, Closed(2, 32));
  });
}

template <typename V>
void PlantFields(V& v, models::PlantConfig& p, const Context& cx) {
  v.Choice("kind", p.kind, models::kPlantKindNames);
  v.Servo("actuator", p.actuator);
  v.Choice("specimen", p.specimen, models::kSpecimenNames);
  v.Bool("current_dynamics", p.current_dynamics);
  v.Number("noise_y_mm_rms", p.noise_y_mm_rms, Closed(0.0, 10.0));
  v.Number("noise_f_kN_rms", p.noise_f_kN_rms, Closed(0.0, 100.0));
  v.Integer("noise_seed", p.noise_seed);
  v.Number("ode_rtol", p.ode_rtol, OpenClosed(0.0, 1e-2));
  // The key's name until issue 45; the integrator was CVODE until issue 15, ARKODE since.
  v.Alias("cvode_rtol", "ode_rtol", p.ode_rtol, "the plant's step integrator is ARKODE's Dormand-Prince 5(4), not CVODE");
  v.Table("physical", [&](V& t) { PhysicalFields(t, p.physical); });
  v.Table("benchmark", [&](V& t) { BenchmarkFields(t, p.benchmark); });
  v.Table("damper", [&](V& t) { DamperFields(t, p.damper); });
  v.Table("current_driver", [&](V& t) {
    models::CurrentDriverParams& d = p.current_driver;
    t.Choice("kind", d.kind, models::kCurrentFilterNames);
    t.Number("eta_1_s", d.eta_1_s, OpenClosed(0.0, 1e6));
    t.Number("lag_pole_rad_s", d.lag_pole_rad_s, OpenClosed(0.0, 1e6));
    t.Number("lag_zero_rad_s", d.lag_zero_rad_s, OpenClosed(0.0, 1e6));
    t.Number("lowpass_hz", d.lowpass_hz, OpenClosed(0.0, 1e6));
    t.Number("lowpass_zeta", d.lowpass_zeta, {0.0, 1.0, true, true});
    t.Choice("start", d.start, models::kCurrentStartNames);
  });
  v.Table("unmodelled", [&](V& t) {
    models::UnmodelledConfig& u = p.unmodelled;
    t.Number("ripple_mm", u.ripple_mm, Closed(0.0, 10.0));
    t.Number("ripple_hz", u.ripple_hz,
             {0.0, 0.5 / cx.dt_s, u.ripple_mm > 0.0, true,
              u.ripple_mm > 0.0 ? "a ripple needs a frequency below the Nyquist frequency 0.5/run.dt_s"
                                : "below the Nyquist frequency 0.5/run.dt_s"});
    t.Number("stiffness_kN_per_mm", u.stiffness_kN_per_mm, Closed(-100.0, 100.0));
    t.Number("fade_start", u.fade_start, Closed(0.1, 10.0));
    t.Number("fade_per_s", u.fade_per_s, Closed(-1.0, 1.0));
  });
  v.Effects("effects", p.effects, p.load_coupling_same_sample);
}

template <typename V>
void SemiactiveFields(V& v, control::SemiactiveConfig& s, const Context& cx) {
  v.Choice("mode", s.mode, control::kSemiactiveModeNames);
  v.Number("current_A", s.current_A, {0.0, s.max_current_A, false, false, "at most semiactive.max_current_A"});
  v.Number("max_current_A", s.max_current_A, OpenClosed(0.0, 5.0));
  v.Number("pulse_hz", s.pulse_hz,
           {0.0, 0.25 / cx.dt_s, true, true, "at least four steps per period: below 0.25/run.dt_s"});
  v.Number("pulse_duty", s.pulse_duty, Open(0.0, 1.0));
  v.Integer("pulse_seed", s.pulse_seed);
  v.Number("r_weight", s.r_weight, OpenClosed(0.0, 1e6));
  v.Number("noise_ratio", s.noise_ratio, OpenClosed(0.0, 1e6));
  v.Number("capacity_kN", s.capacity_kN, OpenClosed(0.0, 1e6));
}

}  // namespace rths::scenario::detail
