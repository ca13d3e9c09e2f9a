#pragma once
/// @file The evaluation criteria of the maRTHS benchmark (Condori Uribe et al. 2023, section 3.7;
/// S5_Evaluation.m of FermandoisLab/maRTHS-bmk-RoDeAC; docs/marths.md "Criteria").
///
/// With std the sample standard deviation (N - 1), i = 1, 2 the actuators, x_a,i the targets and
/// x_m,i the measured strokes (with sensor noise), x_hat and theta_hat the interface motion
/// estimated from the measured strokes, and the subscripts n (numerical substructure) and r
/// (reference structure), all sampled at the loop's rate:
///
///     J1,i = finddelay(x_a,i, x_m,i) / fs [ms]     J4,i = J1,i (the script computes J4 as J1)
///     J2,i = 100 std(x_m,i - x_a,i) / std(x_a,i)   J3,i = 100 max|x_m,i - x_a,i| / max|x_a,i|
///     J5 = 100 std(x_hat - x_n) / std(x_n)          J6 = 100 max|x_hat - x_n| / max|x_n|       (X and THETA)
///     J7 = 100 std(x_hat - x_r) / std(x_r)          J9 = 100 max|x_hat - x_r| / max|x_r|       (X and THETA)
///     J8 = 100 std(x_n,s - x_r,s) / std(x_r,s)      J10 = 100 max|x_n,s - x_r,s| / max|x_r,s|  (stories s = 2, 3; X and THETA)
///
/// finddelay (MATLAB): the lag d maximising |sum_n x(n) y(n + d)| (the normalised cross-correlation
/// of x and y; y delayed by d > 0), ties to the smallest |d|, then to the positive one. Lags are
/// searched in +/- 1 s first and, if the best lies on that window's edge, over every lag.
#include <span>
#include <string>
#include <vector>

namespace rths::signal {

/// MATLAB's finddelay(x, y) [samples] (the file comment). x and y of equal length >= 2.
/// Throws rths::Error otherwise.
int FindDelay(std::span<const double> x, std::span<const double> y, int first_window);

/// The recorded signals of one maRTHS run (equal lengths).
struct MarthsSignals {
  double dt_s = 0.0;
  std::vector<double> xa1_t, xa2_t;      ///< targets [mm]
  std::vector<double> xa1_m, xa2_m;      ///< measured strokes [mm]
  std::vector<double> x_hat, r_hat;      ///< estimated interface translation [mm], rotation [rad]
  std::vector<double> x_num, r_num;      ///< numerical substructure's interface [mm], [rad]
  std::vector<double> x_ref, r_ref;      ///< reference structure's interface [mm], [rad]
  std::vector<double> x2_num, r2_num, x3_num, r3_num;  ///< numerical, stories 2 and 3 [m], [rad]
  std::vector<double> x2_ref, r2_ref, x3_ref, r3_ref;  ///< reference, stories 2 and 3 [m], [rad]
};

/// J1-J10 as summary.json's marths_criteria holds them (J4 equals J1 and is not repeated).
struct MarthsCriteria {
  double J1_1_ms = 0, J1_2_ms = 0;
  double J2_1_pct = 0, J2_2_pct = 0, J3_1_pct = 0, J3_2_pct = 0;
  double J5_X_pct = 0, J5_TH_pct = 0, J6_X_pct = 0, J6_TH_pct = 0;
  double J7_X_pct = 0, J7_TH_pct = 0;
  double J8_X2_pct = 0, J8_TH2_pct = 0, J8_X3_pct = 0, J8_TH3_pct = 0;
  double J9_X_pct = 0, J9_TH_pct = 0;
  double J10_X2_pct = 0, J10_TH2_pct = 0, J10_X3_pct = 0, J10_TH3_pct = 0;

  /// The 22 values with their keys, in the order above.
  std::vector<std::pair<std::string, double>> Items() const;
};

/// The reference code's conversion of an actuator command to the servo-valve voltage
/// (S1_Input_Data.m: volts = u / correction / gain - offset / gain) and S5_Evaluation.m's
/// "realizable" check: a run saturates when both actuators' largest |V| exceed kMarthsVoltLimit.
struct MarthsVoltage {
  double gain[2] = {7.4921, 7.3907};
  double offset[2] = {0.0092, -0.0059};
  double correction[2] = {1.053, 1.055};
  /// Actuator i's (0, 1) command u_mm [mm] in volts [V].
  double Volts(int i, double u_mm) const { return u_mm / correction[i] / gain[i] + (-offset[i] / gain[i]); }
};
inline constexpr double kMarthsVoltLimit = 3.8;  ///< [V]
/// S5_Evaluation.m's flag: both actuators' largest |V| [V] exceed kMarthsVoltLimit (not realizable).
inline bool MarthsSaturated(double max_volts_1, double max_volts_2) {
  return max_volts_1 > kMarthsVoltLimit && max_volts_2 > kMarthsVoltLimit;
}

/// The criteria of `s`. Throws rths::Error if lengths differ, fewer than 2 samples, dt_s is not
/// > 0, or a denominator is zero.
MarthsCriteria MarthsCriteriaFrom(const MarthsSignals& s);

}  // namespace rths::signal
