// Tests for lib/signal: portable Gaussian noise, Butterworth SOS design and filtering, BLWN,
// time-history files, Eq. 31. Expected values are closed forms or published constants.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <new>
#include <cmath>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "signal/blwn.h"
#include "signal/bode.h"
#include "signal/butterworth.h"
#include "signal/derivative.h"
#include "signal/history.h"
#include "signal/metrics.h"
#include "signal/random.h"
#include "signal/stats.h"
#include "signal/zero_phase.h"

namespace sig = rths::signal;
using std::numbers::pi;

#include "alloc_counter.h"

namespace {

// Analytic magnitude of the bilinear-mapped (prewarped) Butterworth low-pass of order n:
// |H|^2 = 1 / (1 + (tan(pi f/fs) / tan(pi fc/fs))^(2n)).
double AnalyticButterworthMag(int n, double fc, double fs, double f) {
  const double ratio = std::tan(pi * f / fs) / std::tan(pi * fc / fs);
  return 1.0 / std::sqrt(1.0 + std::pow(ratio, 2.0 * n));
}

// In-place radix-2 FFT (n a power of two), for the spectrum check only.
void Fft(std::vector<std::complex<double>>* x) {
  const std::size_t n = x->size();
  auto& a = *x;
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const std::complex<double> wl = std::polar(1.0, -2.0 * pi / static_cast<double>(len));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> w = 1.0;
      for (std::size_t k = 0; k < len / 2; ++k) {
        const auto u = a[i + k];
        const auto v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
        w *= wl;
      }
    }
  }
}

double Rms(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

// A scratch folder for history files, unique per test binary run, removed at exit.
struct Scratch {
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("rths_signal_test_" + std::to_string(std::random_device{}()));
  Scratch() { std::filesystem::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};
std::filesystem::path ScratchDir() {
  static const Scratch scratch;
  return scratch.dir;
}

std::string WriteFile(const std::string& name, const std::string& text) {
  const auto path = ScratchDir() / name;
  std::ofstream(path) << text;
  return path.string();
}

// Runs `f` and returns the rths::Error's where() (fails the test if nothing is thrown).
template <class F>
std::string ErrorWhere(F&& f) {
  try {
    f();
  } catch (const rths::Error& e) {
    return e.where();
  }
  FAIL("expected rths::Error");
  return "";
}

}  // namespace

// ------------------------------------------------------------------------------------------
TEST_CASE("random: engine is the standard mt19937_64 and the stream is reproducible") {
  // C++ standard [rand.predef]: the 10000th output of a default-constructed mt19937_64.
  sig::GaussianState g = sig::MakeGaussian(5489u);  // 5489 = std::mt19937_64::default_seed
  for (int i = 0; i < 9999; ++i) g.engine();
  CHECK(g.engine() == 9981545732273789042ull);

  sig::GaussianState a = sig::MakeGaussian(42), b = sig::MakeGaussian(42), c = sig::MakeGaussian(43);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = sig::NextGaussian(&a);
    CHECK(x == sig::NextGaussian(&b));
    differ += x != sig::NextGaussian(&c);
  }
  CHECK(differ == 1000);
  // Copying the state replays the stream (a state is a plain value).
  sig::GaussianState copy = a;
  for (int i = 0; i < 7; ++i) CHECK(sig::NextGaussian(&copy) == sig::NextGaussian(&a));
}

TEST_CASE("random: uniforms lie in [0, 1) with 53-bit resolution") {
  sig::GaussianState g = sig::MakeGaussian(1);
  double lo = 1.0, hi = 0.0, sum = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = sig::NextUniform(&g);
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    CHECK(std::ldexp(u, 53) == std::floor(std::ldexp(u, 53)));
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    sum += u;
  }
  CHECK(lo < 1e-4);
  CHECK(hi > 1.0 - 1e-4);
  CHECK(sum / n == doctest::Approx(0.5).epsilon(0.01));
}

