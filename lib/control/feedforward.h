#pragma once
/// @file The proposed model-based feedforward (Phillips & Spencer 2013, Eqs. 16-22;
/// docs/models.md section 2). Signals in mm, time in s.
///
/// The servohydraulic model G(s) = K / ((s + p)(s^2 + b s + c)) (Eq. 15, N = 3) is inverted
/// exactly: G_FF(s) = (s + p)(s^2 + b s + c) / K = a0 + a1 s + a2 s^2 + a3 s^3 (Eqs. 16-17), i.e.
/// u = a0 r + a1 r' + a2 r'' + a3 r''' (Eqs. 18-19); the derivatives of the desired
/// displacement come from the integrator's displacements (Eqs. 20-22), or, for a history known
/// in advance, from central differences of the whole record.
#include <vector>

#include "models/servo_linear.h"

namespace rths::control {

/// Coefficients of G_FF(s) = a0 + a1 s + a2 s^2 + a3 s^3 (Eq. 17):
/// a3 = 1/K [s^3], a2 = (p + b)/K [s^2], a1 = (p b + c)/K [s], a0 = p c / K [-].
struct FeedforwardCoefficients {
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
};

/// Expands (s + p)(s^2 + b s + c) / K. Throws rths::Error unless K, p, b, c are all finite
/// and > 0 (a stable, minimum-phase model).
FeedforwardCoefficients MakeFeedforwardCoefficients(const models::ServoModel3& model);

/// Estimates of the desired trajectory at step i, as used by Eq. 19.
struct Derivatives {
  double r = 0.0;         ///< r_i [mm]
  double rd = 0.0;        ///< r'_i [mm/s]
  double rdd = 0.0;       ///< r''_i [mm/s^2]
  double rddd = 0.0;      ///< r'''_i [mm/s^3]
  double acc_prev = 0.0;  ///< a_{i-1} = (r_i - 2 r_{i-1} + r_{i-2}) / dt^2 [mm/s^2] (0 if not extrapolated)
  double vel_prev = 0.0;  ///< v_{i-1} = (r_i - r_{i-2}) / (2 dt) [mm/s] (0 if not extrapolated)
};

/// Past desired displacements for Eqs. 20-22. At rest initially: the trajectory is taken as
/// zero before the first step. Eq. 22 needs a_{i-2}, hence three past values.
struct ExtrapolationState {
  double r1 = 0.0;  ///< r_{i-1} [mm]
  double r2 = 0.0;  ///< r_{i-2} [mm]
  double r3 = 0.0;  ///< r_{i-3} [mm]
};

/// Eqs. 20-22 at step i from r_i and the past in `past` (pure: `past` is not changed):
///   a_{i-1} = (r_i - 2 r_{i-1} + r_{i-2}) / dt^2,  a_{i-2} = (r_{i-1} - 2 r_{i-2} + r_{i-3}) / dt^2
///     (the central-difference accelerations of the integrator, Eqs. 2-3),
///   r''_i  = 2 a_{i-1} - a_{i-2}                                    (Eq. 20, linear extrapolation)
///   r'_i   = v_{i-1} + dt/2 (a_{i-1} + r''_i),  v_{i-1} = (r_i - r_{i-2}) / (2 dt)   (Eq. 21)
///   r'''_i = (a_{i-1} - a_{i-2}) / dt                               (Eq. 22)
/// r'' and r''' are exact when r is a polynomial of degree <= 3; r' is exact up to degree 2 and
/// off by dt^2 r'''/6 for a cubic (v_{i-1} is a central difference). dt_s > 0 (not checked).
Derivatives ExtrapolateDerivatives(const ExtrapolationState& past, double r_i, double dt_s);

/// Shifts r_i into the past: (r1, r2, r3) <- (r_i, r1, r2). Call once per step, after the
/// step's command is final (re-answering step i must use the state from before this call).
void PushDisplacement(ExtrapolationState* state, double r_i);

/// ExtrapolateDerivatives(*state, r_i, dt_s), then PushDisplacement(state, r_i).
Derivatives StepDerivatives(ExtrapolationState* state, double r_i, double dt_s);

/// Derivatives of a record known in advance (predefined histories; non-causal), at every step:
///   r'_i   = (r_{i+1} - r_{i-1}) / (2 dt)                               (zero at i = 0, n-1)
///   r''_i  = (r_{i+1} - 2 r_i + r_{i-1}) / dt^2                          (zero at i = 0, n-1)
///   r'''_i = (r_{i+2} - 2 r_{i+1} + 2 r_{i-1} - r_{i-2}) / (2 dt^3)      (zero at i < 2, i >= n-2)
struct DerivativeRecords {
  std::vector<double> rd;    ///< [mm/s], dim r.size()
  std::vector<double> rdd;   ///< [mm/s^2], dim r.size()
  std::vector<double> rddd;  ///< [mm/s^3], dim r.size()

  /// The derivatives at step i as the feedforward consumes them (acc_prev = vel_prev = 0).
  Derivatives At(const std::vector<double>& r, std::size_t i) const {
    return Derivatives{r[i], rd[i], rdd[i], rddd[i], 0.0, 0.0};
  }
};
/// Throws rths::Error unless dt > 0.
DerivativeRecords CentralDerivatives(const std::vector<double>& r, double dt);

/// Feedforward command u_i [mm] (Eq. 19):
///   u = a0 r + a1 r' + a2 r'' + a3 r'''.
/// With half_step_ahead (docs/models.md section 2), each derivative is first advanced half a step by
/// its Taylor series so the zero-order hold's half-sample lag is cancelled in simulation:
///   u = a0 (r + dt/2 r') + a1 (r' + dt/2 r'') + a2 (r'' + dt/2 r''') + a3 r'''.
/// Allocates nothing.
double FeedforwardCommand(const FeedforwardCoefficients& a, const Derivatives& d, bool half_step_ahead,
                          double dt);

}  // namespace rths::control
