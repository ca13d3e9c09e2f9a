// The maRTHS benchmark's models (lib/models/marths_*.h, newmark_linear.h): each checked against
// an independent computation of what the reference code's script or block defines.
#include <cmath>
#include <complex>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <doctest/doctest.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "alloc_counter.h"
#include "models/marths_coupler.h"
#include "models/marths_frame.h"
#include "models/marths_plant.h"
#include "models/marths_rig.h"
#include "models/marths_structure.h"
#include "models/newmark_linear.h"

namespace mm = rths::models::marths;

namespace {

const std::string kData = std::string(RTHS_SOURCE_DIR) + "/data/marths/";

Eigen::MatrixXd ReadCsv(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    rows.emplace_back();
    while (std::getline(ss, cell, ',')) rows.back().push_back(std::stod(cell));
  }
  Eigen::MatrixXd m(rows.size(), rows[0].size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < rows[i].size(); ++j) m(i, j) = rows[i][j];
  return m;
}

}  // namespace

TEST_CASE("the reference and numerical structures: Rayleigh at 13.493 and 165.125 rad/s, the ideal frame subtracted at DOFs 27, 29, 21") {
  const Eigen::MatrixXd K = ReadCsv(kData + "reference_K_N_per_m.csv");
  const Eigen::MatrixXd M = ReadCsv(kData + "reference_M_kg.csv");
  const mm::Structures s = mm::BuildStructures(K, M);
  // Rayleigh: zeta(w) = a_M / (2 w) + a_K w / 2 is 5 % at both frequencies. Recover a_M, a_K from
  // C = a_M M + a_K K at an entry where M is zero and one where it is not.
  const int i27 = mm::Index(mm::kDofX);
  const double aK = s.reference.C(i27, mm::Index(mm::kDofTheta)) / K(i27, mm::Index(mm::kDofTheta));
  const double aM = (s.reference.C(i27, i27) - aK * K(i27, i27)) / M(i27, i27);
  for (double w : {13.493, 165.125}) CHECK(aM / (2 * w) + aK * w / 2 == doctest::Approx(0.05).epsilon(1e-10));
  // Only the nine entries of the physical DOFs change in K and C, and only M(27, 27) in M.
  int changed_K = 0, changed_M = 0;
  for (int i = 0; i < mm::kDofs; ++i)
    for (int j = 0; j < mm::kDofs; ++j) {
      changed_K += s.numerical.K(i, j) != K(i, j);
      changed_M += s.numerical.M(i, j) != M(i, j);
    }
  CHECK(changed_K == 9);
  CHECK(changed_M == 1);
  // The ideal frame: column stiffness 6 E I_c / L_c^3, its mass (m_b + m_c) at 785e3 kg/m^3.
  const double in = 0.0254, E = 200e9, Ic = 2.520 * std::pow(in, 4), Lc = 0.635;
  CHECK(s.physical.K(0, 0) == doctest::Approx(6 * E * Ic / (Lc * Lc * Lc)).epsilon(1e-12));
  CHECK(s.physical.M(0, 0) == doctest::Approx(785e3 * (0.947 * in * in * 0.762 + 1.670 * in * in * 0.635)).epsilon(1e-12));
  CHECK(s.numerical.M(i27, i27) == doctest::Approx(M(i27, i27) - s.physical.M(0, 0)).epsilon(1e-12));
  // The ground loads the floors' translations 13, 26, 27.
  CHECK(s.reference.l.sum() == 3.0);
  CHECK(s.reference.l(mm::Index(13)) == 1.0);
  CHECK(s.reference.l(mm::Index(26)) == 1.0);
  // A wrong size is refused, naming the matrix.
  CHECK_THROWS_WITH(mm::BuildStructures(K.topLeftCorner(28, 28), M), doctest::Contains("K (reference_K_N_per_m.csv)"));
  // The DOFs: the benchmark's by default; out of the model or named twice is refused.
  CHECK(mm::FrameDofsProblem(mm::FrameDofs{}, 29).empty());
  CHECK(s.dofs == mm::FrameDofs{});
  mm::FrameDofs twice;
  twice.stories[3] = 21;
  CHECK(mm::FrameDofsProblem(twice, 29).find("named twice") != std::string::npos);
  mm::FrameDofs outside;
  outside.ground[0] = 30;
  CHECK(mm::FrameDofsProblem(outside, 29).find("outside the model's 1..29") != std::string::npos);
  CHECK_THROWS_WITH(mm::BuildStructures(K, M, 785e3, outside), doctest::Contains("ground DOF 30"));
}

