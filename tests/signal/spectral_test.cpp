// Welch spectra, H1 and coherence (signal/spectral.h): closed forms for FIR and IIR systems,
// Parseval, coherence with and without noise.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <doctest/doctest.h>

#include "core/error.h"
#include "signal/random.h"
#include "signal/spectral.h"

namespace {

using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;

std::vector<double> WhiteNoise(std::size_t n, std::uint64_t seed, double rms = 1.0) {
  auto g = rths::signal::MakeGaussian(seed);
  std::vector<double> x(n);
  for (auto& v : x) v = rms * rths::signal::NextGaussian(&g);
  return x;
}

}  // namespace

TEST_CASE("RealDft equals the defining sum and satisfies Parseval exactly (even and odd lengths)") {
  for (std::size_t n : {8u, 15u, 1000u, 1024u}) {
    const auto x = WhiteNoise(n, 3 + n);
    const auto X = rths::signal::RealDft(x);
    REQUIRE(X.size() == n / 2 + 1);
    // Defining sum at a few bins.
    for (std::size_t i : {std::size_t{0}, std::size_t{1}, n / 3, n / 2}) {
      cd ref = 0.0;
      for (std::size_t j = 0; j < n; ++j) ref += x[j] * std::exp(cd(0.0, -2.0 * kPi * double(i * j % n) / double(n)));
      CHECK(std::abs(X[i] - ref) < 1e-9 * (1.0 + std::abs(ref)));
    }
    // Parseval: sum x^2 = (1/n) sum_{i=0}^{n-1} |X_i|^2, the upper half by conjugate symmetry.
    double sx = 0.0, sX = 0.0;
    for (double v : x) sx += v * v;
    for (std::size_t i = 0; i < n; ++i) sX += std::norm(i <= n / 2 ? X[i] : std::conj(X[n - i]));
    CHECK(sX / double(n) == doctest::Approx(sx).epsilon(1e-12));
  }
}

TEST_CASE("Welch PSD integrates to the variance (Parseval for the density scaling)") {
  const double dt = 0.0005;
  // White noise of variance 4 plus a mean: the mean is removed per segment.
  auto x = WhiteNoise(200000, 11, 2.0);
  for (auto& v : x) v += 5.0;
  const auto psd = rths::signal::WelchPsd(x, dt, 2048);
  const double df = 1.0 / (dt * 2048);
  double area = 0.0;
  for (double p : psd) area += p * df;
  CHECK(area == doctest::Approx(4.0).epsilon(0.01));
  // One-sided white density: variance / (fs / 2) at every inner bin (on average).
  double mid = 0.0;
  for (std::size_t i = 100; i < 900; ++i) mid += psd[i];
  CHECK(mid / 800.0 == doctest::Approx(4.0 / (0.5 / dt)).epsilon(0.02));

  // A sine of amplitude A on a bin: area A^2 / 2.
  std::vector<double> s(64 * 1024);
  const double A = 3.0, f = 50.0 * (1.0 / (dt * 1024));
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = A * std::sin(2.0 * kPi * f * dt * double(k));
  const auto ps = rths::signal::WelchPsd(s, dt, 1024);
  double as = 0.0;
  for (double p : ps) as += p * (1.0 / (dt * 1024));
  CHECK(as == doctest::Approx(A * A / 2.0).epsilon(1e-6));
}

TEST_CASE("H1 of an FIR system matches its closed form; coherence ~ 1 without noise") {
  const double dt = 0.001;
  const auto u = WhiteNoise(1 << 17, 5);
  std::vector<double> y(u.size());
  for (std::size_t k = 0; k < u.size(); ++k)
    y[k] = 0.5 * u[k] + 0.3 * (k >= 1 ? u[k - 1] : 0.0) + 0.1 * (k >= 2 ? u[k - 2] : 0.0);
  const auto e = rths::signal::H1Estimate(u, y, dt, 1024);
  CHECK(e.segments == (u.size() - 1024) / 512 + 1);
  CHECK(e.df_hz == doctest::Approx(1.0 / (dt * 1024)));
  double worst = 0.0, worst_coh = 1.0;
  for (std::size_t i = 1; i + 1 < e.f_hz.size(); ++i) {
    const double w = 2.0 * kPi * e.f_hz[i] * dt;
    const cd ref = 0.5 + 0.3 * std::exp(cd(0, -w)) + 0.1 * std::exp(cd(0, -2 * w));
    worst = std::max(worst, std::abs(e.h[i] - ref) / std::abs(ref));
    worst_coh = std::min(worst_coh, e.coherence[i]);
  }
  CHECK(worst < 0.01);
  CHECK(worst_coh > 0.999);
}

