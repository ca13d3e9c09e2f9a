#include "models/marths_plant.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models::marths {

namespace {

constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
using Cd = std::complex<double>;

/// k prod(s - z) / prod(s - p) for the element (row, col) of `p` at s.
Cd PlantElement(const PlantZpk& p, int row, int col, Cd s) {
  const Cd frame = (s - p.frame_pole) * (s - std::conj(p.frame_pole));
  if (col == 0) {
    const double k = row == 0 ? p.k11 : p.k21;
    return k * (s - p.h1z1) * (s - p.h1z2) / ((s - p.h1p1) * (s - p.h1p2) * frame);
  }
  const double k = row == 0 ? p.k12 : p.k22;
  const double z = row == 0 ? p.h12z1 : p.h22z1;
  return k * (s - z) / ((s - p.h2p1) * (s - p.h2p2) * frame);
}

/// One column's 4 states in the scaled controllable canonical basis (the file comment of the
/// header): writes A's block at (o, o), B at (o, col), and C's entries for numerators n[row][0..3].
void RealiseColumn(const std::array<double, 5>& c, const double n[2][4], int o, int col,
                   MarthsPlant* m) {
  const double w = std::pow(c[0], 0.25);
  for (int i = 0; i < 3; ++i) m->A(o + i, o + i + 1) = w;
  for (int i = 0; i < 4; ++i) m->A(o + 3, o + i) = -c[i] / std::pow(w, 3 - i);
  m->B(o + 3, col) = 1.0 / (w * w * w);
  for (int row = 0; row < 2; ++row) {
    for (int i = 0; i < 4; ++i) m->C(row, o + i) = n[row][i] * std::pow(w, i);
  }
}

double Draw(double value, double rel_std, signal::GaussianState* g) {
  return value + rel_std * value * signal::NextGaussian(g);
}

}  // namespace

std::array<double, 5> ColumnDenominator(const PlantZpk& p, int j) {
  const double a = j == 0 ? p.h1p1 : p.h2p1, b = j == 0 ? p.h1p2 : p.h2p2;
  const double f1 = -2.0 * p.frame_pole.real(), f0 = std::norm(p.frame_pole);  // s^2 + f1 s + f0
  const double r1 = -(a + b), r0 = a * b;                                       // s^2 + r1 s + r0
  return {r0 * f0, r0 * f1 + r1 * f0, r0 + r1 * f1 + f0, r1 + f1, 1.0};
}

PlantZpk NominalPlantZpk() {
  PlantZpk p;
  p.frame_pole = Cd(-50.0, 63.0) * kTwoPi;
  p.h1z1 = -120 * kTwoPi, p.h1z2 = -90 * kTwoPi;
  p.h1p1 = -2.65 * kTwoPi, p.h1p2 = -40 * kTwoPi;
  p.k11 = 2165.2, p.k21 = 349.95;
  p.h12z1 = -3 * kTwoPi, p.h22z1 = -5 * kTwoPi;
  p.h2p1 = -3.5 * kTwoPi, p.h2p2 = -18.5 * kTwoPi;
  p.k12 = 4.5394e6, p.k22 = 1.9238e7;
  return p;
}

Eigen::Matrix2d DcGain(const PlantZpk& p) {
  Eigen::Matrix2d g;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) g(r, c) = PlantElement(p, r, c, Cd(0.0, 0.0)).real();
  }
  return g;
}

Eigen::Matrix2cd Response(const PlantZpk& p, double w_rad_s) {
  Eigen::Matrix2cd h;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) h(r, c) = PlantElement(p, r, c, Cd(0.0, w_rad_s));
  }
  return h;
}

PlantZpk PerturbedPlantZpk(const PlantZpk& nominal, signal::GaussianState* g) {
  PlantZpk p = nominal;
  p.h1z1 = Draw(nominal.h1z1, 0.055, g);
  p.h1z2 = Draw(nominal.h1z2, 0.055, g);
  p.h1p1 = Draw(nominal.h1p1, 0.06, g);
  p.h1p2 = Draw(nominal.h1p2, 0.06, g);
  p.frame_pole = nominal.frame_pole * (1.0 + 0.05 * signal::NextGaussian(g));
  p.h12z1 = Draw(nominal.h12z1, 0.03, g);
  p.h2p1 = Draw(nominal.h2p1, 0.03, g);
  p.h2p2 = Draw(nominal.h2p2, 0.03, g);
  p.h22z1 = Draw(nominal.h22z1, 0.03, g);
  for (double pole : {p.h1p1, p.h1p2, p.h2p1, p.h2p2, p.frame_pole.real()}) {
    if (!(pole < 0.0)) {
      throw Error("maRTHS perturbed plant", fmt::format("a drawn pole ({} rad/s) is not stable", pole));
    }
  }
  const Eigen::Matrix2d nominal_dc = DcGain(nominal), drawn_dc = DcGain(p);
  p.k11 *= nominal_dc(0, 0) / drawn_dc(0, 0);
  p.k21 *= nominal_dc(1, 0) / drawn_dc(1, 0);
  p.k12 *= nominal_dc(0, 1) / drawn_dc(0, 1);
  p.k22 *= nominal_dc(1, 1) / drawn_dc(1, 1);
  return p;
}

MarthsPlant MakeMarthsPlant(const PlantZpk& p, double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("maRTHS plant", "dt_s must be > 0");
  MarthsPlant m;
  m.A.setZero();
  m.B.setZero();
  m.C.setZero();
  m.dt_s = dt_s;
  const double n1[2][4] = {{p.k11 * p.h1z1 * p.h1z2, -p.k11 * (p.h1z1 + p.h1z2), p.k11, 0.0},
                           {p.k21 * p.h1z1 * p.h1z2, -p.k21 * (p.h1z1 + p.h1z2), p.k21, 0.0}};
  const double n2[2][4] = {{-p.k12 * p.h12z1, p.k12, 0.0, 0.0}, {-p.k22 * p.h22z1, p.k22, 0.0, 0.0}};
  RealiseColumn(ColumnDenominator(p, 0), n1, 0, 0, &m);
  RealiseColumn(ColumnDenominator(p, 1), n2, 4, 1, &m);
  using Mat8 = Eigen::Matrix<double, 8, 8>;
  const Mat8 X = dt_s * m.A, I = Mat8::Identity();
  const Mat8 X2 = X * X, X3 = X2 * X, X4 = X3 * X;
  m.P = I + X + X2 / 2.0 + X3 / 6.0 + X4 / 24.0;
  m.G = dt_s * (I + X / 2.0 + X2 / 6.0 + X3 / 24.0) * m.B;
  return m;
}

Eigen::Vector2d PlantOutput(const MarthsPlant& m, const MarthsPlantState& s) { return m.C * s.x; }

void PlantStep(const MarthsPlant& m, MarthsPlantState* s, const Eigen::Vector2d& u_mm) {
  s->x = m.P * s->x + m.G * u_mm;
}

double SensorNoiseMm(double dt_s) { return std::sqrt(1.5e-7 / dt_s); }

}  // namespace rths::models::marths
