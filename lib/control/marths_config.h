#pragma once
/// @file The maRTHS benchmark through the lockstep: a scenario's [marths] table (docs/marths.md,
/// "Through the lockstep"), read at the edge into this plain struct; the participants take it.
///
/// With marths.enabled the run is the reference code's loop with two actuators: the integrator
/// steps the numerical substructure (Newmark, the reference minus the ideal bay), the plant is the
/// 2 x 2 control plant with the feedback frame, and the controller runs marths.compensator on both
/// actuators. [structure], [plant] (but plant.noise_y_mm_rms, the strokes' sensor noise) and
/// controller.kind are not used; ff and ff_lqg take the rest of [controller] (weights, filters).
#include <array>
#include <cstdint>
#include <string>

#include "core/names.h"
#include "models/marths_coupler.h"
#include "models/marths_files.h"
#include "models/marths_structure.h"
#include "models/servo_linear.h"
#include "signal/history.h"

namespace rths::control {

/// The compensators of the benchmark (docs/marths.md "Compensators").
enum class MarthsCompensator {
  kNone,    ///< u = x_t
  kRodeac,  ///< control::RodeacStep per actuator
  kFf,      ///< the paper's feedforward per actuator, designed on H_ii
  kFfLqg,   ///< the paper's FF + LQG per actuator, designed on H_ii
  kMimoFf,  ///< control::MimoFeedforward: the inverse of the 2 x 2 plant
};
inline constexpr std::array<Named<MarthsCompensator>, 5> kMarthsCompensatorNames = {
    {{MarthsCompensator::kNone, "none"},
     {MarthsCompensator::kRodeac, "rodeac"},
     {MarthsCompensator::kFf, "ff"},
     {MarthsCompensator::kFfLqg, "ff_lqg"},
     {MarthsCompensator::kMimoFf, "mimo_ff"}}};

inline constexpr std::array<Named<models::marths::InverseForm>, 2> kMarthsInverseNames = {
    {{models::marths::InverseForm::kAsWired, "as_wired"}, {models::marths::InverseForm::kExact, "exact"}}};

/// [marths]. Paths relative to the scenario file, or found under the source tree's data/marths/.
struct MarthsConfig {
  bool enabled = false;
  std::string reference_k_file = "data/marths/reference_K_N_per_m.csv";  ///< n x n [N/m] (29 x 29: the benchmark)
  std::string reference_m_file = "data/marths/reference_M_kg.csv";       ///< n x n [kg]
  std::string rodeac_file = "data/marths/rodeac_initial_parameters.txt";
  /// The ground motion: two columns t [s], a_g [m/s^2]; linearly interpolated at t_k, times
  /// ground_scale (0.4 in the benchmark).
  std::string ground_file = "data/marths/elcentro_m_s2.txt";
  double ground_scale = 0.4;
  double ideal_density_kg_m3 = 785e3;  ///< the ideal physical bay's density, as coded
  /// Where the interface, the stories and the ground load are among the reference matrices' DOFs
  /// (the benchmark's numbering by default; a lab's own model of the frame declares its own).
  models::marths::FrameDofs dofs;
  MarthsCompensator compensator = MarthsCompensator::kNone;
  /// 0: the nominal plant; i >= 1: the i-th plant drawn by the uncertainty model from plant_seed
  /// (models::marths::PerturbedPlantZpk), as `rths reproduce marths` draws its perturbed_i.
  int perturbed_plant = 0;
  std::int64_t plant_seed = 47;
  std::int64_t noise_seed = 123;  ///< the sensor noise's (the reference code's 123)
  bool identical_noise = true;    ///< the same noise sample on both strokes (docs/marths.md, Decisions)
  /// The coupler's arms (fcn_coupler_geometry.m's by default; a lab's own two-actuator coupler:
  /// models::marths::CouplerGeometry, checked by CouplerProblem).
  models::marths::CouplerGeometry coupler;
  models::marths::InverseForm inverse = models::marths::InverseForm::kAsWired;
  int force_delay_steps = 0;      ///< the forces of t_k (0) or of t_{k-1} (1)
  bool derivatives_from_rest = false;
  /// ff, ff_lqg: each actuator's design model. "avg" (the default) is replaced, when the run is
  /// prepared (ident::ResolveDesignModel), by the third-order fit of H_11 / H_22 of the nominal plant.
  models::ServoModel3 model_1, model_2;

  /// Read at the edge (scenario::ReadReferencedFiles): the matrices, RoDeAC's initial
  /// parameters, the ground record.
  models::marths::MarthsFiles files;
  signal::HistoryRecord ground;

  bool operator==(const MarthsConfig&) const = default;
};

}  // namespace rths::control
