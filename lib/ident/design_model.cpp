#include "ident/design_model.h"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "ident/identify.h"
#include "models/benchmark_plant.h"
#include "signal/blwn.h"

namespace rths::ident {
namespace {

bool UsesModel(const control::ControllerConfig& c) {
  using K = control::ControllerKind;
  return c.kind == K::kFf || c.kind == K::kFfLp || c.kind == K::kFfLqg ||
         (c.kind == K::kAmbc && c.ambc.start == control::AmbcStart::kModel);
}

/// Third-order fit of the benchmark plant's Gp from a noise-free BLWN record through it.
FitSummary FitBenchmarkGp(const models::BenchmarkPlantParams& p, double dt_s) {
  const models::BenchmarkPlant plant = models::BenchmarkPlant::Make(p, dt_s);
  models::BenchmarkPlantState st;
  return FitDesignModel([&](double u_mm) {
    const double y_mm = 1e3 * models::Output(plant, st);  // y_k from u_0 .. u_{k-1}
    models::StepMm(plant, &st, u_mm);
    return y_mm;
  }, dt_s);
}

}  // namespace

FitSummary FitDesignModel(const std::function<double(double u_mm)>& plant, double dt_s) {
  constexpr double kDurationS = 20.0, kBandHz = 30.0, kFitHiHz = 25.0, kRmsMm = 1.0;
  constexpr std::uint64_t kSeed = 11;
  const auto n = static_cast<std::size_t>(std::llround(kDurationS / dt_s));
  const std::vector<double> u = signal::Blwn(std::min(kBandHz, 0.4 / dt_s), kRmsMm, dt_s, n, kSeed, 2.0);
  std::vector<double> y(n);
  for (std::size_t k = 0; k < n; ++k) y[k] = plant(u[k]);
  IdentifyOptions o;
  o.fit.poles = 3;
  o.fit.band_lo_hz = 0.5;
  o.fit.band_hi_hz = std::min(kFitHiHz, 0.3 / dt_s);
  o.fit.zoh_dt_s = 0.0;  // a design model: the hold's half-sample lag in the fit, as the study's
  return Identify(u, y, dt_s, o).fit;
}

std::array<models::ServoModel3, 2> MarthsDesignModels(const models::marths::PlantZpk& p, double dt_s) {
  namespace mm = models::marths;
  const mm::MarthsPlant plant = mm::MakeMarthsPlant(p, dt_s);
  std::array<models::ServoModel3, 2> out;
  for (int i = 0; i < 2; ++i) {
    mm::MarthsPlantState st;
    const FitSummary fit = FitDesignModel([&](double u_mm) {
      const double y_mm = mm::PlantOutput(plant, st)(i);
      mm::PlantStep(plant, &st, i == 0 ? Eigen::Vector2d(u_mm, 0.0) : Eigen::Vector2d(0.0, u_mm));
      return y_mm;
    }, dt_s);
    out[i] = fit.model.ToServoModel3();
    out[i].name = "custom";
  }
  return out;
}

namespace {
/// ResolveDesignModel for marths.enabled.
std::string ResolveMarthsDesign(control::MarthsConfig* m, double dt_s) {
  using control::MarthsCompensator;
  if (m->compensator != MarthsCompensator::kFf && m->compensator != MarthsCompensator::kFfLqg) return "";
  std::array<models::ServoModel3*, 2> model = {&m->model_1, &m->model_2};
  if (model[0]->name != "avg" && model[1]->name != "avg") {
    return "controller: each actuator designed on marths.model_1 and marths.model_2";
  }
  const auto fits = MarthsDesignModels(models::marths::NominalPlantZpk(), dt_s);
  std::string note = "controller: each actuator designed on a third-order fit of the nominal plant's diagonal";
  for (int i = 0; i < 2; ++i) {
    if (model[i]->name != "avg") continue;
    *model[i] = fits[i];
    note += fmt::format("; H_{}{}: K = {:.5g}, p = {:.5g}, b = {:.5g}, c = {:.5g}", i + 1, i + 1, fits[i].K,
                        fits[i].p, fits[i].b, fits[i].c);
  }
  return note;
}
}  // namespace

std::string ResolveDesignModel(scenario::Scenario* s) {
  if (s->marths.enabled) return ResolveMarthsDesign(&s->marths, s->run.dt_s);
  control::ControllerConfig& c = s->controller;
  if (!UsesModel(c)) return "";
  const bool benchmark = s->plant.kind == models::PlantKind::kBenchmark;
  if (benchmark && c.model.name == "avg") {
    const FitSummary fit = FitBenchmarkGp(s->plant.benchmark.params, s->run.dt_s);
    c.model = fit.model.ToServoModel3();
    c.model.name = "custom";
    return fmt::format("controller: designed on the benchmark plant's Gp, a third-order fit (K = {:.5g}, p = {:.5g}, "
                       "b = {:.5g}, c = {:.5g}: DC gain {:.4f}, lag {:.2f} ms), not the paper's \"avg\" servo model "
                       "(controller.model's default; set controller.model to design on another)",
                       c.model.K, c.model.p, c.model.b, c.model.c, fit.model.DcGain(), 1e3 * fit.model.DcLagS());
  }
  const bool identified_plant = s->plant.kind == models::PlantKind::kLinear && s->plant.actuator.name == "custom";
  if (identified_plant && c.model.name == "avg") {
    c.model = s->plant.actuator;
    return fmt::format("controller: designed on the plant's own model, plant.actuator (K = {:.5g}, p = {:.5g}, "
                       "b = {:.5g}, c = {:.5g}), not the paper's \"avg\" servo model (controller.model's default; "
                       "set controller.model to design on another)",
                       c.model.K, c.model.p, c.model.b, c.model.c);
  }
  if (identified_plant && c.model.name != "custom") {
    return fmt::format("warning: controller: designed on the paper's servo model \"{}\" (controller.model), not on "
                       "the identified model the plant runs, plant.actuator (K = {:.5g}, p = {:.5g}, b = {:.5g}, "
                       "c = {:.5g}); leave controller.model out to design on it",
                       c.model.name, s->plant.actuator.K, s->plant.actuator.p, s->plant.actuator.b, s->plant.actuator.c);
  }
  if (c.model.name == "custom")
    return fmt::format("controller: designed on controller.model (K = {:.5g}, p = {:.5g}, b = {:.5g}, c = {:.5g})",
                       c.model.K, c.model.p, c.model.b, c.model.c);
  if (benchmark)
    return fmt::format("warning: controller: designed on the paper's servo model \"{}\" (controller.model), a model "
                       "of the damper rig, not of the benchmark plant this scenario drives (plant.kind = "
                       "\"benchmark\"); leave controller.model out to design on the plant's Gp",
                       c.model.name);
  return fmt::format("controller: designed on the paper's servo model \"{}\" (controller.model)", c.model.name);
}

}  // namespace rths::ident
