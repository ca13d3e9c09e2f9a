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
namespace rths::models::marths {

/// The coupler's arms (fcn_coupler_geometry.m). SI.
struct CouplerGeometry {
  double xv1_m = 0.26670, yv1_m = -0.127;
  double xv2_m = 0.26670, yv2_m = 0.127;
  double alpha1_rad = -25.4633 * 3.14159265358979323846 / 180.0;
  double alpha2_rad = 25.4633 * 3.14159265358979323846 / 180.0;
  double d1_m() const;  ///< sqrt(xv1^2 + yv1^2)
  double d2_m() const;  ///< sqrt(xv2^2 + yv2^2)
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

/// Forward kinematics (the file comment).
ActuatorPair Forward(const CouplerGeometry& g, const InterfaceMotion& m);

/// Inverse kinematics from the measured strokes. |r| > 1 (a stroke difference the coupler
/// cannot make) gives theta NaN, as asin does.
InterfaceMotion Inverse(const CouplerGeometry& g, const ActuatorPair& a, InverseForm form);

}  // namespace rths::models::marths
