#include "models/continuous_structure.h"

#include <Eigen/Dense>

#include "core/error.h"

namespace rths::models {

ContinuousStructure ContinuousStructure::Make(const LinearStructure& st) {
  ContinuousStructure c;
  c.n = st.dofs();
  const Eigen::MatrixXd minv = st.M.inverse();
  c.A = Eigen::MatrixXd::Zero(2 * c.n, 2 * c.n);
  c.A.topRightCorner(c.n, c.n) = Eigen::MatrixXd::Identity(c.n, c.n);
  c.A.bottomLeftCorner(c.n, c.n) = -minv * st.K;
  c.A.bottomRightCorner(c.n, c.n) = -minv * st.C;
  c.b_g = Eigen::VectorXd::Zero(2 * c.n);
  c.b_g.tail(c.n) = -st.iota;
  c.b_f = Eigen::VectorXd::Zero(2 * c.n);
  if (st.specimen_dir.size() == c.n) c.b_f.tail(c.n) = -minv * st.specimen_dir;
  return c;
}

Rk4Workspace Rk4Workspace::Make(const ContinuousStructure& c) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2 * c.n);
  return {zero, zero, zero, zero, zero};
}

namespace {

/// out = A z + b_g a + b_f f (F of the file comment), into preallocated `out`.
void Rate(const ContinuousStructure& c, const Eigen::VectorXd& z, double a, double f, Eigen::VectorXd* out) {
  out->noalias() = c.A * z;
  *out += c.b_g * a;  // (A z + b_g a) + b_f f, summed in this order
  *out += c.b_f * f;
}

}  // namespace

void Rk4Step(const ContinuousStructure& c, Rk4Workspace* w, Eigen::VectorXd* z, double dt, const double ag[3],
             double f) {
  Rate(c, *z, ag[0], f, &w->k1);
  w->z_stage = *z + 0.5 * dt * w->k1;
  Rate(c, w->z_stage, ag[1], f, &w->k2);
  w->z_stage = *z + 0.5 * dt * w->k2;
  Rate(c, w->z_stage, ag[1], f, &w->k3);
  w->z_stage = *z + dt * w->k3;
  Rate(c, w->z_stage, ag[2], f, &w->k4);
  *z += dt / 6.0 * (w->k1 + 2.0 * w->k2 + 2.0 * w->k3 + w->k4);
}

std::vector<std::vector<double>> GroundResponseRk4(const LinearStructure& structure, double dt_s,
                                                   std::span<const double> ground_half) {
  if (ground_half.size() < 3 || ground_half.size() % 2 == 0)
    throw Error("GroundResponseRk4", "needs a_g at the half steps: 2N + 1 values for N >= 1 samples");
  const std::size_t n = (ground_half.size() - 1) / 2;
  const ContinuousStructure c = ContinuousStructure::Make(structure);
  Rk4Workspace w = Rk4Workspace::Make(c);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * c.n);
  std::vector<std::vector<double>> x(static_cast<std::size_t>(c.n), std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    for (int i = 0; i < c.n; ++i) x[static_cast<std::size_t>(i)][k] = z(i);
    const double ag[3] = {ground_half[2 * k], ground_half[2 * k + 1], ground_half[2 * k + 2]};
    Rk4Step(c, &w, &z, dt_s, ag, 0.0);
  }
  return x;
}

}  // namespace rths::models
