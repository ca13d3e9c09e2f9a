// The MIMO feedforward (lib/control/mimo_feedforward.h): its continuous form is the exact inverse
// of the 2 x 2 plant; its discrete form tracks through the plant.
#include <cmath>
#include <complex>

#include <doctest/doctest.h>

#include "alloc_counter.h"
#include "control/mimo_feedforward.h"
#include "control/rodeac.h"

namespace mm = rths::models::marths;

TEST_CASE("Q(jw) + R(jw)/den(jw) is H(jw)^-1 for the nominal and a perturbed plant") {
  rths::signal::GaussianState g = rths::signal::MakeGaussian(3);
  for (const mm::PlantZpk& p : {mm::NominalPlantZpk(), mm::PerturbedPlantZpk(mm::NominalPlantZpk(), &g)}) {
    const double dt = 1.0 / 1024;
    const rths::control::MimoFeedforward f = rths::control::MakeMimoFeedforward(p, dt);
    // The discrete rests at low frequency approach the continuous ones; check the whole inverse
    // at frequencies well below Nyquist, where Tustin's warping is small.
    for (double hz : {0.2, 1.0, 5.0}) {
      const double w = 2 * 3.14159265358979323846 * hz;
      const std::complex<double> s(0.0, w);
      Eigen::Matrix2cd inv;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          std::complex<double> q = 0.0, sm = 1.0;
          for (int m = 0; m < 4; ++m, sm *= s) q += f.q[i][j][m] * sm;
          inv(i, j) = q + f.rest[i][j].Response(hz);
        }
      const Eigen::Matrix2cd prod = inv * mm::Response(p, w);
      CHECK((prod - Eigen::Matrix2cd::Identity()).norm() < 2e-3 * (1 + hz));
    }
  }
}

TEST_CASE("through the plant, the feedforward tracks a coupled 1 Hz motion within a few percent") {
  const double dt = 1.0 / 1024;
  const mm::PlantZpk p = mm::NominalPlantZpk();
  const mm::MarthsPlant plant = mm::MakeMarthsPlant(p, dt);
  const rths::control::MimoFeedforward f = rths::control::MakeMimoFeedforward(p, dt);
  rths::control::MimoFeedforwardState s;
  mm::MarthsPlantState ps;
  double err = 0.0, ref = 0.0, err_none = 0.0;
  mm::MarthsPlantState ps_none;
  const mm::MarthsPlant plant_none = plant;
  for (int k = 0; k < 8 * 1024; ++k) {
    const double t = k * dt;
    const double ramp = std::min(1.0, t / 2.0);
    const Eigen::Vector2d x(ramp * 2.0 * std::sin(2 * 3.14159265358979 * t), ramp * std::sin(2 * 3.14159265358979 * 1.3 * t));
    const Eigen::Vector2d y = mm::PlantOutput(plant, ps), y0 = mm::PlantOutput(plant_none, ps_none);
    if (t > 4.0) {
      err += (y - x).squaredNorm();
      err_none += (y0 - x).squaredNorm();
      ref += x.squaredNorm();
    }
    mm::PlantStep(plant, &ps, rths::control::MimoFeedforwardStep(f, &s, x(0), x(1)));
    mm::PlantStep(plant_none, &ps_none, x);
  }
  const double rel = std::sqrt(err / ref), rel_none = std::sqrt(err_none / ref);
  MESSAGE("relative tracking error: mimo_ff " << rel << ", none " << rel_none);
  CHECK(rel < 0.1 * rel_none);
  CHECK(rel < 0.03);
}

TEST_CASE("the MIMO feedforward's and RoDeAC's steps allocate nothing") {
  const double dt = 1.0 / 1024;
  const rths::control::MimoFeedforward f = rths::control::MakeMimoFeedforward(mm::NominalPlantZpk(), dt);
  rths::control::MimoFeedforwardState s;
  const auto d = rths::control::MakeRodeacDesign(Eigen::Vector4d(1.0, 0.1, 0.0, 0.0), 10.0 * Eigen::Matrix4d::Identity(), 1024.0);
  rths::control::RodeacState r = rths::control::RodeacAtRest(d);
  const long before = rths_test::AllocationCount();
  double sum = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double x = std::sin(0.01 * k);
    sum += rths::control::MimoFeedforwardStep(f, &s, x, -x).sum();
    sum += rths::control::RodeacStep(d, &r, x, 0.9 * x);
  }
  CHECK(rths_test::AllocationCount() == before);
  CHECK(std::isfinite(sum));
}