TEST_CASE("Newmark average acceleration is the trapezoidal rule on (x, x') with the loads at both ends of the step") {
  // m x'' + c x' + k x = -m a_g - F. The trapezoidal rule, written independently on z = (x, v):
  // z_{k+1} = (I - h/2 A)^-1 ((I + h/2 A) z_k + h/2 (b_k + b_{k+1})), b = (0, (-a_g - F/m)).
  const double m = 2.0, c = 3.0, k = 800.0, dt = 0.01;
  Eigen::MatrixXd M(1, 1), C(1, 1), K(1, 1);
  M << m;
  C << c;
  K << k;
  const rths::models::NewmarkLinear nm = rths::models::MakeNewmarkLinear(M, C, K, Eigen::VectorXd::Ones(1), dt);
  rths::models::NewmarkLinearState s = rths::models::NewmarkLinearAtRest(nm);
  Eigen::Matrix2d A;
  A << 0, 1, -k / m, -c / m;
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d L = (I - dt / 2 * A).inverse(), R = I + dt / 2 * A;
  Eigen::Vector2d z = Eigen::Vector2d::Zero(), b_prev = Eigen::Vector2d::Zero();
  double worst = 0.0, peak = 0.0;
  for (int i = 1; i <= 1500; ++i) {
    const double ag = 0.3 * std::sin(0.7 * i) + (i > 50 ? 0.2 : 0.0), F = 5.0 * std::cos(0.3 * i);
    s.F(0) = F;
    rths::models::NewmarkLinearStep(nm, &s, ag);
    const Eigen::Vector2d b(0.0, -ag - F / m);
    z = L * (R * z + dt / 2 * (b_prev + b));
    b_prev = b;
    worst = std::max(worst, std::abs(s.U(0) - z(0)) + std::abs(s.V(0) - z(1)) * dt);
    peak = std::max(peak, std::abs(z(0)));
  }
  CHECK(peak > 1e-3);
  CHECK(worst < 1e-12 * peak);
}

TEST_CASE("coupler: the forward map and the exact inverse round trip; the as-wired inverse differs by the r^3 term") {
  const mm::CouplerGeometry g;
  CHECK(g.d1_m() == doctest::Approx(0.295394).epsilon(2e-6));
  for (double x : {-0.02, 0.0, 0.0037}) {
    for (double th : {-0.05, -1e-3, 0.0, 2e-4, 0.08}) {
      const mm::ActuatorPair a = mm::Forward(g, {x, th});
      const mm::InterfaceMotion e = mm::Inverse(g, a, mm::InverseForm::kExact);
      CHECK(std::abs(e.x_m - x) < 1e-15);
      CHECK(std::abs(e.theta_rad - th) < 1e-14);
      const mm::InterfaceMotion w = mm::Inverse(g, a, mm::InverseForm::kAsWired);
      CHECK(w.theta_rad == e.theta_rad);
      // x_wired - x = -d (cos(alpha_1 + r) - cos(alpha_1 + theta)), r = sin(theta): of order
      // d sin(alpha_1) theta^3 / 6.
      const double r = std::sin(th);
      const double expect = -g.d1_m() * (std::cos(g.alpha1_rad() + r) - std::cos(g.alpha1_rad() + th));
      CHECK(std::abs((w.x_m - x) - expect) < 1e-15);
      CHECK(std::abs(w.x_m - x) <= g.d1_m() * std::abs(th * th * th) / 6 * 1.01 + 1e-18);
    }
  }
  // A rotation alone moves the two actuators in opposite directions by equal amounts (first order).
  const mm::ActuatorPair a = mm::Forward(g, {0.0, 1e-4});
  CHECK(a.a1_mm == doctest::Approx(-a.a2_mm).epsilon(1e-4));
  CHECK(a.a1_mm == doctest::Approx(1000 * g.d1_m() * std::sin(-g.alpha1_rad()) * 1e-4).epsilon(1e-3));
}

