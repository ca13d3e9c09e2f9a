#pragma once
/// @file SupplyRipple's library shape at continuous time (models/rig_effects.h): the displacement
/// the displacement path adds at a sample, and the rate the rig mode's damper moves with between
/// samples (the ripple is a continuous motion: a linear interpolation of it between samples would
/// give the damper its mean rate over the step, half a sample late and, at a harmonic of a few
/// samples per period, of the wrong size).
#include "models/rig_effects.h"

namespace rths::models {

/// A ripple's displacement [mm] and rate [mm/s].
struct RippleMotion {
  double mm = 0.0;
  double mm_s = 0.0;
};

/// amplitude sum_h w_h sin(2 pi h f t + phi_h) and its time derivative at t_s [s], over the
/// harmonics below the Nyquist frequency of dt_s (RippleHarmonicSampled).
RippleMotion SupplyRippleAt(const SupplyRipple& r, double dt_s, double t_s);

}  // namespace rths::models
