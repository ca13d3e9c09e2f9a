#pragma once
/// @file The maRTHS benchmark's closed loop in one process, as its reference code closes it
/// (Model_vmaRHTS_R2019b.slx of FermandoisLab/maRTHS-bmk-RoDeAC; docs/marths.md "The loop"), so
/// that each of the reference code's ambiguous choices can be switched alone and measured.
///
/// Sample k (t_k = k dt, dt = 1/1024 s by default), everything SI inside, strokes in mm:
///
///     y_k   = C x_k + n_k                                  measured strokes (plant state at t_k, noise)
///     (x^, th^)_k = coupler inverse of y_k                  interface motion estimated
///     F_k   = frame feedback force of (x^, th^)_k           backward differences of its motion
///     U_k   = Newmark step of the numerical substructure    under a_g(t_k) and F_k
///     x_t,k = coupler forward of (U_27, -U_21)_k            actuator targets [mm]
///     u_k   = compensator(x_t,k, y_k)                       per actuator
///     x_{k+1} = RK4 step of the plant with u_k held
///     U^r_k = Newmark step of the reference structure      under a_g(t_k)
///
/// a_g(t_k) is the record linearly interpolated at t_k (Simulink's From File) times the scale
/// (0.4 in the benchmark). The signals recorded at every sample are those of S5_Evaluation.m, and
/// the run is scored by signal::MarthsCriteriaFrom.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "control/controller_config.h"
#include "control/marths_compensator.h"
#include "control/marths_config.h"
#include "control/rodeac.h"
#include "models/marths_coupler.h"
#include "models/marths_plant.h"
#include "models/marths_rig.h"
#include "signal/marths_criteria.h"

namespace rths::studies {

/// The compensators the loop runs (control/marths_config.h).
using control::MarthsCompensator;

/// One run's inputs (read at the edge: no file is opened here).
struct MarthsLoopConfig {
  double dt_s = 1.0 / 1024.0;
  std::vector<double> ag_m_s2;          ///< the scaled ground acceleration at t_k, one per sample
  Eigen::MatrixXd K_ref, M_ref;         ///< the SAP2000 reference matrices (29 x 29, SI)
  models::marths::FrameDofs dofs;       ///< where the interface, stories and ground load are in them
  double ideal_density_kg_m3 = 785e3;   ///< the ideal physical substructure's density (as coded)
  models::marths::PlantZpk plant = models::marths::NominalPlantZpk();
  /// The rig's sensor noise (off by default here), its seed, and the reference code's ambiguous
  /// choices (models::marths::RigOptions; docs/marths.md "Decisions").
  models::marths::RigOptions rig{};
  /// The compensators (kind, RoDeAC's designs, each actuator's controller for ff and ff_lqg,
  /// and the plant they are designed on: the nominal one, also for perturbed runs).
  control::MarthsCompensatorSpec compensators{};
  /// The reference code's voltage conversion of each command (signal::MarthsVoltage).
  signal::MarthsVoltage volts{};
};

/// The run's outcome.
struct MarthsLoopResult {
  signal::MarthsCriteria j;
  signal::MarthsSignals signals;
  double max_volts[2] = {0.0, 0.0};  ///< largest |command| per actuator [V]
  /// Both actuators' largest |V| exceed signal::kMarthsVoltLimit: the reference code's saturation flag.
  bool saturated = false;
};

/// Runs `c` for c.ag_m_s2.size() samples and scores it. Throws rths::Error for inputs the models
/// refuse or if the loop diverges (a value that is not finite).
MarthsLoopResult RunMarthsLoop(const MarthsLoopConfig& c);

}  // namespace rths::studies
