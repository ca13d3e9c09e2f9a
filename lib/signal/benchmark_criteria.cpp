#include "signal/benchmark_criteria.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/stats.h"

namespace rths::signal {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kWhere = "benchmark criteria";

double Mean(std::span<const double> a) {
  double s = 0.0;
  for (double v : a) s += v;
  return s / static_cast<double>(a.size());
}

void CheckRecord(const std::string& name, const std::vector<double>& x, std::size_t n) {
  if (x.size() != n)
    throw Error(kWhere, fmt::format("{} has {} samples but x_m has {}: every record must have the same length", name,
                                    x.size(), n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]))
      throw Error(kWhere, fmt::format("{} is not finite at sample {} (0-based; the run diverged?)", name, i));
  }
}

/// 100 std(a - b) / std(b), and 100 max|a - b| / max|b|, with b a reference that must move.
std::pair<double, double> Errors(std::span<const double> a, std::span<const double> b, const std::string& b_name) {
  const double sd = StdOfDifference(b, {});
  const double mx = MaxAbsOfDifference(b, {});
  if (!(sd > 0.0) || !(mx > 0.0))
    throw Error(kWhere, fmt::format("{} does not move (std {:g}, max |.| {:g}): the criteria divide by it", b_name,
                                    sd, mx));
  return {100.0 * StdOfDifference(a, b) / sd, 100.0 * MaxAbsOfDifference(a, b) / mx};
}

double Round(double v, double unit) { return std::isfinite(v) ? std::round(v / unit) * unit : v; }

}  // namespace

double PearsonCorrelation(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size())
    throw Error("PearsonCorrelation", fmt::format("{} and {} samples: they must match", a.size(), b.size()));
  if (a.size() < 2) return kNaN;
  const double ma = Mean(a), mb = Mean(b);
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double da = a[i] - ma, db = b[i] - mb;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  if (!(saa > 0.0) || !(sbb > 0.0)) return kNaN;
  return sab / std::sqrt(saa * sbb);
}

double BenchmarkCriteria::At(int i) const {
  const double v[9] = {J1_ms, J2_pct, J3_pct, J4_pct, J5_pct, J6_pct, J7_pct, J8_pct, J9_pct};
  return i >= 0 && i < 9 ? v[i] : std::nan("");
}

BenchmarkCriteria BenchmarkCriteria::Rounded() const {
  BenchmarkCriteria r = *this;
  r.J1_ms = Round(J1_ms, 0.1);
  for (double* v : {&r.J2_pct, &r.J3_pct, &r.J4_pct, &r.J5_pct, &r.J6_pct, &r.J7_pct, &r.J8_pct, &r.J9_pct})
    *v = Round(*v, 0.01);
  for (FloorCriteria& f : r.floors) {
    f.std_pct = Round(f.std_pct, 0.01);
    f.max_pct = Round(f.max_pct, 0.01);
  }
  return r;
}

std::string BenchmarkCriteria::Format() const {
  const BenchmarkCriteria r = Rounded();
  auto pct = [](double v) { return std::isfinite(v) ? fmt::format("{:.2f} %", v) : std::string("n/a"); };
  std::string o = fmt::format("J1 {}  J2 {}  J3 {}  J4 {}  J5 {}  J6 {}  J7 {}  J8 {}  J9 {}",
                              std::isfinite(r.J1_ms) ? fmt::format("{:.1f} ms", r.J1_ms) : std::string("n/a"),
                              pct(r.J2_pct), pct(r.J3_pct), pct(r.J4_pct), pct(r.J5_pct), pct(r.J6_pct),
                              pct(r.J7_pct), pct(r.J8_pct), pct(r.J9_pct));
  // Say which floors J6-J9 are unless they are the benchmark's (floors 2 and 3).
  if (!(floors.size() == 2 && floors[0].floor == 2 && floors[1].floor == 3)) {
    std::string list;
    for (const FloorCriteria& f : r.floors)
      list += fmt::format("{}floor {}: {} / {}", list.empty() ? "" : "; ", f.floor, pct(f.std_pct), pct(f.max_pct));
    o += fmt::format("  (J6/J8, J7/J9 = the first two floors other than the actuator's; std / max per floor: {})",
                     list.empty() ? std::string("none") : list);
  }
  return o;
}

BenchmarkCriteria BenchmarkCriteriaFrom(const BenchmarkSignals& s) {
  if (!(s.dt_s > 0.0) || !std::isfinite(s.dt_s))
    throw Error(kWhere, fmt::format("dt_s = {} s is out of range (0, inf)", s.dt_s));
  const std::size_t floors = s.x_r.size();
  if (floors == 0) throw Error(kWhere, "x_r has no floor");
  if (s.x_n.size() != floors)
    throw Error(kWhere, fmt::format("x_n has {} floors and x_r {}: they must match", s.x_n.size(), floors));
  if (s.actuator_floor < 1 || s.actuator_floor > static_cast<int>(floors))
    throw Error(kWhere, fmt::format("actuator_floor = {} is out of range [1, {}]", s.actuator_floor, floors));
  const std::size_t n = s.x_m.size();
  if (n < kBenchmarkMinSamples)
    throw Error(kWhere, fmt::format("{} samples are too few (at least {}: J1 tries lags of up to {} samples)", n,
                                    kBenchmarkMinSamples, kBenchmarkMaxLag - 1));
  CheckRecord("x_m", s.x_m, n);
  CheckRecord("x_t", s.x_t, n);
  for (std::size_t i = 0; i < floors; ++i) {
    CheckRecord(fmt::format("x_n floor {}", i + 1), s.x_n[i], n);
    CheckRecord(fmt::format("x_r floor {}", i + 1), s.x_r[i], n);
  }
  const std::span<const double> xm(s.x_m), xt(s.x_t);
  const std::size_t a = static_cast<std::size_t>(s.actuator_floor - 1);

  BenchmarkCriteria c;
  // J1: x_m(j:N) against x_t(1:N-j+1), j = 1..50 (1-based): x_m lags x_t by j - 1 samples.
  double best = -std::numeric_limits<double>::infinity();
  c.lag_samples = -1;
  for (int j = 1; j <= kBenchmarkMaxLag; ++j) {
    const std::size_t lag = static_cast<std::size_t>(j - 1);
    const double rho = PearsonCorrelation(xm.subspan(lag), xt.first(n - lag));
    if (rho > best) {  // NaN never wins; a tie keeps the smaller lag
      best = rho;
      c.lag_samples = j - 1;
    }
  }
  c.J1_ms = c.lag_samples >= 0 ? 1e3 * c.lag_samples * s.dt_s : kNaN;
  std::tie(c.J2_pct, c.J3_pct) = Errors(xm, xt, "x_t (the target)");
  std::tie(c.J4_pct, c.J5_pct) = Errors(xm, s.x_r[a], fmt::format("x_r floor {} (the reference)", a + 1));
  for (std::size_t i = 0; i < floors; ++i) {
    if (i == a) continue;
    const auto [sd, mx] = Errors(s.x_n[i], s.x_r[i], fmt::format("x_r floor {} (the reference)", i + 1));
    c.floors.push_back({static_cast<int>(i + 1), sd, mx});
  }
  c.J6_pct = c.floors.size() > 0 ? c.floors[0].std_pct : kNaN;
  c.J7_pct = c.floors.size() > 1 ? c.floors[1].std_pct : kNaN;
  c.J8_pct = c.floors.size() > 0 ? c.floors[0].max_pct : kNaN;
  c.J9_pct = c.floors.size() > 1 ? c.floors[1].max_pct : kNaN;
  return c;
}

}  // namespace rths::signal
