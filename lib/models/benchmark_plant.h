#pragma once
/// @file The control plant of the RTHS benchmark problem (Silva, Gomez, Maghareh, Dyke & Spencer,
/// Mech. Syst. Signal Process. 2020; docs/benchmark.md): commanded actuator displacement u to
/// measured displacement y of the servohydraulic actuator loaded by the experimental substructure.
///
/// **Units: SI (m, N, kg, s), unlike the rest of the project (docs/units.md).** The benchmark's
/// constants are SI, so this model is SI inside and converts at its edge: the transfer function is
/// displacement over displacement (m/m = mm/mm), Step() takes and returns metres, StepMm() takes
/// and returns millimetres (u_m = 1e-3 u_mm, y_mm = 1e3 y_m). Only the internal states (y and its
/// derivatives) carry SI units.
///
/// The plant, as the benchmark's reference code defines it:
///
///     Gs(s)   = a1b0 / (s^2 + b1 s + b2)                 servo-valve and controller
///     Ga(s)   = 1 / (s + a3)                             actuator
///     Gest(s) = 1 / (m_e s^2 + c_e s + k_e)              experimental substructure, c_e = 2 zeta_e sqrt(m_e k_e)
///     G0(s)   = Ga Gest / (1 + a2 s Ga Gest)             control-structure interaction
///     Gp(s)   = gain Gs G0 / (1 + Gs G0)                 the closed servo loop: u -> y
///
/// By polynomial algebra, with D0(s) = (s + a3)(m_e s^2 + c_e s + k_e) + a2 s (third order):
///
///     Gp(s) = gain a1b0 / ((s^2 + b1 s + b2) D0(s) + a1b0)      (fifth order, no zeros)
///
/// and DC gain gain a1b0 / (b2 a3 k_e + a1b0) = 1.0075 at the nominal constants.
///
/// Realisation (phase variables, as models::LinearServo): with the denominator made monic,
/// den(s) = s^5 + d4 s^4 + ... + d0 and numerator n0 = gain a1b0 / m_e, the state is
/// z = [y, y', y'', y''', y''''] [m, m/s, m/s^2, m/s^3, m/s^4]:
///
///     z' = A z + B u,  y = C z,  A = companion(d),  B = [0, 0, 0, 0, n0]^T,  C = [1, 0, 0, 0, 0].
///
/// ZOH: z_{k+1} = Phi z_k + Gamma u_k, Phi = e^{A dt}, Gamma = int_0^dt e^{A s} ds B, from one
/// exponential of the augmented matrix taken in the balanced basis diag(1, 1/w, ..., 1/w^4) z,
/// w = d0^(1/5) (the geometric mean of the pole magnitudes).
#include <array>
#include <complex>
#include <cstdint>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace rths::models {

/// Order of the benchmark plant Gp (checked when it is assembled).
inline constexpr int kBenchmarkPlantOrder = 5;

/// The benchmark plant's constants (SI). Defaults: the nominal plant of the benchmark, case 1.
struct BenchmarkPlantParams {
  double gain = 1.0261;          ///< output gain of Gp [-] (> 0)
  double a1b0 = 2.1283e13;       ///< numerator of Gs [N/(m s^3)] (> 0)
  double a2 = 4.2297e6;          ///< control-structure interaction of G0 [N/m] (>= 0)
  double a3 = 3.3;               ///< pole of Ga at s = -a3 [1/s] (finite; may be drawn negative)
  double b1 = 425.0;             ///< s^1 coefficient of Gs's denominator [1/s] (> 0)
  double b2 = 9.9976e4;          ///< s^0 coefficient of Gs's denominator [1/s^2] (> 0)
  double m_e_kg = 29.13;         ///< experimental substructure's mass [kg] (> 0)
  double k_e_N_per_m = 1.19e6;   ///< experimental substructure's stiffness [N/m] (> 0)
  double zeta_e = 0.0097;        ///< experimental substructure's damping ratio [-] (>= 0)

  /// Viscous damping c_e = 2 zeta_e sqrt(m_e k_e) [N s/m] (follows a perturbed k_e).
  double c_e_N_s_per_m() const;
  bool operator==(const BenchmarkPlantParams&) const = default;
};

/// Standard deviations of the benchmark's Gaussian parameter uncertainty (perturbed runs):
/// b1 = 425 + 3.3 N(0,1), b2 = 9.9976e4 + 3.3e3 N, a3 = 3.3 + 1.3 N, k_e = 1.19e6 + 5e4 N.
struct BenchmarkUncertainty {
  double b1_sigma = 3.3;                ///< [1/s]
  double b2_sigma = 3.3e3;              ///< [1/s^2]
  double a3_sigma = 1.3;                ///< [1/s]
  double k_e_sigma_N_per_m = 5.0e4;     ///< [N/m]
};

/// `nominal` with b1, b2, a3 and k_e perturbed by independent Gaussian deviates, drawn in that
/// order from signal::MakeGaussian(seed) (portable: the same seed gives the same plant on any
/// platform). Nothing is truncated: a3 < 0 (probability 0.6 %) is kept, Gp stays stable for
/// it (ValidateBenchmarkParams checks). The other constants are copied.
BenchmarkPlantParams PerturbedBenchmarkParams(const BenchmarkPlantParams& nominal, std::uint64_t seed,
                                              const BenchmarkUncertainty& sigma = {});

