#pragma once
/// @file The evaluation criteria J1-J9 of the RTHS benchmark problem (Silva, Gomez, Maghareh,
/// Dyke & Spencer, Mech. Syst. Signal Process. 2020; docs/benchmark.md "Criteria J1-J9").
///
/// On N samples at step dt, with x_m the measured actuator displacement, x_t the target (the
/// numerical substructure's actuator floor), x_r,i the reference structure's floor i and x_n,i
/// the numerical substructure's floor i (any one unit), std the sample standard deviation
/// (N - 1 in the denominator) and indices 1-based as in the benchmark's MATLAB:
///
///     J1 = (j* - 1) dt,  j* in 1..50 maximising rho(x_m(j:N), x_t(1:N-j+1))   (Pearson correlation)
///     J2 = 100 std(x_m - x_t) / std(x_t)          J3 = 100 max|x_m - x_t| / max|x_t|
///     J4 = 100 std(x_m - x_r,a) / std(x_r,a)      J5 = 100 max|x_m - x_r,a| / max|x_r,a|
///     J6, J7 = 100 std(x_n,i - x_r,i) / std(x_r,i)       for the floors i != a
///     J8, J9 = 100 max|x_n,i - x_r,i| / max|x_r,i|
///
/// a is the actuator's floor (1 in the benchmark). The benchmark has 3 floors and a = 1, so J6, J8
/// belong to floor 2 and J7, J9 to floor 3. For another structure the per-floor errors are in
/// BenchmarkCriteria::floors, one entry per floor other than a (ascending); J6/J8 are the first
/// of them and J7/J9 the second (NaN where there is no such floor). Ties in J1 go to the smaller
/// lag. J1 is reported in ms rounded to 0.1 ms, J2-J9 in % rounded to 0.01 % (Rounded()).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace rths::signal {

/// Smallest record the criteria accept: J1 tries lags up to 49 samples and needs 2 samples left.
inline constexpr std::size_t kBenchmarkMinSamples = 51;
/// J1's largest lag j* [samples, 1-based] (J1 <= 49 dt).
inline constexpr int kBenchmarkMaxLag = 50;

/// The per-floor errors of the numerical substructure against the reference (J6-J9's kind).
struct FloorCriteria {
  int floor = 0;         ///< 1-based floor (DOF) number
  double std_pct = 0.0;  ///< 100 std(x_n,i - x_r,i) / std(x_r,i) [%]
  double max_pct = 0.0;  ///< 100 max|x_n,i - x_r,i| / max|x_r,i| [%]
};

/// J1-J9 (raw values unless made by Rounded()).
struct BenchmarkCriteria {
  double J1_ms = 0.0;   ///< (j* - 1) dt [ms]; NaN if x_m does not vary at any lag
  double J2_pct = 0.0;  ///< [%]
  double J3_pct = 0.0;  ///< [%]
  double J4_pct = 0.0;  ///< [%]
  double J5_pct = 0.0;  ///< [%]
  double J6_pct = 0.0;  ///< floors[0].std_pct (floor 2 of the benchmark) [%], NaN if there is none
  double J7_pct = 0.0;  ///< floors[1].std_pct (floor 3) [%], NaN if there is none
  double J8_pct = 0.0;  ///< floors[0].max_pct (floor 2) [%], NaN if there is none
  double J9_pct = 0.0;  ///< floors[1].max_pct (floor 3) [%], NaN if there is none
  int lag_samples = 0;  ///< j* - 1 [samples] (-1 with J1 NaN)
  std::vector<FloorCriteria> floors;  ///< every floor but the actuator's, ascending

  /// J1 rounded to 0.1 ms, every percentage (J2-J9 and floors) to 0.01 % (half away from zero).
  BenchmarkCriteria Rounded() const;
  /// One line, rounded as the benchmark reports: "J1 25.4 ms  J2 12.34 %  ...  J9 0.12 %".
  std::string Format() const;
  /// J(i + 1): i = 0 gives J1_ms, i = 1 .. 8 give J2_pct .. J9_pct.
  double At(int i) const;
};

/// The inputs of BenchmarkCriteriaFrom: equal-length records sampled at dt_s.
struct BenchmarkSignals {
  double dt_s = 0.0;                          ///< sample step [s] (> 0)
  std::vector<double> x_m;                    ///< measured actuator displacement
  std::vector<double> x_t;                    ///< target: the numerical substructure's actuator floor
  std::vector<std::vector<double>> x_n;       ///< numerical substructure, floor i in x_n[i - 1]
  std::vector<std::vector<double>> x_r;       ///< reference structure, floor i in x_r[i - 1]
  int actuator_floor = 1;                     ///< a, 1-based
};

/// Pearson correlation of two equal-length spans; NaN if either does not vary.
double PearsonCorrelation(std::span<const double> a, std::span<const double> b);

/// J1-J9 of `s` (the file comment). Throws rths::Error ("benchmark criteria: <what>") if dt_s is
/// not finite and > 0, x_n and x_r have different floor counts or none, actuator_floor is out of
/// [1, floors], any record's length differs from x_m's, the records are shorter than
/// kBenchmarkMinSamples, a value is not finite (naming the record and the sample), or a
/// denominator is zero: x_t or a reference floor that does not move (zero std or max).
BenchmarkCriteria BenchmarkCriteriaFrom(const BenchmarkSignals& s);

}  // namespace rths::signal