TEST_CASE("coupler: any two-arm geometry round-trips exactly; the benchmark's arms keep their formula bit for bit") {
  std::mt19937_64 gen(4711);
  std::uniform_real_distribution<double> xv(0.05, 0.6), yv(-0.4, 0.4), x(-0.05, 0.05), th(-0.2, 0.2);
  int geometries = 0, motions = 0;
  double worst_x = 0.0, worst_th = 0.0;
  while (geometries < 200) {
    mm::CouplerGeometry g;
    for (int i = 0; i < 2; ++i) {
      g.xv_m[i] = xv(gen) * (i == 1 && geometries % 3 == 0 ? -1.0 : 1.0);  // some arms on the far side
      g.yv_m[i] = yv(gen);
      g.alpha_deg[i] = std::atan2(g.yv_m[i], g.xv_m[i]) * 180.0 / 3.14159265358979323846;
    }
    if (!mm::CouplerProblem(g, mm::InverseForm::kExact).empty()) continue;
    ++geometries;
    const auto [P, Q] = mm::StrokeDifferenceOf(g);
    for (int j = 0; j < 20; ++j) {
      const mm::InterfaceMotion m{x(gen), th(gen)};
      // Near the fold (theta + phi = +-pi/2) the stroke difference is stationary in theta: no
      // inverse is well conditioned there; the working range keeps away from it.
      if (std::abs(std::cos(m.theta_rad + std::atan2(P, -Q))) < 0.2) continue;
      const mm::InterfaceMotion e = mm::Inverse(g, mm::Forward(g, m), mm::InverseForm::kExact);
      worst_x = std::max(worst_x, std::abs(e.x_m - m.x_m));
      worst_th = std::max(worst_th, std::abs(e.theta_rad - m.theta_rad));
      const mm::ActuatorPair a = mm::Forward(g, m), b = mm::Forward(g, e);
      CHECK(std::abs(a.a1_mm - b.a1_mm) < 1e-9);
      CHECK(std::abs(a.a2_mm - b.a2_mm) < 1e-9);
      ++motions;
    }
  }
  CHECK(motions > 2000);
  CHECK(worst_x < 1e-12);
  CHECK(worst_th < 1e-12);
  MESSAGE("round trip over ", geometries, " geometries, ", motions, " motions: |dx| <= ", worst_x,
          " m, |dtheta| <= ", worst_th, " rad");

  // The benchmark's arms: the general inverse performs the benchmark formula's operations.
  const mm::CouplerGeometry bmk;
  for (double a1 : {-3.1, -0.2, 0.0, 0.05, 2.7}) {
    for (double a2 : {-2.9, 0.0, 0.01, 3.3}) {
      const double x1 = a1 / 1000.0, x2 = a2 / 1000.0;
      const double theta = std::asin((x1 - x2) / (2.0 * bmk.d2_m() * std::sin(bmk.alpha2_rad())));
      const mm::InterfaceMotion e = mm::Inverse(bmk, {a1, a2}, mm::InverseForm::kExact);
      CHECK(e.theta_rad == theta);
      CHECK(e.x_m == x1 - bmk.d1_m() * (std::cos(bmk.alpha1_rad() + theta) - std::cos(bmk.alpha1_rad())));
    }
  }
}

TEST_CASE("coupler: CouplerProblem names what is wrong with a geometry") {
  mm::CouplerGeometry g;
  CHECK(mm::CouplerProblem(g, mm::InverseForm::kAsWired).empty());
  CHECK(mm::CouplerProblem(g, mm::InverseForm::kExact).empty());
  mm::CouplerGeometry lopsided = g;  // a longer second arm: exact only
  lopsided.xv_m[1] = 0.4;
  lopsided.alpha_deg[1] = std::atan2(lopsided.yv_m[1], lopsided.xv_m[1]) * 180.0 / 3.14159265358979323846;
  CHECK(mm::CouplerProblem(lopsided, mm::InverseForm::kExact).empty());
  CHECK(mm::CouplerProblem(lopsided, mm::InverseForm::kAsWired).find("symmetric") != std::string::npos);
  mm::CouplerGeometry level = g;  // both arm ends at one height: the rotation is not seen
  level.yv_m[1] = -0.127;
  level.alpha_deg[1] = -25.4633;
  level.xv_m[1] = 0.3;
  level.alpha_deg[1] = std::atan2(level.yv_m[1], level.xv_m[1]) * 180.0 / 3.14159265358979323846;
  CHECK(mm::CouplerProblem(level, mm::InverseForm::kExact).find("rotation") != std::string::npos);
  mm::CouplerGeometry wrong_angle = g;
  wrong_angle.alpha_deg[0] = -30.0;
  CHECK(mm::CouplerProblem(wrong_angle, mm::InverseForm::kExact).find("atan2") != std::string::npos);
  mm::CouplerGeometry short_arm = g;
  short_arm.xv_m[0] = 1e-4;
  short_arm.yv_m[0] = 0.0;
  short_arm.alpha_deg[0] = 0.0;
  CHECK(mm::CouplerProblem(short_arm, mm::InverseForm::kExact).find("at least") != std::string::npos);
}

