#include "models/marths_rig.h"

#include "core/error.h"
#include "models/marths_structure.h"

namespace rths::models::marths {

MarthsRig MakeMarthsRig(const PlantZpk& p, double dt_s, const RigOptions& o) {
  if (o.force_delay_steps != 0 && o.force_delay_steps != 1) throw Error("maRTHS rig", "force_delay_steps must be 0 or 1");
  if (!(o.noise_mm >= 0.0)) throw Error("maRTHS rig", "noise_mm must be >= 0");
  if (const std::string why = CouplerProblem(o.geometry, o.inverse); !why.empty()) throw Error("maRTHS coupler", why);
  return {MakeMarthsPlant(p, dt_s), MakeFeedbackFrame(dt_s), o};
}

MarthsRigState MarthsRigAtRest(const MarthsRig& r) {
  MarthsRigState s;
  s.frame.started = r.options.derivatives_from_rest;  // q_{-1} = 0, q'_{-1} = 0: differences from rest
  s.noise = signal::MakeGaussian(r.options.noise_seed);
  return s;
}

RigReading RigRead(const MarthsRig& r, MarthsRigState* s) {
  RigReading out;
  out.y_mm = PlantOutput(r.plant, s->plant);
  const RigOptions& o = r.options;
  if (o.noise_mm > 0.0) {
    const double n1 = o.noise_mm * signal::NextGaussian(&s->noise);
    const double n2 = o.identical_noise ? n1 : o.noise_mm * signal::NextGaussian(&s->noise);
    out.y_mm += Eigen::Vector2d(n1, n2);
  }
  out.estimate = Inverse(o.geometry, {out.y_mm(0), out.y_mm(1)}, o.inverse);
  const InterfaceForces estimated = FeedbackForce(r.frame, &s->frame, out.estimate.x_m, out.estimate.theta_rad);
  out.forces = o.force_delay_steps == 1 ? s->held : estimated;
  s->held = estimated;
  return out;
}

void RigStep(const MarthsRig& r, MarthsRigState* s, const Eigen::Vector2d& u_mm) { PlantStep(r.plant, &s->plant, u_mm); }

SubstructureOutput SubstructureStep(const MarthsSubstructure& m, NewmarkLinearState* s, double ag_m_s2,
                                    const InterfaceForces& f) {
  s->F(Index(m.dofs.x())) = f.F27_N;
  s->F(Index(m.dofs.theta())) = f.M21_N_m;
  s->F(Index(m.dofs.theta2())) = f.M29_N_m;
  NewmarkLinearStep(m.numerical, s, ag_m_s2);
  SubstructureOutput out;
  out.interface = {s->U(Index(m.dofs.x())), -s->U(Index(m.dofs.theta()))};
  out.targets = Forward(m.geometry, out.interface);
  return out;
}

}  // namespace rths::models::marths