TEST_CASE("random: PortableLog agrees with the libm log to a few ulp") {
  const double values[] = {1.0, 2.0, 0.5, std::numbers::e, 0.7071067811865476, 1.4142135623730951,
                           3.0, 10.0, 1e-300, 1e300, 4.9e-324, 0.999999999999, 1.000000000001};
  for (double x : values) {
    const double ref = std::log(x);
    const double tol = 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(ref));
    CHECK(std::abs(sig::PortableLog(x) - ref) <= tol);
  }
  sig::GaussianState g = sig::MakeGaussian(9);
  for (int i = 0; i < 100000; ++i) {
    const double x = sig::NextUniform(&g) + 1e-12;  // (0, 1): the polar method's range
    const double ref = std::log(x);
    REQUIRE(std::abs(sig::PortableLog(x) - ref) <= 4e-16 * std::max(1.0, std::abs(ref)));
  }
  CHECK(sig::PortableLog(1.0) == 0.0);
  CHECK(std::isnan(sig::PortableLog(0.0)));
  CHECK(std::isnan(sig::PortableLog(-1.0)));
}

TEST_CASE("random: Gaussian moments match N(0, 1)") {
  sig::GaussianState g = sig::MakeGaussian(2024);
  const int n = 400000;
  double m1 = 0, m2 = 0, m4 = 0;
  int within1 = 0, within2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = sig::NextGaussian(&g);
    m1 += x;
    m2 += x * x;
    m4 += x * x * x * x;
    within1 += std::abs(x) < 1.0;
    within2 += std::abs(x) < 2.0;
  }
  m1 /= n;
  m2 /= n;
  m4 /= n;
  // Standard errors: mean 1/sqrt(n) = 0.0016, variance sqrt(2/n) = 0.0022, m4 sqrt(96/n) = 0.015.
  CHECK(std::abs(m1) < 0.008);
  CHECK(std::abs(m2 - 1.0) < 0.011);
  CHECK(std::abs(m4 - 3.0) < 0.08);
  // P(|x| < 1) = erf(1/sqrt 2) = 0.682689, P(|x| < 2) = 0.954500; standard errors < 0.001.
  CHECK(std::abs(within1 / double(n) - 0.682689) < 0.004);
  CHECK(std::abs(within2 / double(n) - 0.954500) < 0.002);
}

// ------------------------------------------------------------------------------------------
TEST_CASE("butterworth: DC gain 1, -3 dB at fc, analytic magnitude, zero at Nyquist") {
  const double fs = 2000.0;
  for (int order = 1; order <= 10; ++order) {
    for (double fc : {5.0, 15.0, 50.0, 318.0, 700.0}) {
      CAPTURE(order);
      CAPTURE(fc);
      const sig::Sos sos = sig::ButterworthLowpass(order, fc, fs);
      CHECK(sos.sections.size() == static_cast<std::size_t>((order + 1) / 2));
      CHECK(std::abs(sig::SosResponse(sos, 0.0, fs)) == doctest::Approx(1.0).epsilon(1e-12));
      CHECK(std::abs(sig::SosResponse(sos, fc, fs)) == doctest::Approx(1.0 / std::sqrt(2.0)).epsilon(1e-10));
      for (double ratio : {0.1, 0.5, 0.9, 1.1, 1.5, 2.0, 3.0}) {
        const double f = ratio * fc;
        if (f >= 0.5 * fs) continue;
        CAPTURE(f);
        const double expect = AnalyticButterworthMag(order, fc, fs, f);
        CHECK(std::abs(sig::SosResponse(sos, f, fs)) == doctest::Approx(expect).epsilon(1e-8));
      }
      CHECK(std::abs(sig::SosResponse(sos, 0.5 * fs, fs)) < 1e-12);
      // Poles inside the unit circle: |a2| < 1 and |a1| < 1 + a2 for every section.
      for (const auto& s : sos.sections) {
        CHECK(std::abs(s.a2) < 1.0);
        CHECK(std::abs(s.a1) < 1.0 + s.a2);
      }
    }
  }
}

