#include "models/benchmark_plant.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/error.h"
#include "models/phase_lag.h"
#include "signal/random.h"

namespace rths::models {
namespace {

/// Coefficients in ascending powers of s.
using Poly = Eigen::VectorXd;

Poly Multiply(const Poly& a, const Poly& b) {
  Poly c = Poly::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i)
    for (Eigen::Index j = 0; j < b.size(); ++j) c(i + j) += a(i) * b(j);
  return c;
}

Poly Add(const Poly& a, const Poly& b) {
  Poly c = Poly::Zero(std::max(a.size(), b.size()));
  c.head(a.size()) += a;
  c.head(b.size()) += b;
  return c;
}

Poly Coefficients(std::initializer_list<double> ascending) {
  Poly p(static_cast<Eigen::Index>(ascending.size()));
  Eigen::Index i = 0;
  for (double v : ascending) p(i++) = v;
  return p;
}

std::vector<std::complex<double>> SortedByMagnitude(const Eigen::VectorXcd& v) {
  std::vector<std::complex<double>> out(v.data(), v.data() + v.size());
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    if (std::abs(a) != std::abs(b)) return std::abs(a) < std::abs(b);
    return a.imag() < b.imag();
  });
  return out;
}

/// Companion matrix of a monic polynomial (phase variables): ones above the diagonal, last row
/// -d0 .. -d4.
BenchmarkPlant::Matrix Companion(const Poly& den) {
  BenchmarkPlant::Matrix a = BenchmarkPlant::Matrix::Zero();
  for (int i = 0; i + 1 < kBenchmarkPlantOrder; ++i) a(i, i + 1) = 1.0;
  for (int j = 0; j < kBenchmarkPlantOrder; ++j) a(kBenchmarkPlantOrder - 1, j) = -den(j);
  return a;
}

std::vector<std::complex<double>> CompanionRoots(const Poly& den) {
  // Eigenvalues of the companion matrix in the basis scaled by w^-i, divided by w (entries of
  // order 1: the roots of the polynomial in s / w), then scaled back by w.
  const double w = std::pow(std::abs(den(0)), 1.0 / kBenchmarkPlantOrder);
  BenchmarkPlant::Matrix a = Companion(den);
  for (int i = 0; i < kBenchmarkPlantOrder; ++i)
    for (int j = 0; j < kBenchmarkPlantOrder; ++j) a(i, j) *= std::pow(w, j - i - 1);
  const Eigen::EigenSolver<BenchmarkPlant::Matrix> es(a, false);
  return SortedByMagnitude(es.eigenvalues() * w);
}

}  // namespace

double BenchmarkPlantParams::c_e_N_s_per_m() const { return 2.0 * zeta_e * std::sqrt(m_e_kg * k_e_N_per_m); }

BenchmarkPolynomials BenchmarkPlantPolynomials(const BenchmarkPlantParams& p) {
  const Poly gs_den = Coefficients({p.b2, p.b1, 1.0});                            // s^2 + b1 s + b2
  const Poly ga_den = Coefficients({p.a3, 1.0});                                  // s + a3
  const Poly gest_den = Coefficients({p.k_e_N_per_m, p.c_e_N_s_per_m(), p.m_e_kg});  // m s^2 + c s + k
  // G0 = 1 / (Ga_den Gest_den + a2 s).
  const Poly g0_den = Add(Multiply(ga_den, gest_den), Coefficients({0.0, p.a2}));
  // Gs G0 / (1 + Gs G0) = a1b0 / (Gs_den G0_den + a1b0).
  const Poly den = Add(Multiply(gs_den, g0_den), Coefficients({p.a1b0}));
  const double lead = den(den.size() - 1);  // m_e
  BenchmarkPolynomials out;
  out.num = Coefficients({p.gain * p.a1b0 / lead});
  out.den = den / lead;
  out.den(out.den.size() - 1) = 1.0;
  return out;
}

std::vector<std::complex<double>> BenchmarkPoles(const BenchmarkPlantParams& p) {
  return CompanionRoots(BenchmarkPlantPolynomials(p).den);
}

void ValidateBenchmarkParams(const BenchmarkPlantParams& p, std::string_view where) {
  const std::string at(where);
  const auto require = [&](double v, bool ok, std::string_view name, std::string_view range) {
    if (!std::isfinite(v) || !ok)
      throw Error(at, fmt::format("{} must be finite and {} (got {})", name, range, v));
  };
  require(p.gain, p.gain > 0.0, "gain", "> 0");
  require(p.a1b0, p.a1b0 > 0.0, "a1b0 [N/(m s^3)]", "> 0");
  require(p.a2, p.a2 >= 0.0, "a2 [N/m]", ">= 0");
  require(p.a3, true, "a3 [1/s]", "any value");
  require(p.b1, p.b1 > 0.0, "b1 [1/s]", "> 0");
  require(p.b2, p.b2 > 0.0, "b2 [1/s^2]", "> 0");
  require(p.m_e_kg, p.m_e_kg > 0.0, "m_e_kg [kg]", "> 0");
  require(p.k_e_N_per_m, p.k_e_N_per_m > 0.0, "k_e_N_per_m [N/m]", "> 0");
  require(p.zeta_e, p.zeta_e >= 0.0, "zeta_e", ">= 0");
  for (const std::complex<double>& pole : BenchmarkPoles(p))
    if (!(pole.real() < 0.0))
      throw Error(at, fmt::format("the plant Gp is unstable: pole at {:.6g}{:+.6g}j 1/s (every pole must have a "
                                  "negative real part; a3 = {}, b1 = {}, b2 = {}, k_e = {} N/m)",
                                  pole.real(), pole.imag(), p.a3, p.b1, p.b2, p.k_e_N_per_m));
}

