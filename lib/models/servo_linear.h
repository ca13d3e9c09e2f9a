#pragma once
/// @file The linear servohydraulic model (Eqs. 28-30): G(s) = K / ((s + p)(s^2 + b s + c)),
/// displacement command u [mm] to measured displacement y [mm], discretised exactly with a
/// zero-order hold at the lockstep step dt.
///
/// Realisation (phase variables, docs/models.md section 4): with (s + p)(s^2 + b s + c) =
/// s^3 + d2 s^2 + d1 s + d0, d2 = p + b, d1 = p b + c, d0 = p c, and z = [y, y', y''] / 1
/// ([mm, mm/s, mm/s^2]):
///
///     z' = A z + B u,  y = C z,
///     A = [[0, 1, 0], [0, 0, 1], [-d0, -d1, -d2]],  B = [0, 0, K]^T,  C = [1, 0, 0].
///
/// ZOH: z_{k+1} = Phi z_k + Gamma u_k with Phi = e^{A dt}, Gamma = int_0^dt e^{A s} ds B.
#include <complex>

#include <Eigen/Core>
#include <string>
#include <string_view>


namespace rths::models {

/// A three-pole servohydraulic model G(s) = K / ((s + p)(s^2 + b s + c)) (Eq. 15 with N = 3;
/// Eqs. 28-30 of the paper are presets). In a file: a preset name ("0.0A", "2.5A", "avg")
/// or a table {K = ..., p = ..., b = ..., c = ...}. All four must be > 0 (stable, minimum phase).
struct ServoModel3 {
  double K = 1.600e7;  ///< gain [1/s^3] (mm/mm at DC: K / (p c))
  double p = 151.7;    ///< real pole at s = -p [1/s]
  double b = 250.4;    ///< quadratic factor s^2 + b s + c [1/s]
  double c = 1.061e5;  ///< [1/s^2]
  std::string name = "avg";  ///< preset name, or "custom"
  bool operator==(const ServoModel3&) const = default;
};
/// The paper's identified models: "0.0A" (Eq. 28), "2.5A" (Eq. 29), "avg" (Eq. 30).
/// Throws rths::Error for an unknown name.
ServoModel3 ServoPreset(std::string_view name);

/// Immutable description of one linear servo (continuous and ZOH matrices).
struct LinearServo {
  Eigen::Matrix3d A;                  ///< continuous state matrix [1/s^k]
  Eigen::Vector3d B;                  ///< continuous input vector, [0, 0, K]^T [1/s^3]
  Eigen::RowVector3d C;               ///< output row [1, 0, 0]
  Eigen::Matrix3d Phi;                ///< e^{A dt}
  Eigen::Vector3d Gamma;              ///< int_0^dt e^{A s} ds B
  double dt_s = 0.0;                  ///< ZOH step [s]
  double K = 0, p = 0, b = 0, c = 0;  ///< model coefficients (models::ServoModel3)

  /// Builds the realisation and its exact ZOH discretisation (augmented-matrix exponential,
  /// computed in a balanced state basis). Throws rths::Error unless K, p, b, c > 0 and dt_s > 0.
  static LinearServo Make(const models::ServoModel3& m, double dt_s);
  /// Static gain K / (p c) [mm/mm] (identical for the continuous and the ZOH model).
  double DcGain() const;
};

/// Per-step state: z_k = [y_k, y'_k, y''_k] [mm, mm/s, mm/s^2].
struct LinearServoState {
  Eigen::Vector3d z = Eigen::Vector3d::Zero();
};

/// Measured displacement y_k = C z_k [mm]. Strictly proper: y_k depends on u_0 .. u_{k-1} only.
double Output(const LinearServo& m, const LinearServoState& s);
/// Actuator velocity y'_k = C A z_k [mm/s].
double OutputVelocity(const LinearServo& m, const LinearServoState& s);
/// Advances one step: z_{k+1} = Phi z_k + Gamma u_k, with the command u_k [mm] held over
/// [t_k, t_{k+1}) (the D/A hold, which lags half a step). Allocates nothing.
void Step(const LinearServo& m, LinearServoState* s, double u_mm);

/// Frequency response at f_hz [Hz] (mm/mm): the continuous G(j w) if !discrete, else the ZOH
/// model C (zI - Phi)^-1 Gamma at z = e^{j w dt}.
std::complex<double> FrequencyResponse(const LinearServo& m, double f_hz, bool discrete);
/// Time lag -phase(f) / w [s], phase unwrapped continuously from 0 at DC. f_hz > 0.
double TimeLagS(const LinearServo& m, double f_hz, bool discrete);

}  // namespace rths::models