TEST_CASE("butterworth: time-domain filtering gives the analytic steady-state sine amplitude") {
  // A sine through SosStep, after the transient, has amplitude |H(f)| from the closed form:
  // this checks the DF-II-T recursion independently of SosResponse.
  const double fs = 2000.0, fc = 5.0;
  for (int order : {3, 8}) {
    const sig::Sos sos = sig::ButterworthLowpass(order, fc, fs);
    for (double f : {2.0, 5.0, 8.0}) {
      CAPTURE(order);
      CAPTURE(f);
      sig::SosFilter st = sig::SosAtRest(sos);
      const int settle = 20000, periods = 8;
      const int span = static_cast<int>(std::lround(periods * fs / f));
      double s2 = 0.0;
      for (int k = 0; k < settle + span; ++k) {
        const double y = sig::SosStep(sos, &st, std::sin(2.0 * pi * f * k / fs));
        if (k >= settle) s2 += y * y;
      }
      const double amplitude = std::sqrt(2.0 * s2 / span);
      CHECK(amplitude == doctest::Approx(AnalyticButterworthMag(order, fc, fs, f)).epsilon(1e-4));
    }
    // Unit step settles to exactly the DC gain 1.
    sig::SosFilter st = sig::SosAtRest(sos);
    double y = 0.0;
    for (int k = 0; k < 40000; ++k) y = sig::SosStep(sos, &st, 1.0);
    CHECK(y == doctest::Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE("butterworth: preconditions") {
  CHECK_THROWS_AS(sig::ButterworthLowpass(0, 5.0, 2000.0), rths::Error);
  CHECK_THROWS_AS(sig::ButterworthLowpass(33, 5.0, 2000.0), rths::Error);
  CHECK_THROWS_AS(sig::ButterworthLowpass(8, 0.0, 2000.0), rths::Error);
  CHECK_THROWS_AS(sig::ButterworthLowpass(8, 1000.0, 2000.0), rths::Error);
  CHECK_THROWS_AS(sig::ButterworthLowpass(8, 5.0, -1.0), rths::Error);
  try {
    sig::ButterworthLowpass(8, 1500.0, 2000.0);
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("fc_hz") != std::string::npos);
  }
}

// ------------------------------------------------------------------------------------------
TEST_CASE("blwn: exact RMS, reproducible per seed, different across seeds") {
  const double dt = 0.0005;
  const std::size_t n = 20000;
  const auto a = sig::Blwn(5.0, 2.78, dt, n, 1, 2.0);
  const auto b = sig::Blwn(5.0, 2.78, dt, n, 1, 2.0);
  const auto c = sig::Blwn(5.0, 2.78, dt, n, 2, 2.0);
  REQUIRE(a.size() == n);
  CHECK(Rms(a) == doctest::Approx(2.78).epsilon(1e-12));
  CHECK(Rms(c) == doctest::Approx(2.78).epsilon(1e-12));
  CHECK(a == b);
  double diff2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) diff2 += (a[i] - c[i]) * (a[i] - c[i]);
  // Independent records: the difference has about sqrt(2) x the RMS.
  CHECK(std::sqrt(diff2 / n) > 2.78);
  CHECK(Rms(sig::Blwn(15.0, 0.595, dt, n, 7, 0.0)) == doctest::Approx(0.595).epsilon(1e-12));
}

TEST_CASE("blwn: the first discard_s seconds of the same filtered stream are dropped") {
  // With discard m samples, the record is the tail of the discard-free record of length m + n,
  // up to the scale factor (RMS normalisation over the kept part only).
  const double dt = 0.0005;
  const std::size_t n = 4000, m = 2000;  // 1 s discarded
  const auto kept = sig::Blwn(10.0, 1.0, dt, n, 3, 1.0);
  const auto full = sig::Blwn(10.0, 1.0, dt, n + m, 3, 0.0);
  const double ratio = kept[n / 2] / full[m + n / 2];
  for (std::size_t i = 0; i < n; ++i) {
    REQUIRE(kept[i] == doctest::Approx(ratio * full[m + i]).epsilon(1e-9));
  }
  CHECK(ratio != doctest::Approx(1.0).epsilon(1e-3));  // the kept part's RMS differs
}

TEST_CASE("blwn: spectrum is confined to the band") {
  // 8th-order Butterworth: the fraction of the power above 1.5 x the band edge is
  // int_1.5^inf dx / (1 + x^16) / int_0^inf ... ~ 1.5^-15 / 15 = 1.5e-4 (less after the
  // bilinear map); below the edge it is int_0^1 / int_0^inf ~ 0.96. Hann-windowed periodogram.
  const double dt = 0.0005, band = 5.0;
  const std::size_t n = 1u << 17;  // 65.5 s
  const auto x = sig::Blwn(band, 2.78, dt, n, 11, 2.0);
  std::vector<std::complex<double>> X(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * pi * static_cast<double>(i) / static_cast<double>(n));
    X[i] = w * x[i];
  }
  Fft(&X);
  double total = 0.0, above = 0.0, below = 0.0;
  const double df = 1.0 / (n * dt);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    const double p = std::norm(X[k]);
    const double f = k * df;
    total += p;
    if (f > 1.5 * band) above += p;
    if (f <= band) below += p;
  }
  MESSAGE("BLWN 5 Hz: power fraction above 7.5 Hz = ", above / total, ", below 5 Hz = ", below / total);
  CHECK(above / total < 1e-3);
  CHECK(below / total > 0.9);
}

