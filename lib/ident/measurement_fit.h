#pragma once
/// @file What the DAQ and the fixture add to a damper test's force channel, fitted around a damper
/// model (`rths identify --damper --skew auto --inertia auto`; docs/identification.md "Channel skew
/// and load-cell inertia"; the effects channel_skew and load_cell_inertia of models/rig_effects.h).
/// Units: mm, kN, s, kg.
///
/// The force channel records, at t_k,
///     f_k = F(t_k - s) + 1e-6 m a(t_k - s)                                       [kN]
/// with F the damper's force, a = x'' the specimen's acceleration [mm/s^2] (the derivative of
/// SmoothVelocity at the record's velocity cut-off), m the mass between the load cell and the damper
/// [kg] and s the force channel's lag behind the displacement channel [s] (a sample-and-hold DAQ
/// that reads its channels in turn, anti-alias filters of different delays). A shift by s is
/// models::ShiftSamples (a 4-point Lagrange interpolant of the samples).
///
/// Fit, given the damper model's force F_r on each record r: minimise the records' cost
///     J(s, m) = sum_r w_r sum_k (f_rk - [shift_s(F_r + 1e-6 m a_r)]_k)^2,   w_r = 1 / sum_k f_rk^2
/// (each record weighs the same, as the damper fits' J): m by weighted least squares at each s
/// (clipped at 0: a mass is not negative), s over [-kMaxSkewMs, kMaxSkewMs] by a grid of
/// kSkewGrid points, then golden section. Standard errors from J's curvature, se^2 = 2 (J / n)
/// tau / J'' (n the samples, tau the residual's integrated correlation time: correlated samples
/// count once per correlation time), each with the other held, and the damper model held:
/// FitDamperModel replaces them by profiles, the model refitted (the skew trades with the damper's
/// own lag, the mass with its stiffness: held, the curvature overstates what the records tell).
#include <span>
#include <string>
#include <vector>

#include "io/rig_record.h"

namespace rths::ident {

/// How a measurement parameter is set.
enum class MeasurementMode {
  kOff,    ///< not in the model (0)
  kAuto,   ///< fitted
  kGiven,  ///< held at the given value
};

struct MeasurementOptions {
  MeasurementMode skew = MeasurementMode::kOff;
  double skew_ms = 0.0;      ///< kGiven: the skew [ms], in [-kMaxSkewMs, kMaxSkewMs]
  MeasurementMode inertia = MeasurementMode::kOff;
  double mass_kg = 0.0;      ///< kGiven: the mass [kg], >= 0
  bool Any() const { return skew != MeasurementMode::kOff || inertia != MeasurementMode::kOff; }
};

/// The skew search range [ms] and grid (file comment).
inline constexpr double kMaxSkewMs = 10.0;
inline constexpr int kSkewGrid = 201;

/// The measurement's effects as fitted (or given).
struct MeasurementFit {
  MeasurementOptions options;     ///< what was asked
  double skew_ms = 0.0;           ///< s [ms]
  double skew_se_ms = 0.0;        ///< its standard error [ms] (0 if not fitted)
  double mass_kg = 0.0;           ///< m [kg]
  double mass_se_kg = 0.0;        ///< its standard error [kg] (0 if not fitted)
  /// A fitted mass smaller than twice its standard error: the records' acceleration is too small
  /// to tell m from noise (said in the report).
  bool mass_unresolved = false;
  double cost = 0.0;    ///< J at (skew, mass) (file comment)
  double sigma2 = 0.0;  ///< J / n: the weighted residual's mean square
  double tau = 1.0;     ///< the residual's integrated correlation time [samples]
  /// The standard errors are profiles (the damper model refitted at either side), not only J's
  /// curvature with the model held (DamperModelFit: the skew trades with the damper's own lag).
  bool profiled = false;
  /// The fitted skew sits at an end of its search range (+-kMaxSkewMs): not a minimum; said in the report.
  bool skew_at_range_end = false;

  bool Any() const { return options.Any(); }
  /// The force channel f_k predicted from the damper's force F_k [kN] on record r (file comment).
  std::vector<double> Measured(std::span<const double> F_kN, const io::RigRecord& r, double cutoff_hz) const;
  /// The record with its force channel turned into the damper's own force, F(t_k) = f(t_k + s) -
  /// 1e-6 m a(t_k) (what a damper model is fitted to).
  io::RigRecord DamperForceRecord(const io::RigRecord& r, double cutoff_hz) const;
  /// Lines of the report: the skew and the mass with their standard errors (empty if none).
  std::string Report() const;
  /// The model file's tables, [plant.effects.channel_skew] and [plant.effects.load_cell_inertia]
  /// (those asked for), with comments: `rths run` then rehearses the rig with them.
  std::string Toml() const;
};

/// The acceleration [mm/s^2] of a record's displacement: the central difference of
/// SmoothVelocity(y_mm, dt_s, cutoff_hz).
std::vector<double> SmoothAcceleration(const io::RigRecord& r, double cutoff_hz);

/// Fits the measurement (file comment) on the records, F[r] the damper model's force on record r and
/// cutoff_hz[r] its velocity cut-off. Throws rths::Error for bad options or lengths.
MeasurementFit FitMeasurement(const std::vector<io::RigRecord>& records, const std::vector<std::vector<double>>& F,
                              const std::vector<double>& cutoff_hz, const MeasurementOptions& options);

}  // namespace rths::ident
