// bench-nonlinear_structure: the cost of one RTHS step of each structural integrator on the 9-story
// building (data/buildings/ohtori9_ns.txt: its masses and modal damping) made nonlinear -- a
// Bouc-Wen spring per story with the file's story stiffness, alpha = 0.1, x_y = 20 mm (0.5 % of a
// 4 m story), n = 1, beta = gamma = 0.5 -- under El Centro NS, side by side in one invocation: us per
// step (median of --repeat runs of the whole record), with the peak ductility, the hysteretic
// energy and the roof NRMSE against the CVODE reference (models/structure_reference.h).
//
//   build/bin/bench-nonlinear_structure [--scale S] [--repeat N] [--root DIR]   (from the repository root)
#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "models/integrator_accuracy.h"
#include "models/structure_file.h"
#include "signal/stats.h"

using namespace rths::models;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  CLI::App app{"us per step of each structural integrator on the nonlinear 9-story building"};
  double scale = 1.0;
  int repeat = 3;
  std::string src = ".";
  app.add_option("--root", src, "repository root (data/ is read from there)");
  app.add_option("--scale", scale, "El Centro scale factor")->check(CLI::Range(0.01, 10.0));
  app.add_option("--repeat", repeat, "runs per integrator (median)")->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);

  const StructureMatrices file = LoadStructureFile(src + "/data/buildings/ohtori9_ns.txt");
  const int n = static_cast<int>(file.M.rows());
  std::vector<double> masses;
  std::vector<SpringParams> springs;
  for (int i = 0; i < n; ++i) {
    masses.push_back(file.M(i, i) * 1e6);
    SpringParams p;
    p.kind = SpringKind::kBoucWen;
    p.k_kN_per_mm = i + 1 < n ? file.K(i, i) + file.K(i, i + 1) : file.K(i, i);  // story i+1
    p.alpha = 0.1, p.x_y_mm = 20.0, p.n = 1.0, p.beta = 0.5, p.gamma = 0.5;
    springs.push_back(p);
  }
  const NonlinearBuilding b = NonlinearBuilding::Make(masses, springs, file.C, n - 1, 1.0);
  const double dt = 0.0005;
  const std::vector<double> ag = ElCentroGround(src + "/data/ground_motion/elcentro_1940_ns_g.txt", scale, dt, 40.0);

  auto t0 = Clock::now();
  const ReferenceSolution ref = SolveReference(b, dt, ag);
  const double ref_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const ResponseSummary rs = Summarize(ref.x_mm);
  const double duct = *std::max_element(rs.peak_drift_mm.begin(), rs.peak_drift_mm.end()) / 20.0;
  fmt::print("9-story Bouc-Wen building, El Centro x {}, dt = {} s, {} steps\n", scale, dt, ag.size());
  fmt::print("reference ({}): {:.2f} s, peak ductility {:.3f}, E_h {:.1f} kN mm\n\n", ref.method, ref_s, duct,
             ref.hysteretic_energy_kN_mm);
  fmt::print("{:<24} {:>10} {:>12} {:>9} {:>10} {:>12} {:>10}\n", "integrator", "us/step", "x central", "of dt [%]",
             "ductility", "E_h [kN mm]", "NRMSE [%]");
  double us_cd = 0.0;  // central difference's median, the ratio's denominator (measured first, same run)

  std::vector<IntegratorConfig> configs(6);
  configs[0].kind = IntegratorKind::kCentralDifference;
  configs[1].kind = IntegratorKind::kCentralDifference, configs[1].substeps = 4;
  configs[2].kind = IntegratorKind::kCr;
  configs[3].kind = IntegratorKind::kAlphaOs, configs[3].alpha = -0.05;
  configs[4].kind = IntegratorKind::kNewmarkImplicit, configs[4].newton_iterations = 1;
  configs[5].kind = IntegratorKind::kNewmarkImplicit, configs[5].newton_iterations = 3;
  for (const IntegratorConfig& c : configs) {
    const StructureIntegrator integ = StructureIntegrator::Make(b, dt, c);
    std::vector<double> us;
    SimulatedRun run;
    for (int r = 0; r < repeat; ++r) {
      IntegratorState s = MakeIntegratorState(b);
      t0 = Clock::now();
      for (std::size_t k = 0; k + 1 < ag.size(); ++k) Advance(integ, &s, ag[k], ag[k + 1], 0.0);
      us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / (ag.size() - 1));
    }
    run = Simulate(integ, ag);
    const ResponseSummary sum = Summarize(run.x_mm);
    const double med = rths::signal::Median(us);
    if (us_cd == 0.0) us_cd = med;
    fmt::print("{:<24} {:>10.3f} {:>12.2f} {:>9.3f} {:>10.3f} {:>12.1f} {:>10.4f}\n", Describe(c), med, med / us_cd,
               100.0 * med * 1e-6 / dt,
               *std::max_element(sum.peak_drift_mm.begin(), sum.peak_drift_mm.end()) / 20.0,
               run.hysteretic_energy_kN_mm, NrmsePct(run.x_mm.row(n - 1), ref.x_mm.row(n - 1)));
  }
  return 0;
}