TEST_CASE("blwn: preconditions") {
  CHECK_THROWS_AS(sig::Blwn(0.0, 1.0, 0.0005, 10, 1, 0.0), rths::Error);
  CHECK_THROWS_AS(sig::Blwn(1000.0, 1.0, 0.0005, 10, 1, 0.0), rths::Error);
  CHECK_THROWS_AS(sig::Blwn(5.0, 0.0, 0.0005, 10, 1, 0.0), rths::Error);
  CHECK_THROWS_AS(sig::Blwn(5.0, 1.0, 0.0, 10, 1, 0.0), rths::Error);
  CHECK_THROWS_AS(sig::Blwn(5.0, 1.0, 0.0005, 0, 1, 0.0), rths::Error);
  CHECK_THROWS_AS(sig::Blwn(5.0, 1.0, 0.0005, 10, 1, -1.0), rths::Error);
}

// ------------------------------------------------------------------------------------------
TEST_CASE("history: one column, linear interpolation, scale, zero padding") {
  // Values 0, 1, 4, 9 at 0.1 s: interpolated linearly between rows; zero after t = 0.3 s.
  const auto path = WriteFile("one.txt", "# header comment\n0\n1\n\n4   # trailing comment\n9\n");
  const double dt = 0.025;
  const auto x = sig::LoadHistory(path, 0.1, 2.0, dt, 20);
  REQUIRE(x.size() == 20);
  const double v[] = {0, 1, 4, 9};
  for (std::size_t k = 0; k < 20; ++k) {
    const double t = k * dt;
    double expect = 0.0;
    if (t <= 0.3 + 1e-12) {
      const auto j = std::min<std::size_t>(static_cast<std::size_t>(std::floor(t / 0.1 + 1e-9)), 2);
      const double w = t / 0.1 - j;
      expect = 2.0 * (v[j] + w * (v[j + 1] - v[j]));
    }
    CAPTURE(k);
    CHECK(x[k] == doctest::Approx(expect).epsilon(1e-12));
  }
  CHECK(x[12] == doctest::Approx(18.0));  // t = 0.3 s: the last row
  CHECK(x[13] == 0.0);
}

TEST_CASE("history: two columns with commas, non-uniform steps, start after 0") {
  // Rows at 0.1, 0.2, 0.25, 0.35, 0.45 s (steps within 1.5 x the median 0.1 s: no gap).
  const auto path = WriteFile("two.csv",
                              "# t, value\n"
                              "0.1, 1.0\n"
                              "0.2,3.0\n"
                              "  0.25 ,\t 2.0  \n"
                              "0.35 5\n"
                              "+0.45\t1e0\n");
  const auto x = sig::LoadHistory(path, 0.0, 1.0, 0.05, 12);
  // Zero before the first row (0.1 s) and after the last (0.45 s); linear in between.
  const std::vector<double> expect = {0.0, 0.0, 1.0, 2.0, 3.0, 2.0, 3.5, 5.0, 3.0, 1.0, 0.0, 0.0};
  REQUIRE(x.size() == expect.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    CAPTURE(k);
    CHECK(x[k] == doctest::Approx(expect[k]).epsilon(1e-12));
  }
}

