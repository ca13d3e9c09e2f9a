#include "models/integrator_accuracy.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/history.h"

namespace rths::models {

NonlinearBuilding ReferenceSdof() {
  const double m = 20000.0 * 1e-6, w = 2.0 * std::numbers::pi * 5.0;
  SpringParams p;
  p.kind = SpringKind::kBoucWen;
  p.k_kN_per_mm = m * w * w;
  p.alpha = 0.1, p.x_y_mm = 4.0, p.n = 1.0, p.beta = 0.5, p.gamma = 0.5;
  return NonlinearBuilding::Make({20000.0}, {p}, Eigen::MatrixXd::Constant(1, 1, 2.0 * 0.02 * m * w), 0, 1.0);
}

std::vector<double> ElCentroGround(const std::string& path, double scale, double dt, double duration_s,
                                   double start_s) {
  const auto n = static_cast<std::size_t>(std::llround(duration_s / dt));
  return signal::LoadHistory(path, 0.02, 9810.0 * scale, dt, n, start_s);
}

std::string Describe(const IntegratorConfig& c) {
  std::string s(NameOf(kIntegratorKindNames, c.kind));
  if (c.kind == IntegratorKind::kAlphaOs) s += fmt::format("({})", c.alpha);
  if (c.kind == IntegratorKind::kNewmarkImplicit) s += fmt::format("({} it)", c.newton_iterations);
  if (c.substeps > 1) s += fmt::format(" x{}", c.substeps);
  return s;
}

std::vector<double> ResampleLinear(const std::vector<double>& samples, int r) {
  if (r < 1) throw Error("ResampleLinear", fmt::format("the ratio must be >= 1 (got {})", r));
  const std::size_t n = samples.size();
  std::vector<double> out(n * static_cast<std::size_t>(r));
  for (std::size_t k = 0; k < n; ++k) {
    const double next = samples[std::min(k + 1, n - 1)];
    for (int i = 0; i < r; ++i)
      out[k * static_cast<std::size_t>(r) + static_cast<std::size_t>(i)] =
          samples[k] + (next - samples[k]) * (static_cast<double>(i) / r);
  }
  return out;
}

AccuracyStudy MeasureAccuracy(const NonlinearBuilding& b, double dt, const SampledHistory& ground, int levels,
                              const std::vector<IntegratorConfig>& configs, const SampledHistory& force,
                              double rtol) {
  const auto force_at = [&](double h) { return force ? force(h) : std::vector<double>{}; };
  AccuracyStudy out;
  out.reference = SolveReference(b, dt, ground(dt), force_at(dt), rtol);
  out.reference_summary = Summarize(out.reference.x_mm);
  const Eigen::Index roof = b.dofs() - 1, N = out.reference.x_mm.cols();
  const Eigen::RowVectorXd ref = out.reference.x_mm.row(roof);
  for (const IntegratorConfig& c : configs) {
    double prev = 0.0;
    for (int j = 0; j < levels; ++j) {
      const int r = 1 << j;
      const double h = dt / r;
      const SimulatedRun run = Simulate(StructureIntegrator::Make(b, h, c), ground(h), force_at(h));
      Eigen::MatrixXd x(b.dofs(), N);  // at the RTHS samples
      for (Eigen::Index k = 0; k < N; ++k) x.col(k) = run.x_mm.col(k * r);
      AccuracyRow row;
      row.integrator = Describe(c);
      row.dt_s = h;
      row.summary = Summarize(x);
      row.hysteretic_energy_kN_mm = run.hysteretic_energy_kN_mm;
      row.nrmse_pct = NrmsePct(x.row(roof), ref);
      row.max_error_mm = (x.row(roof) - ref).cwiseAbs().maxCoeff();
      row.order = j > 0 ? std::log2(prev / row.nrmse_pct) : 0.0;
      row.max_residual_kN = run.max_residual_kN;
      prev = row.nrmse_pct;
      out.rows.push_back(row);
    }
  }
  return out;
}

}  // namespace rths::models
