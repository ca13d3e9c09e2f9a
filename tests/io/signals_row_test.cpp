// io::FormatSignalsRow: the same bytes as the printf format signals.csv was always written with.
#include <doctest/doctest.h>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "io/signals_row.h"

namespace {
std::string Printf(std::int64_t k, double t, const std::array<double, 10>& v) {
  char buf[512];
  const int n = std::snprintf(buf, sizeof buf,
                              "%" PRId64 ",%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", k, t,
                              v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]);
  return std::string(buf, static_cast<std::size_t>(n));
}
std::string Row(std::int64_t k, double t, const std::array<double, 10>& v) {
  char buf[rths::io::kSignalsRowMaxBytes + 1];
  return std::string(buf, rths::io::FormatSignalsRow(buf, k, t, v));
}
}  // namespace

TEST_CASE("signals.csv rows: byte for byte printf's %.6f and %.17g, on random and extreme values") {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> exp10(-320, 308);
  std::uniform_int_distribution<std::uint64_t> bits;
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    std::array<double, 10> v{};
    for (double& x : v) {
      switch (i % 3) {
        case 0: x = mant(rng) * std::pow(10.0, exp10(rng)); break;
        case 1: { const std::uint64_t b = bits(rng); std::memcpy(&x, &b, sizeof x); break; }  // any bit pattern
        default: x = mant(rng) * 100.0; break;  // what a run logs
      }
    }
    const std::int64_t k = i % 2 ? i : std::numeric_limits<std::int64_t>::max() - i;
    const double t = static_cast<double>(i) * 0.0005 * (i % 5 == 0 ? 1e6 : 1.0);
    const std::string want = Printf(k, t, v), got = Row(k, t, v);
    REQUIRE_MESSAGE(got == want, "row " << i);
    CHECK(got.size() <= rths::io::kSignalsRowMaxBytes);
    ++checked;
  }
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const std::array<double, 10> odd{0.0, -0.0, inf, -inf, nan, -nan, 5e-324, -1.7976931348623157e308, 1e-5, 0.1};
  CHECK(Row(-7, -0.0000004, odd) == Printf(-7, -0.0000004, odd));
  CHECK(checked == 20000);
}