TEST_CASE("history: the El Centro record resamples to 2 kHz with its peak in place") {
  const std::string path = std::string(RTHS_SOURCE_DIR) + "/data/ground_motion/elcentro_1940_ns_g.txt";
  // data/README.md: 1560 samples at 0.02 s, peak -0.31882 g at t = 2.02 s (row 101).
  const double dt = 0.0005;
  const std::size_t n = 70000;  // 35 s
  const auto x = sig::LoadHistory(path, 0.02, 9806.65, dt, n);  // g -> mm/s^2
  CHECK(x[4040] == doctest::Approx(-0.31882 * 9806.65).epsilon(1e-12));
  const auto peak = std::min_element(x.begin(), x.end());
  CHECK(peak - x.begin() == 4040);
  // The last rows are -0.00006, 0, 0 g at 31.14, 31.16, 31.18 s.
  CHECK(x[1557 * 40] == doctest::Approx(-0.00006 * 9806.65).epsilon(1e-12));
  CHECK(x[1557 * 40 + 20] == doctest::Approx(-0.00003 * 9806.65).epsilon(1e-12));
  const std::size_t last = 1559 * 40;  // t = 31.18 s
  for (std::size_t k = last + 1; k < n; ++k) REQUIRE(x[k] == 0.0);
}

TEST_CASE("history: start_s delays the record and pads it with zeros at the file's own step (the benchmark's record)") {
  const std::string path = std::string(RTHS_SOURCE_DIR) + "/data/ground_motion/elcentro_1940_ns_g.txt";
  const double dt = 0.0025;  // 8 samples per file step
  const std::size_t n = 16480;  // 41.2 s
  const auto plain = sig::LoadHistory(path, 0.02, 1.0, dt, n);
  const auto padded = sig::LoadHistory(path, 0.02, 1.0, dt, n, 5.0);
  for (std::size_t k = 0; k < 1992; ++k) REQUIRE(padded[k] == 0.0);  // zeros up to 4.98 s
  // From 4.98 s to 5.00 s the record ramps from 0 to its first value (0.0063 g), as the file
  // padded with zero rows at 0.02 s would.
  CHECK(padded[1996] == doctest::Approx(0.5 * 0.0063).epsilon(1e-12));
  for (std::size_t k = 2000; k < 2000 + 12480; ++k) REQUIRE(padded[k] == doctest::Approx(plain[k - 2000]).epsilon(1e-12));
  CHECK(padded[2000 + 1559 * 8] == doctest::Approx(plain[1559 * 8]));  // last row at 36.18 s
  for (std::size_t k = 2000 + 1560 * 8; k < n; ++k) REQUIRE(padded[k] == 0.0);
  CHECK_THROWS_AS(sig::LoadHistory(path, 0.02, 1.0, dt, n, -1.0), rths::Error);
}

TEST_CASE("history: errors name the file and line") {
  const auto where_of = [](const std::string& name, const std::string& text, double file_dt) {
    const auto path = WriteFile(name, text);
    return ErrorWhere([&] { sig::LoadHistory(path, file_dt, 1.0, 0.001, 10); });
  };
  CHECK(where_of("bad_num.txt", "0 1\n0.1 2\n0.2 abc\n", 0.0).ends_with("bad_num.txt:3"));
  CHECK(where_of("bad_num1.txt", "1\n# c\n2x\n", 0.01).ends_with("bad_num1.txt:3"));
  CHECK(where_of("nan.txt", "1\nnan\n", 0.01).ends_with("nan.txt:2"));
  CHECK(where_of("nonincr.txt", "0 1\n0.1 2\n0.1 3\n", 0.0).ends_with("nonincr.txt:3"));
  CHECK(where_of("decr.txt", "0 1\n0.1 2\n0.05 3\n", 0.0).ends_with("decr.txt:3"));
  CHECK(where_of("gap.txt", "0 1\n0.01 2\n0.02 3\n0.04 4\n0.05 5\n", 0.0).ends_with("gap.txt:4"));
  CHECK(where_of("empty_field.csv", "0,1\n0.01,,2\n", 0.0).ends_with("empty_field.csv:2"));
  CHECK(where_of("trailing_comma.csv", "0,1,\n", 0.0).ends_with("trailing_comma.csv:1"));
  CHECK(where_of("cols.txt", "0 1\n0.01 2 3\n", 0.0).ends_with("cols.txt:2"));
  CHECK(where_of("cols1.txt", "0 1\n", 0.01).ends_with("cols1.txt:1"));
  CHECK(where_of("negative_t.txt", "-0.01 1\n0 2\n", 0.0).ends_with("negative_t.txt:1"));
  // No data: the message names the file (no line).
  const auto empty = WriteFile("empty.txt", "");
  CHECK(ErrorWhere([&] { sig::LoadHistory(empty, 0.01, 1.0, 0.001, 10); }) == empty);
  const auto comments = WriteFile("comments.txt", "# nothing\n\n   # here\n");
  CHECK(ErrorWhere([&] { sig::LoadHistory(comments, 0.0, 1.0, 0.001, 10); }) == comments);
  const auto missing = (ScratchDir() / "does_not_exist.txt").string();
  CHECK(ErrorWhere([&] { sig::LoadHistory(missing, 0.01, 1.0, 0.001, 10); }) == missing);
  const auto ok = WriteFile("ok.txt", "1\n2\n");
  CHECK_THROWS_AS(sig::LoadHistory(ok, -0.01, 1.0, 0.001, 10), rths::Error);
  CHECK_THROWS_AS(sig::LoadHistory(ok, 0.01, 1.0, 0.0, 10), rths::Error);
}