TEST_CASE("H1 of a first-order IIR system; noise on y lowers the coherence but not H1") {
  const double dt = 0.0005, a = 0.95;
  const auto u = WhiteNoise(1 << 18, 7);
  std::vector<double> y(u.size());
  double prev = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) prev = y[k] = a * prev + (1.0 - a) * u[k];
  const auto ref = [&](double f) { return (1.0 - a) / (1.0 - a * std::exp(cd(0.0, -2.0 * kPi * f * dt))); };

  const auto clean = rths::signal::H1Estimate(u, y, dt, 4096);
  double worst = 0.0;
  for (std::size_t i = 1; i < clean.f_hz.size() - 1; ++i)
    worst = std::max(worst, std::abs(clean.h[i] - ref(clean.f_hz[i])) / std::abs(ref(clean.f_hz[i])));
  CHECK(worst < 0.01);
  for (std::size_t i = 1; i < clean.f_hz.size() - 1; ++i) REQUIRE(clean.coherence[i] > 0.995);

  // Output noise n with S_nn = S_yy at the bin where |H|^2 = ... : coherence = S_yy / (S_yy + S_nn).
  auto noisy = y;
  const auto n = WhiteNoise(y.size(), 8, 0.05);
  for (std::size_t k = 0; k < y.size(); ++k) noisy[k] += n[k];
  const auto e = rths::signal::H1Estimate(u, noisy, dt, 4096);
  const double snn = 0.05 * 0.05 / (0.5 / dt), suu = 1.0 / (0.5 / dt);
  for (std::size_t i = 8; i < e.f_hz.size() - 1; i += 64) {
    const double syy = std::norm(ref(e.f_hz[i])) * suu;
    const double expect = syy / (syy + snn);
    CHECK(e.coherence[i] == doctest::Approx(expect).epsilon(0.15));
    CHECK(e.coherence[i] < clean.coherence[i]);
    // H1 stays unbiased, only noisier: relative standard error sqrt((1 - g2) / (2 M g2)).
    const double se = std::sqrt((1.0 - expect) / (2.0 * static_cast<double>(e.segments) * expect));
    CHECK(std::abs(e.h[i] - ref(e.f_hz[i])) / std::abs(ref(e.f_hz[i])) < 4.0 * se + 0.01);
  }
  CHECK(e.coherence[e.f_hz.size() - 2] < 0.5);  // near Nyquist the noise dominates
}

TEST_CASE("UnwrapPhase follows a pure delay past +/- pi") {
  std::vector<cd> h;
  for (int i = 0; i < 200; ++i) h.push_back(std::exp(cd(0.0, -0.1 * i)));
  const auto ph = rths::signal::UnwrapPhase(h);
  for (int i = 0; i < 200; ++i) CHECK(ph[i] == doctest::Approx(-0.1 * i).epsilon(1e-12));
}

TEST_CASE("Welch rejects bad arguments") {
  const std::vector<double> u(100, 1.0), y(99, 1.0);
  CHECK_THROWS_AS(rths::signal::WelchCrossSpectra(u, y, 0.001, 32), rths::Error);
  CHECK_THROWS_AS(rths::signal::WelchCrossSpectra(u, u, 0.0, 32), rths::Error);
  CHECK_THROWS_AS(rths::signal::WelchCrossSpectra(u, u, 0.001, 101), rths::Error);
  CHECK_THROWS_AS(rths::signal::WelchCrossSpectra(u, u, 0.001, 2), rths::Error);
  CHECK_THROWS_AS(rths::signal::RealDft(std::vector<double>{}), rths::Error);
}
