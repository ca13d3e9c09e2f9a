#include "ident/damper_model.h"

namespace rths::ident {

DamperModelFit FitDamperModel(const std::vector<io::RigRecord>& records, const DamperFitOptions& o) {
  DamperModelFit fit;
  fit.velocity_cutoff_hz = o.velocity_cutoff_hz;
  if (o.current_A) fit.at_current = FitDamper(records, o);
  else fit.any_input = FitSpencer(records, o);
  return fit;
}

std::string DamperModelFit::Report() const { return at_current ? at_current->Report() : any_input->Report(); }

const FitStatus& DamperModelFit::status() const { return at_current ? at_current->status : any_input->status; }

double DamperModelFit::CutoffHz(const io::RigRecord& record) const {
  return velocity_cutoff_hz > 0.0 ? velocity_cutoff_hz : VelocityCutoffHz(record);
}

std::vector<double> DamperModelFit::PredictForce(const io::RigRecord& r) const {
  const double cutoff = CutoffHz(r);
  if (any_input)
    return PredictSpencerForce(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage, cutoff,
                               any_input->force_offset_kN);
  return PredictDamperForce(at_current->coef, r, cutoff, at_current->force_offset_kN);
}

DamperRecordScore DamperModelFit::Score(const io::RigRecord& r) const {
  if (any_input)
    return ScoreSpencer(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage,
                        velocity_cutoff_hz, any_input->force_offset_kN);
  return ScoreDamper(at_current->coef, r, velocity_cutoff_hz, at_current->force_offset_kN);
}

std::string DamperModelFit::ModelToml(const std::string& title) const {
  return at_current ? DamperTomlFragment(*at_current, title) : SpencerModelToml(*any_input, title);
}

}  // namespace rths::ident
