#include "models/benchmark_rig.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

void ValidateBenchmarkDaq(const BenchmarkDaqConfig& daq, std::string_view where) {
  const std::string at(where);
  if (!std::isfinite(daq.volts_per_m) || !(daq.volts_per_m > 0.0))
    throw Error(at, fmt::format("volts_per_m [V/m] must be finite and > 0 (got {})", daq.volts_per_m));
  if (!std::isfinite(daq.saturation_V) || !(daq.saturation_V > 0.0))
    throw Error(at, fmt::format("saturation_V [V] must be finite and > 0 (got {})", daq.saturation_V));
  if (daq.bits < 2 || daq.bits > 32)
    throw Error(at, fmt::format("bits must be in [2, 32] (got {})", daq.bits));
}

namespace {
/// Volts per millimetre.
double VoltsPerMm(const BenchmarkDaqConfig& daq) { return 1e-3 * daq.volts_per_m; }
/// Quantisation step [V].
double StepV(const BenchmarkDaqConfig& daq) { return 2.0 * daq.saturation_V / std::ldexp(1.0, daq.bits); }
}  // namespace

double DaqStepMm(const BenchmarkDaqConfig& daq) { return StepV(daq) / VoltsPerMm(daq); }

double DaqConvertMm(const BenchmarkDaqConfig& daq, double x_mm) {
  if (!daq.enabled) return x_mm;
  const double q = StepV(daq);
  const double v = std::clamp(VoltsPerMm(daq) * x_mm, -daq.saturation_V, daq.saturation_V);
  const double top = std::ldexp(1.0, daq.bits - 1);  // 2^(bits-1): exact in a double
  const double code = std::clamp(std::round(v / q), -top, top - 1.0);
  return code * q / VoltsPerMm(daq);
}

BenchmarkRig BenchmarkRig::Make(const BenchmarkRigConfig& config, double dt_s) {
  ValidateBenchmarkDaq(config.daq);
  return {BenchmarkPlant::Make(config.params, dt_s), config.daq};
}

void Step(const BenchmarkRig& rig, BenchmarkRigState* s, double u_mm) {
  StepMm(rig.plant, &s->plant, DaqConvertMm(rig.daq, u_mm));
}

double TrueDisplacementMm(const BenchmarkRig& rig, const BenchmarkRigState& s) {
  return 1e3 * Output(rig.plant, s.plant);
}

double MeasuredDisplacementMm(const BenchmarkRig& rig, const BenchmarkRigState& s, double noise_mm) {
  return DaqConvertMm(rig.daq, TrueDisplacementMm(rig, s) + noise_mm);
}

double MeasuredForceKn(const BenchmarkRig& rig, const BenchmarkRigState& s) {
  const BenchmarkPlantParams& p = rig.plant.params;
  // z = [y, y', y'', ...] in SI (phase variables: Gp has no zeros).
  const double f_N = p.m_e_kg * s.plant.z(2) + p.c_e_N_s_per_m() * s.plant.z(1) + p.k_e_N_per_m * s.plant.z(0);
  return 1e-3 * f_N;
}

}  // namespace rths::models