BenchmarkPlantParams PerturbedBenchmarkParams(const BenchmarkPlantParams& nominal, std::uint64_t seed,
                                              const BenchmarkUncertainty& sigma) {
  signal::GaussianState g = signal::MakeGaussian(seed);
  BenchmarkPlantParams p = nominal;
  p.b1 = nominal.b1 + sigma.b1_sigma * signal::NextGaussian(&g);
  p.b2 = nominal.b2 + sigma.b2_sigma * signal::NextGaussian(&g);
  p.a3 = nominal.a3 + sigma.a3_sigma * signal::NextGaussian(&g);
  p.k_e_N_per_m = nominal.k_e_N_per_m + sigma.k_e_sigma_N_per_m * signal::NextGaussian(&g);
  return p;
}

BenchmarkPlant BenchmarkPlant::Make(const BenchmarkPlantParams& p, double dt_s) {
  ValidateBenchmarkParams(p);
  if (!std::isfinite(dt_s) || !(dt_s > 0.0))
    throw Error("benchmark plant", fmt::format("dt_s must be finite and > 0 (got {})", dt_s));

  BenchmarkPlant m;
  m.params = p;
  m.dt_s = dt_s;
  m.poly = BenchmarkPlantPolynomials(p);
  if (m.Order() != kBenchmarkPlantOrder)
    throw Error("benchmark plant", fmt::format("assembled order {} (expected {})", m.Order(), kBenchmarkPlantOrder));
  m.A = Companion(m.poly.den);
  m.B = Vector::Zero();
  m.B(kBenchmarkPlantOrder - 1) = m.poly.num(0);
  m.C = Row::Zero();
  m.C(0) = 1.0;

  // exp([[A, B], [0, 0]] dt) = [[Phi, Gamma], [0, 1]], in the basis z~ = D z, D = diag(w^-i).
  constexpr int n = kBenchmarkPlantOrder;
  const double w = std::pow(m.poly.den(0), 1.0 / n);
  Vector d;
  for (int i = 0; i < n; ++i) d(i) = std::pow(w, -i);
  Eigen::Matrix<double, n + 1, n + 1> aug = Eigen::Matrix<double, n + 1, n + 1>::Zero();
  aug.topLeftCorner<n, n>() = d.asDiagonal() * m.A * d.cwiseInverse().asDiagonal();
  aug.topRightCorner<n, 1>() = d.asDiagonal() * m.B;
  const Eigen::Matrix<double, n + 1, n + 1> e = (aug * dt_s).exp();
  m.Phi = d.cwiseInverse().asDiagonal() * e.topLeftCorner<n, n>() * d.asDiagonal();
  m.Gamma = d.cwiseInverse().asDiagonal() * e.topRightCorner<n, 1>();
  return m;
}

double BenchmarkPlant::DcGain() const { return poly.num(0) / poly.den(0); }

std::vector<std::complex<double>> BenchmarkPlant::Poles() const { return CompanionRoots(poly.den); }

double Output(const BenchmarkPlant& m, const BenchmarkPlantState& s) { return m.C.dot(s.z); }

double Step(const BenchmarkPlant& m, BenchmarkPlantState* s, double u_m) {
  s->z = m.Phi * s->z + m.Gamma * u_m;
  return m.C.dot(s->z);
}

double StepMm(const BenchmarkPlant& m, BenchmarkPlantState* s, double u_mm) {
  return 1e3 * Step(m, s, 1e-3 * u_mm);
}

BenchmarkNoiseRms BenchmarkSensorNoise(double dt_s) {
  if (!std::isfinite(dt_s) || !(dt_s > 0.0))
    throw Error("BenchmarkSensorNoise", fmt::format("dt_s must be finite and > 0 (got {})", dt_s));
  constexpr double kDisplacementPower_m2_s = 6.25e-14;  // the benchmark's, SI
  constexpr double kForcePower_N2_s = 1.16e-3;
  return {1e3 * std::sqrt(kDisplacementPower_m2_s / dt_s), 1e-3 * std::sqrt(kForcePower_N2_s / dt_s)};
}

std::complex<double> FrequencyResponse(const BenchmarkPlant& m, double f_hz, bool discrete) {
  using cd = std::complex<double>;
  const double w = 2.0 * std::numbers::pi * f_hz;
  if (!discrete) {
    const cd s(0.0, w);
    cd den = 0.0;
    for (Eigen::Index i = m.poly.den.size() - 1; i >= 0; --i) den = den * s + m.poly.den(i);
    return m.poly.num(0) / den;
  }
  using MatrixC = Eigen::Matrix<cd, kBenchmarkPlantOrder, kBenchmarkPlantOrder>;
  const cd z = std::exp(cd(0.0, w * m.dt_s));
  const MatrixC zi_phi = z * MatrixC::Identity() - m.Phi.cast<cd>();
  const Eigen::Matrix<cd, kBenchmarkPlantOrder, 1> x = zi_phi.partialPivLu().solve(m.Gamma.cast<cd>());
  return (m.C.cast<cd>() * x).value();
}

double TimeLagS(const BenchmarkPlant& m, double f_hz, bool discrete) {
  if (!std::isfinite(f_hz) || !(f_hz > 0.0))
    throw Error("benchmark plant TimeLagS", fmt::format("f_hz must be finite and > 0 (got {})", f_hz));
  return UnwrappedLagS(f_hz, m.DcGain(), [&](double f) { return FrequencyResponse(m, f, discrete); });
}

}  // namespace rths::models
