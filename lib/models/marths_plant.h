#pragma once
/// @file The maRTHS benchmark's control plant: the two actuators, their servo loops and the frame
/// they drive, identified as a 2 x 2 transfer matrix from the commands [u_1, u_2] to the measured
/// strokes [y_1, y_2] (both mm); fcn_build_uncert_plant.m of FermandoisLab/maRTHS-bmk-RoDeAC and
/// its ID_Control_plant_100Hz.mat; docs/marths.md "Control plant".
///
/// In zero-pole-gain form (MATLAB's zpk: k prod(s - z) / prod(s - p)), every pole and zero in
/// rad/s = 2 pi x the Hz below:
///
///     frame poles       p_f = (-50 +/- 63 j) 2 pi
///     H11, H21          zeros -120 2pi, -90 2pi;  poles -2.65 2pi, -40 2pi, p_f;  k = 2165.2, 349.95
///     H12, H22          zero -3 2pi (H12), -5 2pi (H22);  poles -3.5 2pi, -18.5 2pi, p_f;  k = 4.5394e6, 1.9238e7
///
/// giving the DC gains H11 0.8638, H21 0.1396, H12 0.1311, H22 0.9258. Each column is realised
/// with 4 states (controllable canonical form in a basis scaled by w = d_0^(1/4), so the matrices'
/// entries are of the order of the poles), 8 in all, y = C x (no direct term).
///
/// The reference code integrates the continuous plant with Simulink's ode4 (classic Runge-Kutta),
/// one step per loop sample, the command held over it (a discrete block's output). For a linear
/// plant that step is exactly
///
///     x_{k+1} = P(h A) x_k + h Q(h A) B u_k,  P(X) = I + X + X^2/2 + X^3/6 + X^4/24,
///                                             Q(X) = I + X/2 + X^2/6 + X^3/24,
///
/// computed once (MarthsPlant). Perturbed plants (the script's uncertainty model): each pole and
/// zero z drawn as z (1 + s N(0, 1)) with s = 5.5 % (H11/H21 zeros), 6 % (their real poles),
/// 3 % (H12/H22 zeros and real poles), 5 % (the frame pole, the pair kept conjugate), in the
/// script's order; each gain then rescaled to keep its nominal low-frequency gain (the script
/// matches the magnitude at the lowest frequency of MATLAB's Bode grid; here the DC gain:
/// docs/marths.md "Decisions").
#include <array>
#include <complex>

#include <Eigen/Core>

#include "signal/random.h"

namespace rths::models::marths {

/// The plant's poles, zeros and gains [rad/s] (zpk form; the file comment).
struct PlantZpk {
  std::complex<double> frame_pole;     ///< upper of the pair (the lower is its conjugate)
  double h1z1 = 0, h1z2 = 0;           ///< zeros of H11 and H21
  double h1p1 = 0, h1p2 = 0;           ///< real poles of H11 and H21
  double h12z1 = 0, h22z1 = 0;         ///< zero of H12, of H22
  double h2p1 = 0, h2p2 = 0;           ///< real poles of H12 and H22
  double k11 = 0, k21 = 0, k12 = 0, k22 = 0;  ///< zpk gains
};

/// The nominal plant (fcn_build_uncert_plant.m's nominal model).
PlantZpk NominalPlantZpk();

/// Column j's common denominator (s - p_a)(s - p_b)(s - p_f)(s - conj p_f), monic: its
/// coefficients of s^0 .. s^4 (the last is 1). j = 0, 1.
std::array<double, 5> ColumnDenominator(const PlantZpk& p, int j);

/// DC gain matrix [[H11, H12], [H21, H22]] (mm/mm).
Eigen::Matrix2d DcGain(const PlantZpk& p);

/// H(j w) at w [rad/s].
Eigen::Matrix2cd Response(const PlantZpk& p, double w_rad_s);

/// A perturbed plant: nine standard normal draws from `g` in the script's order
/// (h1z1, h1z2, h1p1, h1p2, frame pole, h12z1, h2p1, h2p2, h22z1), gains rescaled to keep each
/// element's nominal DC gain. Throws rths::Error if a drawn pole is not in the left half plane
/// (then the plant would be unstable; the script does not check).
PlantZpk PerturbedPlantZpk(const PlantZpk& nominal, signal::GaussianState* g);

/// The plant stepped as the reference code's ode4 steps it (the file comment). Immutable.
struct MarthsPlant {
  Eigen::Matrix<double, 8, 8> A;       ///< continuous, scaled basis [1/s]
  Eigen::Matrix<double, 8, 2> B;
  Eigen::Matrix<double, 2, 8> C;
  Eigen::Matrix<double, 8, 8> P;       ///< RK4 step: x_{k+1} = P x_k + G u_k
  Eigen::Matrix<double, 8, 2> G;
  double dt_s = 0.0;
};

/// Realises `p` and forms the RK4 step at dt_s (> 0). Throws rths::Error otherwise.
MarthsPlant MakeMarthsPlant(const PlantZpk& p, double dt_s);

/// Per-step state: x at t_k.
struct MarthsPlantState {
  Eigen::Matrix<double, 8, 1> x = Eigen::Matrix<double, 8, 1>::Zero();
};

/// The plant's strokes at t_k [mm] (no noise). Allocates nothing.
Eigen::Vector2d PlantOutput(const MarthsPlant& m, const MarthsPlantState& s);

/// t_k -> t_{k+1} with [u_1, u_2] [mm] held. Allocates nothing.
void PlantStep(const MarthsPlant& m, MarthsPlantState* s, const Eigen::Vector2d& u_mm);

/// The reference code's sensor noise: Simulink's Band-Limited White Noise with power
/// 1.5e-7 at sample time dt: standard deviation sqrt(1.5e-7 / dt) [mm] (0.01239 mm at 1024 Hz).
double SensorNoiseMm(double dt_s);

}  // namespace rths::models::marths