TEST_CASE("history: MakeSignal dispatches on kind") {
  const double dt = 0.0005;
  rths::signal::SignalSpec spec;
  spec.kind = rths::signal::SignalKind::kZero;
  CHECK(sig::MakeSignal(spec, dt, 5) == std::vector<double>(5, 0.0));

  spec.kind = rths::signal::SignalKind::kBlwn;
  spec.band_hz = 15.0;
  spec.rms = 0.595;
  spec.seed = 4;
  spec.discard_s = 2.0;
  CHECK(sig::MakeSignal(spec, dt, 3000) == sig::Blwn(15.0, 0.595, dt, 3000, 4, 2.0));

  WriteFile("ramp.txt", "0\n1\n2\n");
  spec.kind = rths::signal::SignalKind::kFile;
  spec.file = "ramp.txt";
  spec.file_dt_s = 0.001;
  spec.scale = 10.0;
  spec.record = sig::ReadHistoryFile((ScratchDir() / spec.file).string(), spec.file_dt_s);  // the loader's part
  const auto x = sig::MakeSignal(spec, dt, 6);
  const std::vector<double> expect = {0.0, 5.0, 10.0, 15.0, 20.0, 0.0};
  for (std::size_t k = 0; k < 6; ++k) CHECK(x[k] == doctest::Approx(expect[k]).epsilon(1e-12));
}

// ------------------------------------------------------------------------------------------
TEST_CASE("metrics: Eq. 31 closed forms") {
  const std::size_t n = 4000;
  std::vector<double> r(n), y90(n), yd(n), zero(n, 0.0);
  const double w = 2.0 * pi * 5.0, dt = 0.0005, tau = 0.008;
  for (std::size_t i = 0; i < n; ++i) {  // 10 whole periods of 5 Hz
    const double t = i * dt;
    r[i] = 3.0 * std::sin(w * t);
    y90[i] = 0.9 * r[i];
    yd[i] = 3.0 * std::sin(w * (t - tau));
  }
  CHECK(sig::RmsErrorPercent(r, r) == 0.0);
  CHECK(sig::RmsErrorPercent(r, y90) == doctest::Approx(10.0).epsilon(1e-12));
  CHECK(sig::RmsErrorPercent(r, zero) == doctest::Approx(100.0).epsilon(1e-12));
  // A pure delay tau on a sine: mean (sin a - sin b)^2 / mean sin^2 = 2 (1 - cos w tau),
  // so e = 2 |sin(w tau / 2)| x 100 %.
  CHECK(sig::RmsErrorPercent(r, yd) == doctest::Approx(200.0 * std::sin(w * tau / 2.0)).epsilon(1e-9));

  sig::RmsErrorAccumulator acc;
  CHECK(std::isnan(acc.Percent()));
  for (std::size_t i = 0; i < n; ++i) acc.Add(r[i], yd[i]);
  CHECK(acc.count == n);
  CHECK(acc.Percent() == sig::RmsErrorPercent(r, yd));

  CHECK(std::isnan(sig::RmsErrorPercent(zero, r)));
  CHECK_THROWS_AS(sig::RmsErrorPercent(std::span<const double>(r).first(10), r), rths::Error);
}