TEST_CASE("feedback frame: a held motion gives the statically condensed stiffness; its first mode is the script's") {
  const double dt = 1.0 / 1024;
  const mm::FeedbackFrame f = mm::MakeFeedbackFrame(dt);
  // Condensation by hand: K_red = K_tt - K_to K_oo^-1 K_ot.
  const Eigen::Matrix2d Kred = f.K.topLeftCorner<2, 2>() -
                               f.K.block<2, 3>(0, 2) * f.K.block<3, 3>(2, 2).inverse() * f.K.block<3, 2>(2, 0);
  mm::FeedbackFrameState s;
  const double x = 1e-3, th = -2e-3;
  mm::InterfaceForces out{};
  for (int i = 0; i < 3; ++i) out = mm::FeedbackForce(f, &s, x, th);  // the derivatives are 0 from the third sample
  const Eigen::Vector2d expect = Kred * Eigen::Vector2d(x, th);
  CHECK(out.F27_N == doctest::Approx(expect(0)).epsilon(1e-10));
  CHECK(out.M21_N_m == doctest::Approx(-expect(1)).epsilon(1e-10));
  // M29 = -(K q)_3, and the condensed rotations make (K q)_3..5 zero when the motion is held.
  CHECK(std::abs(out.M29_N_m) < 1e-9 * std::abs(expect(0)));
  // The damping is 5 % in every mode, at the rounded frequencies.
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eig(f.K, f.M);
  for (int i = 0; i < 5; ++i) {
    const auto phi = eig.eigenvectors().col(i);
    const double w = std::round(100 * std::sqrt(eig.eigenvalues()(i))) / 100;
    CHECK(phi.dot(f.C * phi) / phi.dot(f.M * phi) == doctest::Approx(2 * 0.05 * w).epsilon(1e-8));
  }
  // The first sample's derivatives are 0: the force is K q alone.
  mm::FeedbackFrameState fresh;
  const mm::InterfaceForces first = mm::FeedbackForce(f, &fresh, x, th);
  CHECK(first.F27_N == doctest::Approx(expect(0)).epsilon(1e-10));
}

TEST_CASE("control plant: DC gains 0.864 / 0.131 / 0.140 / 0.926, the realisation's response equals the zpk, RK4 as ode4") {
  const mm::PlantZpk p = mm::NominalPlantZpk();
  const Eigen::Matrix2d dc = mm::DcGain(p);
  CHECK(dc(0, 0) == doctest::Approx(0.8638).epsilon(2e-4));
  CHECK(dc(0, 1) == doctest::Approx(0.1311).epsilon(5e-4));
  CHECK(dc(1, 0) == doctest::Approx(0.1396).epsilon(5e-4));
  CHECK(dc(1, 1) == doctest::Approx(0.9258).epsilon(2e-4));
  const double dt = 1.0 / 1024;
  const mm::MarthsPlant m = mm::MakeMarthsPlant(p, dt);
  for (double f_hz : {0.0, 0.5, 3.0, 20.0, 80.0}) {
    const double w = 2 * 3.14159265358979323846 * f_hz;
    const Eigen::Matrix<std::complex<double>, 8, 8> jw =
        std::complex<double>(0, w) * Eigen::Matrix<std::complex<double>, 8, 8>::Identity() - m.A.cast<std::complex<double>>();
    const Eigen::Matrix2cd ss = m.C.cast<std::complex<double>>() * jw.inverse() * m.B.cast<std::complex<double>>();
    const Eigen::Matrix2cd zpk = mm::Response(p, w);
    CHECK((ss - zpk).norm() < 1e-9 * zpk.norm());
  }
  // P and G are one classic Runge-Kutta step with the input held (as Simulink's ode4 takes it),
  // stepped here stage by stage from each unit state and each unit input.
  using V8 = Eigen::Matrix<double, 8, 1>;
  auto rk4 = [&](const V8& x0, const Eigen::Vector2d& u) {
    auto f = [&](const V8& x) -> V8 { return m.A * x + m.B * u; };
    const V8 k1 = f(x0), k2 = f(x0 + dt / 2 * k1), k3 = f(x0 + dt / 2 * k2), k4 = f(x0 + dt * k3);
    return V8(x0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4));
  };
  for (int i = 0; i < 8; ++i) {
    CHECK((rk4(V8::Unit(i), Eigen::Vector2d::Zero()) - m.P.col(i)).norm() < 1e-13 * m.P.norm());
  }
  for (int i = 0; i < 2; ++i) {
    CHECK((rk4(V8::Zero(), Eigen::Vector2d::Unit(i)) - m.G.col(i)).norm() < 1e-13 * m.G.norm());
  }
  // ... and within RK4's error of the exact transition e^{A dt} (h |lambda| = 0.49 at the frame poles).
  const Eigen::Matrix<double, 8, 8> expA = (m.A * dt).exp();
  CHECK((m.P - expA).norm() < 1e-2 * expA.norm());
  // A held unit command settles to the DC gain.
  mm::MarthsPlantState s;
  for (int i = 0; i < 4 * 1024; ++i) mm::PlantStep(m, &s, Eigen::Vector2d(1.0, 0.0));
  CHECK(mm::PlantOutput(m, s)(0) == doctest::Approx(dc(0, 0)).epsilon(1e-6));
  CHECK(mm::PlantOutput(m, s)(1) == doctest::Approx(dc(1, 0)).epsilon(1e-6));
  CHECK(mm::SensorNoiseMm(dt) == doctest::Approx(0.012394).epsilon(1e-4));
}

