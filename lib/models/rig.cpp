#include "models/rig.h"

#include <fmt/format.h>

#include "core/error.h"
#include "models/linear_rig.h"
#include "models/servo_physical.h"

namespace rths::models {
namespace {

// Rig over LinearRig (+ LinearRigStepper).
class LinearRigAdapter final : public Rig {
 public:
  explicit LinearRigAdapter(const LinearRig& rig) : rig_(rig), stepper_(rig_) {}
  void Step(double u_mm, double i_cmd_A) override {
    if (k_ == 0) state_.current = SteadyState(i_cmd_A);  // current set before the test
    stepper_.Step(&state_, u_mm, i_cmd_A);
    ++k_;
  }
  double y_mm() const override { return MeasuredDisplacementMm(rig_, state_); }
  double f_kN() const override { return MeasuredForceKn(rig_, state_); }
  double current_A() const override { return EffectiveCurrentA(rig_, state_); }
  std::int64_t k() const override { return k_; }

 private:
  const LinearRig rig_;
  LinearRigStepper stepper_;
  LinearRigState state_{};
  std::int64_t k_ = 0;
};

// Rig over PhysicalRig (+ PhysicalRigStepper).
class PhysicalRigAdapter final : public Rig {
 public:
  explicit PhysicalRigAdapter(const PhysicalRig& rig) : rig_(rig), stepper_(rig_) {}
  void Step(double u_mm, double i_cmd_A) override {
    if (k_ == 0) state_.current = SteadyState(i_cmd_A);  // current set before the test
    stepper_.Step(&state_, u_mm, i_cmd_A);
    ++k_;
  }
  double y_mm() const override { return MeasuredDisplacementMm(rig_, state_); }
  double f_kN() const override { return MeasuredForceKn(rig_, state_); }
  double current_A() const override { return EffectiveCurrentA(rig_, state_); }
  std::int64_t k() const override { return k_; }

 private:
  const PhysicalRig rig_;
  PhysicalRigStepper stepper_;
  PhysicalRigState state_{};
  std::int64_t k_ = 0;
};

}  // namespace

std::unique_ptr<Rig> MakeRig(const scenario::PlantConfig& plant, double dt_s) {
  bool damper = false;
  if (plant.specimen == "mr_damper") {
    damper = true;
  } else if (plant.specimen != "none") {
    throw Error("plant.specimen",
                fmt::format("\"{}\" is not one of \"mr_damper\", \"none\"", plant.specimen));
  }
  if (plant.kind == "linear") {
    return std::make_unique<LinearRigAdapter>(LinearRig::Make(plant.actuator, dt_s, damper,
                                                              MrDamperParams::Table3(),
                                                              plant.cvode_rtol,
                                                              plant.current_dynamics));
  }
  if (plant.kind == "physical") {
    return std::make_unique<PhysicalRigAdapter>(
        PhysicalRig::Make(plant.physical, dt_s, damper ? RigLoad::kMrDamper : RigLoad::kNone,
                          plant.current_dynamics, MrDamperParams::Table3(), {},
                          plant.cvode_rtol));
  }
  throw Error("plant.kind",
              fmt::format("\"{}\" is not one of \"linear\", \"physical\"", plant.kind));
}

}  // namespace rths::models
