#include "models/rig.h"

#include <fmt/format.h>

#include "core/error.h"
#include "models/effect_rig.h"
#include "models/linear_rig.h"
#include "models/servo_physical.h"
#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/ode.h"

namespace rths::models {
namespace {

// Rig over a model with its stepper and state (LinearRig or PhysicalRig).
template <class Model, class Stepper, class State>
class RigAdapter final : public Rig {
 public:
  explicit RigAdapter(const Model& rig) : rig_(rig), stepper_(rig_) {}
  void Step(double u_mm, double i_cmd_A) override {
    if (k_ == 0) state_.current = StartState(rig_.driver.params, i_cmd_A);  // [plant.current_driver] start
    stepper_.Step(&state_, u_mm, i_cmd_A);
    ++k_;
  }
  double y_mm() const override { return MeasuredDisplacementMm(rig_, state_); }
  double f_kN() const override { return MeasuredForceKn(rig_, state_); }
  double current_A() const override { return EffectiveCurrentA(rig_, state_); }
  std::int64_t k() const override { return k_; }

 private:
  const Model rig_;
  Stepper stepper_;
  State state_{};
  std::int64_t k_ = 0;
};
using LinearRigAdapter = RigAdapter<LinearRig, LinearRigStepper, LinearRigState>;
using PhysicalRigAdapter = RigAdapter<PhysicalRig, PhysicalRigStepper, PhysicalRigState>;

// The ideal loading system (plant.kind = "ideal"): the MR damper driven by the desired motion
// itself, x(t) linear between samples; y_k = r_k bit for bit.
class IdealRig final : public Rig {
 public:
  IdealRig(const MrDamperParams& params, bool damper, bool current_dynamics, double dt_s, double rtol,
           const CurrentDriverParams& driver)
      : params_(params),
        damper_(damper),
        current_dynamics_(current_dynamics),
        dt_(dt_s),
        driver_(CurrentDriver::Make(driver, dt_s)),
        ode_(2, rtol, rtol * 0.01, &IdealRig::Rhs, this) {
    params_.Validate();
  }
  void StartAt(double x_mm) override {
    x_ = x_mm;
    v_ = 0.0;
  }
  void Step(double r_mm, double i_cmd_A) override {
    if (k_ == 0) state_ = StartState(driver_.params, i_cmd_A);  // [plant.current_driver] start
    if (current_dynamics_) {
      Hold(driver_, &state_, i_cmd_A);
    } else {
      state_ = SteadyState(i_cmd_A);
    }
    constant_ = AtSteadyState(state_);
    x0_ = x_;
    v_ = (r_mm - x_) / dt_;
    if (damper_) {
      if (constant_) coef_ = CoefficientsAt(params_, state_.held_A);
      double w[2] = {d_.y_mm, d_.z_mm};
      ode_.Advance(0.0, dt_, w);
      d_ = {w[0], w[1]};
    }
    if (current_dynamics_) Advance(driver_, &state_);
    x_ = r_mm;  // exactly r_k: no arithmetic between the request and the measurement
    ++k_;
  }
  double y_mm() const override { return x_; }
  double f_kN() const override {
    if (!damper_) return 0.0;
    return DamperForceKn(CoefficientsAt(params_, current_A()), d_, x_, v_);
  }
  double current_A() const override { return k_ == 0 ? 0.0 : EffectiveCurrentA(driver_, state_); }
  std::int64_t k() const override { return k_; }
  bool TracksDesired() const override { return true; }

 private:
  static int Rhs(double t, const double* w, double* wdot, void* self) {
    const auto* me = static_cast<const IdealRig*>(self);
    const double x = me->x0_ + me->v_ * t;
    const MrDamperCoefficients coef =
        me->constant_ ? me->coef_
                      : CoefficientsAt(me->params_, EffectiveCurrentAt(me->driver_, me->state_, t));
    const MrDamperRates r = DamperRates(coef, {w[0], w[1]}, x, me->v_);
    wdot[0] = r.ydot_mm_s;
    wdot[1] = r.zdot_mm_s;
    return 0;
  }

  MrDamperParams params_;
  bool damper_, current_dynamics_;
  double dt_;
  CurrentDriver driver_;
  CurrentDriverState state_{};
  MrDamperState d_{};
  MrDamperCoefficients coef_{};
  bool constant_ = true;
  double x_ = 0.0, x0_ = 0.0, v_ = 0.0;
  std::int64_t k_ = 0;
  OdeStepper ode_;
};

// The RTHS benchmark's plant (plant.kind = "benchmark"): no damper, no current.
class BenchmarkRigAdapter final : public Rig {
 public:
  explicit BenchmarkRigAdapter(BenchmarkRig rig) : rig_(std::move(rig)) {}
  void Step(double u_mm, double /*i_cmd_A: no damper*/) override {
    models::Step(rig_, &state_, u_mm);
    ++k_;
  }
  double y_mm() const override { return MeasuredDisplacementMm(rig_, state_); }
  double MeasuredYMm(double noise_mm) const override { return MeasuredDisplacementMm(rig_, state_, noise_mm); }
  double f_kN() const override { return MeasuredForceKn(rig_, state_); }
  double current_A() const override { return 0.0; }
  std::int64_t k() const override { return k_; }

 private:
  const BenchmarkRig rig_;
  BenchmarkRigState state_{};
  std::int64_t k_ = 0;
};

}  // namespace

bool HasDamper(const models::PlantConfig& plant) { return plant.specimen == Specimen::kMrDamper; }

std::unique_ptr<Rig> MakeRig(const models::PlantConfig& plant, double dt_s) {
  const bool damper = HasDamper(plant);
  if (plant.RigMode()) {  // effects or unmodelled disturbances on: docs/rig_mode.md
    if (plant.kind != PlantKind::kLinear) {
      throw Error(plant.effects.Empty() ? "plant.unmodelled" : "plant.effects",
                  fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act around "
                              "the linear actuator model",
                              NameOf(kPlantKindNames, plant.kind)));
    }
    return MakeEffectRig(plant, dt_s);
  }
  switch (plant.kind) {
    case PlantKind::kLinear:  // the nominal linear rig, unchanged
      return std::make_unique<LinearRigAdapter>(LinearRig::Make(plant.actuator, dt_s, damper,
                                                                plant.damper,
                                                                plant.ode_rtol,
                                                                plant.current_dynamics,
                                                                plant.current_driver));
    case PlantKind::kPhysical:
      return std::make_unique<PhysicalRigAdapter>(
          PhysicalRig::Make(plant.physical, dt_s, damper ? RigLoad::kMrDamper : RigLoad::kNone,
                            plant.current_dynamics, plant.damper, {},
                            plant.ode_rtol, plant.current_driver));
    case PlantKind::kIdeal:
      if (!(plant.ode_rtol > 0.0 && plant.ode_rtol <= 1e-2))
        throw Error("plant.ode_rtol", fmt::format("must be in (0, 1e-2] (got {})", plant.ode_rtol));
      return std::make_unique<IdealRig>(plant.damper, damper, plant.current_dynamics, dt_s,
                                        plant.ode_rtol, plant.current_driver);
    case PlantKind::kBenchmark:  // the specimen is the benchmark's experimental substructure, inside Gp
      return std::make_unique<BenchmarkRigAdapter>(BenchmarkRig::Make(plant.benchmark, dt_s));
  }
  throw Error("plant.kind", "unknown loading system");
}

}  // namespace rths::models