TEST_CASE("perturbed plants keep the DC gains, move the poles by their stated spreads, and repeat for a seed") {
  const mm::PlantZpk nominal = mm::NominalPlantZpk();
  rths::signal::GaussianState g1 = rths::signal::MakeGaussian(7), g2 = rths::signal::MakeGaussian(7);
  double sum_sq = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const mm::PlantZpk a = mm::PerturbedPlantZpk(nominal, &g1), b = mm::PerturbedPlantZpk(nominal, &g2);
    CHECK(a.h1p1 == b.h1p1);
    CHECK(a.frame_pole == b.frame_pole);
    CHECK((mm::DcGain(a) - mm::DcGain(nominal)).cwiseAbs().maxCoeff() < 1e-12);
    sum_sq += std::pow(a.h1p2 / nominal.h1p2 - 1.0, 2);
    CHECK(std::arg(a.frame_pole) == doctest::Approx(std::arg(nominal.frame_pole)).epsilon(1e-12));
  }
  CHECK(std::sqrt(sum_sq / n) == doctest::Approx(0.06).epsilon(0.15));
}

TEST_CASE("the rig's and the substructure's steps allocate nothing") {
  const Eigen::MatrixXd K = ReadCsv(kData + "reference_K_N_per_m.csv");
  const Eigen::MatrixXd M = ReadCsv(kData + "reference_M_kg.csv");
  const double dt = 1.0 / 1024;
  const mm::Structures st = mm::BuildStructures(K, M);
  const mm::MarthsSubstructure sub{rths::models::MakeNewmarkLinear(st.numerical.M, st.numerical.C, st.numerical.K,
                                                                   st.numerical.l, dt),
                                   mm::CouplerGeometry{}, st.dofs};
  mm::RigOptions o;
  o.noise_mm = 0.0124;
  const mm::MarthsRig rig = mm::MakeMarthsRig(mm::NominalPlantZpk(), dt, o);
  rths::models::NewmarkLinearState ns = rths::models::NewmarkLinearAtRest(sub.numerical);
  mm::MarthsRigState rs = mm::MarthsRigAtRest(rig);
  const long before = rths_test::AllocationCount();
  double peak = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const mm::RigReading r = mm::RigRead(rig, &rs);
    const mm::SubstructureOutput out = mm::SubstructureStep(sub, &ns, 0.5 * std::sin(0.01 * k), r.forces);
    mm::RigStep(rig, &rs, Eigen::Vector2d(out.targets.a1_mm, out.targets.a2_mm));
    peak = std::max(peak, std::abs(out.targets.a1_mm));
  }
  CHECK(rths_test::AllocationCount() == before);
  CHECK(peak > 0.0);
}