/// Throws rths::Error (prefixed `where`, e.g. "scenario.toml: plant.benchmark") unless every
/// constant is finite, gain, a1b0, b1, b2, m_e, k_e > 0, a2 >= 0, zeta_e >= 0, and Gp is stable
/// (every pole has a negative real part). The message names the field and its allowed range.
void ValidateBenchmarkParams(const BenchmarkPlantParams& p, std::string_view where = "benchmark plant");

/// Gp as polynomials in s, coefficients in ascending powers (index i is the s^i coefficient),
/// both divided by m_e so that the denominator is monic: num has 1 entry, den 6.
struct BenchmarkPolynomials {
  Eigen::VectorXd num;  ///< [n0], n0 = gain a1b0 / m_e
  Eigen::VectorXd den;  ///< [d0, d1, d2, d3, d4, 1]
};
/// Assembles Gp from Gs, Ga, Gest and G0 by polynomial products (no validation).
BenchmarkPolynomials BenchmarkPlantPolynomials(const BenchmarkPlantParams& p);

/// Immutable description of one benchmark plant: its polynomials, continuous realisation and ZOH
/// discretisation at dt_s.
struct BenchmarkPlant {
  using Matrix = Eigen::Matrix<double, kBenchmarkPlantOrder, kBenchmarkPlantOrder>;
  using Vector = Eigen::Matrix<double, kBenchmarkPlantOrder, 1>;
  using Row = Eigen::Matrix<double, 1, kBenchmarkPlantOrder>;

  BenchmarkPlantParams params;  ///< the constants it was built from
  BenchmarkPolynomials poly;    ///< Gp = num / den (monic)
  Matrix A;                     ///< companion matrix of den
  Vector B;                     ///< [0, 0, 0, 0, n0]^T
  Row C;                        ///< [1, 0, 0, 0, 0]
  Matrix Phi;                   ///< e^{A dt}
  Vector Gamma;                 ///< int_0^dt e^{A s} ds B
  double dt_s = 0.0;            ///< ZOH step [s]

  /// Validates `p` (ValidateBenchmarkParams) and dt_s (finite, > 0), then builds the model.
  /// Throws rths::Error otherwise.
  static BenchmarkPlant Make(const BenchmarkPlantParams& p, double dt_s);
  /// Number of poles of Gp (the degree of den): 5.
  int Order() const { return static_cast<int>(poly.den.size()) - 1; }
  /// Static gain Gp(0) = n0 / d0 [m/m] (identical for the ZOH model).
  double DcGain() const;
  /// Poles of Gp [1/s] (eigenvalues of A), sorted by increasing magnitude.
  std::vector<std::complex<double>> Poles() const;
};

/// Poles of a plant with constants `p` [1/s] (roots of den), sorted by increasing magnitude.
std::vector<std::complex<double>> BenchmarkPoles(const BenchmarkPlantParams& p);

/// Per-step state z_k = [y, y', y'', y''', y''''] [m, m/s, ...]. Zero: at rest.
struct BenchmarkPlantState {
  BenchmarkPlant::Vector z = BenchmarkPlant::Vector::Zero();
};

/// Measured displacement y_k = C z_k [m]; depends on u_0 .. u_{k-1} only (strictly proper).
double Output(const BenchmarkPlant& m, const BenchmarkPlantState& s);
/// Advances one step with the command u_k [m] held over [t_k, t_{k+1}):
/// z_{k+1} = Phi z_k + Gamma u_k, and returns y_{k+1} = C z_{k+1} [m]. Allocates nothing.
double Step(const BenchmarkPlant& m, BenchmarkPlantState* s, double u_m);
/// Step() at the millimetre edge: u_mm [mm] in, y_{k+1} [mm] out.
double StepMm(const BenchmarkPlant& m, BenchmarkPlantState* s, double u_mm);

/// RMS of the benchmark's sensor noise at the loop rate, in project units.
struct BenchmarkNoiseRms {
  double y_mm = 0;  ///< displacement noise [mm]
  double f_kN = 0;  ///< force noise [kN]
};
/// The benchmark's band-limited white noise at the loop rate dt_s [s]: variance = power / dt
/// (Simulink's Band-Limited White Noise block with sample time dt), with the benchmark's SI
/// powers, displacement 6.25e-14 m^2 s and force 1.16e-3 N^2 s:
///
///     y_mm = 1e3 sqrt(6.25e-14 / dt_s),   f_kN = 1e-3 sqrt(1.16e-3 / dt_s)
///
/// (at 4096 Hz: 0.0160 mm and 0.00218 kN). These are plant.noise_y_mm_rms and
/// plant.noise_f_kN_rms of a run at run.dt_s = dt_s. Throws rths::Error unless dt_s is finite and > 0.
BenchmarkNoiseRms BenchmarkSensorNoise(double dt_s);

/// Frequency response at f_hz [Hz] (m/m): continuous num/den at s = j w if !discrete, else the
/// ZOH model C (zI - Phi)^-1 Gamma at z = e^{j w dt}.
std::complex<double> FrequencyResponse(const BenchmarkPlant& m, double f_hz, bool discrete);
/// Time lag -phase(f) / w [s], phase unwrapped from 0 at DC. f_hz > 0 (else rths::Error).
double TimeLagS(const BenchmarkPlant& m, double f_hz, bool discrete);

}  // namespace rths::models