TEST_CASE("per-step functions allocate nothing") {
  const sig::Sos sos = sig::ButterworthLowpass(8, 5.0, 2000.0);
  sig::SosFilter st = sig::SosAtRest(sos);
  sig::GaussianState g = sig::MakeGaussian(3);
  sig::RmsErrorAccumulator acc;
  double sink = 0.0;
  const long before = rths_test::AllocationCount();
  for (int i = 0; i < 1000; ++i) {
    const double x = sig::SosStep(sos, &st, sig::NextGaussian(&g));
    acc.Add(x, 0.5 * x);
    sink += x + sig::NextUniform(&g);
  }
  const long after = rths_test::AllocationCount();
  CHECK(after == before);
  CHECK(std::isfinite(sink));
  CHECK(acc.Percent() == doctest::Approx(50.0));
}

TEST_CASE("zero-phase low-pass: no lag in the band, |H|^2 above it, the ends as reflection and start say") {
  const double dt = 0.001, fc = 50.0;
  const std::size_t n = 4000;
  std::vector<double> slow(n), noisy(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    slow[k] = std::sin(2.0 * pi * 2.0 * t);
    noisy[k] = slow[k] + std::sin(2.0 * pi * 200.0 * t);
  }
  for (int order : {2, 4}) {
    const auto out = sig::ZeroPhaseLowpass(noisy, dt, fc, order, 600, sig::Reflection::kOdd);
    REQUIRE(out.size() == n);
    // 2 Hz passes without lag (a causal pass would delay it); 200 Hz is left at |H(200 Hz)|^2 of
    // one pass (order 2: 0.0022; order 4: 5e-6).
    double worst = 0.0;
    for (std::size_t k = 500; k + 500 < n; ++k) worst = std::max(worst, std::abs(out[k] - slow[k]));
    CHECK(worst < (order == 2 ? 0.003 : 1e-4));
    if (order == 2) CHECK(worst > 0.001);
  }
  // A ramp, extended by odd reflection, is a ramp: the filter leaves it as it is.
  std::vector<double> ramp(1000);
  for (std::size_t k = 0; k < ramp.size(); ++k) ramp[k] = 0.5 + 0.01 * static_cast<double>(k);
  const auto r = sig::ZeroPhaseLowpass(ramp, dt, fc, 2, 999, sig::Reflection::kOdd, sig::FilterStart::kSteadyState);
  for (std::size_t k = 0; k < ramp.size(); k += 111) CHECK(r[k] == doctest::Approx(ramp[k]).epsilon(1e-6));
  // A constant without padding: from rest each pass rises to it (the ends are wrong); from the
  // first value's steady state it stays.
  const std::vector<double> level(200, 3.0);
  const auto rest = sig::ZeroPhaseLowpass(level, dt, fc, 2, 0, sig::Reflection::kEven);
  const auto steady = sig::ZeroPhaseLowpass(level, dt, fc, 2, 0, sig::Reflection::kEven, sig::FilterStart::kSteadyState);
  CHECK(std::abs(rest.front() - 3.0) > 0.1);
  CHECK(std::abs(rest.back() - 3.0) > 0.1);
  for (double v : steady) CHECK(v == doctest::Approx(3.0).epsilon(1e-12));
  CHECK(sig::ZeroPhaseLowpass(std::vector<double>{}, dt, fc, 2, 10, sig::Reflection::kOdd).empty());
  CHECK_THROWS_AS(sig::ZeroPhaseLowpass(level, dt, 600.0, 2, 10, sig::Reflection::kOdd), rths::Error);
}

TEST_CASE("derivative: central difference inside, one-sided at the ends") {
  // A parabola y = 3 t^2: the central difference is exact inside (6 t), the ends one-sided.
  std::vector<double> y;
  for (int k = 0; k < 5; ++k) y.push_back(3.0 * (0.1 * k) * (0.1 * k));
  const auto v = sig::Derivative(y, 0.1);
  REQUIRE(v.size() == 5);
  CHECK(v[1] == doctest::Approx(0.6));
  CHECK(v[2] == doctest::Approx(1.2));
  CHECK(v[3] == doctest::Approx(1.8));
  CHECK(v[0] == doctest::Approx(0.3));   // (0.03 - 0) / 0.1
  CHECK(v[4] == doctest::Approx(2.1));   // (0.48 - 0.27) / 0.1
  CHECK(sig::Derivative(std::vector<double>{1.0, 3.0}, 0.5) == std::vector<double>{4.0, 4.0});
  CHECK(sig::Derivative(std::vector<double>{7.0}, 0.5) == std::vector<double>{0.0});
}

