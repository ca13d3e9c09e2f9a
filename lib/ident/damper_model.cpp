#include "ident/damper_model.h"

#include <algorithm>
#include <cmath>

namespace rths::ident {

namespace {

/// At most this many refits of the damper model around the measurement's effects.
constexpr int kMeasurementRounds = 6;

/// The fit the options ask for, without measurement effects.
DamperModelFit FitBase(const std::vector<io::RigRecord>& records, const DamperFitOptions& o) {
  DamperModelFit fit;
  fit.velocity_cutoff_hz = o.velocity_cutoff_hz;
  if (o.current_A) fit.at_current = FitDamper(records, o);
  else fit.any_input = FitSpencer(records, o);
  return fit;
}

/// The measurement fitted around `fit`'s damper force on the records.
MeasurementFit MeasureAround(const DamperModelFit& fit, const std::vector<io::RigRecord>& records,
                             const MeasurementOptions& m) {
  std::vector<std::vector<double>> F;
  std::vector<double> cut;
  for (const auto& r : records) F.push_back(fit.DamperForce(r)), cut.push_back(fit.CutoffHz(r));
  return FitMeasurement(records, F, cut, m);
}

}  // namespace

DamperModelFit FitDamperModel(const std::vector<io::RigRecord>& records, const DamperFitOptions& o,
                              const MeasurementOptions& m) {
  DamperModelFit fit = FitBase(records, o);
  if (!m.Any()) return fit;
  // Around the model, then the model again on the damper's own force that implies, until the skew
  // moves by less than its standard error (at most kMeasurementRounds refits).
  fit.measurement = MeasureAround(fit, records, m);
  for (int round = 0; round < kMeasurementRounds; ++round) {
    std::vector<io::RigRecord> own;
    for (const auto& r : records) own.push_back(fit.measurement.DamperForceRecord(r, fit.CutoffHz(r)));
    const MeasurementFit before = fit.measurement;
    fit = FitBase(own, o);
    fit.measurement = MeasureAround(fit, records, m);
    if (std::abs(fit.measurement.skew_ms - before.skew_ms) <= std::max(fit.measurement.skew_se_ms, 1e-9) &&
        std::abs(fit.measurement.mass_kg - before.mass_kg) <= std::max(fit.measurement.mass_se_kg, 1e-9))
      break;
  }
  // The training scores on the measured force.
  auto& scores = fit.at_current ? fit.at_current->records : fit.any_input->records;
  for (std::size_t j = 0; j < records.size() && j < scores.size(); ++j) scores[j] = fit.Score(records[j]);
  return fit;
}

std::string DamperModelFit::Report() const {
  return (at_current ? at_current->Report() : any_input->Report()) + measurement.Report();
}

const FitStatus& DamperModelFit::status() const { return at_current ? at_current->status : any_input->status; }

double DamperModelFit::CutoffHz(const io::RigRecord& record) const {
  return velocity_cutoff_hz > 0.0 ? velocity_cutoff_hz : VelocityCutoffHz(record);
}

std::vector<double> DamperModelFit::DamperForce(const io::RigRecord& r) const {
  const double cutoff = CutoffHz(r);
  if (any_input)
    return PredictSpencerForce(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage, cutoff,
                               any_input->force_offset_kN);
  return PredictDamperForce(at_current->coef, r, cutoff, at_current->force_offset_kN);
}

std::vector<double> DamperModelFit::PredictForce(const io::RigRecord& r) const {
  auto F = DamperForce(r);
  return measurement.Any() ? measurement.Measured(F, r, CutoffHz(r)) : F;
}

DamperRecordScore DamperModelFit::Score(const io::RigRecord& r) const {
  if (measurement.Any()) return ScoreForce(r, PredictForce(r), CutoffHz(r));
  if (any_input)
    return ScoreSpencer(any_input->params, any_input->driver, any_input->filter, r, any_input->voltage,
                        velocity_cutoff_hz, any_input->force_offset_kN);
  return ScoreDamper(at_current->coef, r, velocity_cutoff_hz, at_current->force_offset_kN);
}

std::string DamperModelFit::ModelToml(const std::string& title) const {
  return (at_current ? DamperTomlFragment(*at_current, title) : SpencerModelToml(*any_input, title)) + measurement.Toml();
}

}  // namespace rths::ident
