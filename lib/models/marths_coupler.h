#pragma once
/// @file The maRTHS benchmark's coupler: two horizontal actuators joined by a rigid link impose
/// the interface node's translation x and rotation theta (fcn_coupler_geometry.m and the
/// Simulink model's "Coordinate transformation" subsystems of FermandoisLab/maRTHS-bmk-RoDeAC;
/// docs/marths.md "Coupler").
///
/// Actuator i is attached at the arm (x_v,i, y_v,i) from the node, of length
/// d_i = sqrt(x_v,i^2 + y_v,i^2) at the angle alpha_i: d = 0.29540 m, alpha_1 = -25.4633 deg,
/// alpha_2 = +25.4633 deg. Its stroke is the arm end's horizontal motion:
///
///     forward:  x_a,i = 1000 (x + d_i (cos(theta + alpha_i) - cos(alpha_i)))      [mm; x m, theta rad]
///
/// (subsystem "Coordinate transformation: Frame to Actuator"). With d_1 = d_2 = d and
/// alpha_1 = -alpha_2 = -alpha the difference of the strokes gives theta exactly:
///
///     x_a,1 - x_a,2 = 1000 d (cos(theta - alpha) - cos(theta + alpha)) = 2000 d sin(alpha) sin(theta)
///     r = (x_1 - x_2) / (2 d_2 sin(alpha_2)),  theta = asin(r),  x = x_1 - d_1 (cos(alpha_1 + theta) - cos(alpha_1))
///
/// with x_i = x_a,i / 1000 [m]. The reference code's inverse ("Coordinate transformation:
/// Actuator to Frame") computes theta = asin(r) but puts r, not asin(r), inside the cosine of the
/// translation: x = x_1 - d_1 (cos(alpha_1 + r) - cos(alpha_1)). Both are here (Inverse's `form`);
/// the difference is of order d sin(alpha_1) r^3 / 6 (1e-12 m at the benchmark's 1e-3 rad).
///
/// **Any geometry** (a lab's own coupler; declared in [marths] as coupler_xv_m, coupler_yv_m,
/// coupler_alpha_deg). With P = d_1 cos(alpha_1) - d_2 cos(alpha_2) and
/// Q = d_1 sin(alpha_1) - d_2 sin(alpha_2) the stroke difference is
///
///     x_1 - x_2 = P (cos(theta) - 1) - Q sin(theta) = R sin(theta + phi) - P,
///     R = hypot(P, Q),  phi = atan2(P, -Q),
///
/// so theta = asin((x_1 - x_2 + P) / R) - phi, or pi - asin(...) - phi: the exact inverse takes
/// the branch nearer theta = 0 (the coupler's working range) and then x as above. For the
/// benchmark's symmetric arms P = 0 and -Q = 2 d sin(alpha_2): the same floating-point operations
/// as the benchmark's formula, so its numbers are unchanged bit for bit. R = 0 (arms whose ends
/// move alike) leaves theta unobservable, and so, to first order, does Q = 0 (arm ends at one
/// height: d(x_1 - x_2)/d theta = -Q at theta = 0): CouplerProblem refuses |Q| under 1 % of the
/// longer arm. The as-wired form is the reference code's formula for symmetric arms only
/// (CouplerProblem refuses it otherwise).
#include <array>
#include <string>

namespace rths::models::marths {

/// The coupler's arms, actuator 1 then 2 (fcn_coupler_geometry.m's values by default): arm i
/// ends at (xv_i, yv_i) [m] from the interface node, at the angle alpha_i [deg] (the reference
/// code gives the angle to four decimals beside the arm; CouplerProblem checks they agree).
struct CouplerGeometry {
  std::array<double, 2> xv_m = {0.26670, 0.26670};
  std::array<double, 2> yv_m = {-0.127, 0.127};
  std::array<double, 2> alpha_deg = {-25.4633, 25.4633};
  double d_m(int i) const;        ///< sqrt(xv_i^2 + yv_i^2), i = 0, 1
  double alpha_rad(int i) const;  ///< alpha_i pi / 180
  double d1_m() const { return d_m(0); }
  double d2_m() const { return d_m(1); }
  double alpha1_rad() const { return alpha_rad(0); }
  double alpha2_rad() const { return alpha_rad(1); }
  bool operator==(const CouplerGeometry&) const = default;
};

/// The two actuator strokes [mm].
struct ActuatorPair {
  double a1_mm = 0.0, a2_mm = 0.0;
};

/// The interface node's translation [m] and rotation [rad].
struct InterfaceMotion {
  double x_m = 0.0, theta_rad = 0.0;
};

/// How Inverse computes the translation: as the reference code wires it (r inside the cosine)
/// or exactly (asin r): the file comment.
enum class InverseForm { kAsWired, kExact };

/// The stroke difference's coefficients (the file comment):
/// x_1 - x_2 = P (cos theta - 1) - Q sin theta [m].
struct StrokeDifference {
  double P_m = 0.0;  ///< d_1 cos(alpha_1) - d_2 cos(alpha_2)
  double Q_m = 0.0;  ///< d_1 sin(alpha_1) - d_2 sin(alpha_2)
};
StrokeDifference StrokeDifferenceOf(const CouplerGeometry& g);

/// What is wrong with `g` for the inverse `form`, or "" if nothing: an arm shorter than 1 mm, an
/// angle more than 1e-3 deg from atan2(yv, xv), arms whose stroke difference does not see a small
/// rotation (|Q| < 0.01 max(d_1, d_2): the file comment), or the as-wired form on arms that are
/// not symmetric (d_1 = d_2, alpha_1 = -alpha_2).
std::string CouplerProblem(const CouplerGeometry& g, InverseForm form);

/// Forward kinematics (the file comment).
ActuatorPair Forward(const CouplerGeometry& g, const InterfaceMotion& m);

/// Inverse kinematics from the measured strokes (the file comment). A stroke difference the
/// coupler cannot make (|sin| > 1) gives theta NaN, as asin does. Allocates nothing.
InterfaceMotion Inverse(const CouplerGeometry& g, const ActuatorPair& a, InverseForm form);

}  // namespace rths::models::marths