TEST_CASE("Eq. 31 of sums: the accumulator's percent, NaN without a reference") {
  sig::RmsErrorAccumulator acc;
  acc.Add(4.0, 1.0);  // e = 3
  acc.Add(3.0, 3.0);  // e = 0
  CHECK(acc.Percent() == doctest::Approx(100.0 * std::sqrt(9.0 / 25.0)));
  CHECK(sig::RmsErrorAccumulator{9.0, 25.0, 0}.Percent() == doctest::Approx(60.0));
  CHECK(std::isnan(sig::RmsErrorAccumulator{9.0, 0.0, 0}.Percent()));
}

TEST_CASE("stats: spread (mean, sample std, min, max) and median") {
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};
  const auto s = sig::SpreadOf(v);
  CHECK(s.n == 4);
  CHECK(s.mean == doctest::Approx(2.5));
  CHECK(s.std == doctest::Approx(std::sqrt(5.0 / 3.0)));  // (2.25 + 0.25 + 0.25 + 2.25) / 3
  CHECK(s.min == 1.0);
  CHECK(s.max == 4.0);
  const auto one = sig::SpreadOf(std::vector<double>{7.0});
  CHECK(one.std == 0.0);
  CHECK(one.mean == 7.0);
  const auto none = sig::SpreadOf(std::vector<double>{});
  CHECK(none.n == 0);
  CHECK(std::isnan(none.mean));
  CHECK(std::isnan(none.std));
  CHECK(sig::Median(v) == 2.5);
  CHECK(sig::Median({3.0, 1.0, 2.0}) == 2.0);
  CHECK(sig::Median({5.0}) == 5.0);
  CHECK(std::isnan(sig::Median({})));
}

TEST_CASE("bode: phase unwrapped across -180 deg, time lag from it, coherence 1 for a model") {
  // h_k = 2 exp(-i k) at f = k + 1 Hz: the phase falls by 1 rad a point, past -pi at k = 4.
  std::vector<double> f;
  std::vector<std::complex<double>> h;
  for (int k = 0; k < 10; ++k) {
    f.push_back(k + 1.0);
    h.push_back(std::polar(2.0, -1.0 * k));
  }
  const auto c = sig::BodeFromResponse("model", f, h);
  REQUIRE(c.phase_deg.size() == 10);
  for (int k = 0; k < 10; ++k) {
    CHECK(c.phase_deg[k] == doctest::Approx(-k * 180.0 / pi));
    CHECK(c.lag_ms[k] == doctest::Approx(k / (2.0 * pi * f[k]) * 1e3));
    CHECK(c.magnitude[k] == doctest::Approx(2.0));
    CHECK(c.coherence[k] == 1.0);
  }
  CHECK(c.name == "model");
  const std::vector<double> coh(10, 0.5);
  CHECK(sig::BodeFromResponse("m", f, h, coh).coherence[3] == 0.5);
  CHECK_THROWS_AS(sig::BodeFromResponse("m", std::vector<double>{1.0}, h), rths::Error);
  // An estimate: the points of (0, f_max], DC left out.
  sig::FrequencyResponseEstimate est;
  est.f_hz = {0.0, 1.0, 2.0, 3.0};
  est.h = {1.0, std::polar(1.0, -0.5), std::polar(1.0, -1.0), std::polar(1.0, -1.5)};
  est.coherence = {1.0, 0.9, 0.8, 0.7};
  const auto e = sig::BodeFromEstimate("H1", est, 2.0);
  REQUIRE(e.f_hz.size() == 2);
  CHECK(e.f_hz[0] == 1.0);
  CHECK(e.coherence[1] == 0.8);
  CHECK(e.phase_deg[1] == doctest::Approx(-1.0 * 180.0 / pi));
}
