// `rths reproduce table2 --extended` (lib/studies/table2_extended.cpp; docs/reproduce_table2.md):
// the pi_lead design rule checked on the design model independently of the code that chose it;
// a --quick extended run's table (every condition x band x controller, finite numbers or a stop
// reason, the Table 2 rows it reuses equal to table2.csv's); the paper's 36 rows and their files
// the same with and without --extended; a run the safety monitor stops is a row, not an error.
#include <doctest/doctest.h>

#include <charconv>
#include <cmath>
#include <complex>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "control/analysis.h"
#include "control/lti.h"
#include "control/lti_controller.h"
#include "io/csv.h"
#include "studies/table2.h"
#include "scenario/scenario.h"
#include "test_support.h"

using namespace rths::studies;
using rths_test::TempDir;
using rths_test::Slurp;
using rths_test::Number;
namespace fs = std::filesystem;
namespace control = rths::control;

namespace {

constexpr double kDt = 0.0005;  // Table 2's step

/// table2.md without its "Made by ... on <date>" line (the only line that differs between runs).
std::string WithoutStamp(const std::string& md) {
  std::istringstream in(md);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.rfind("Made by ", 0) == 0) continue;
    out += line + "\n";
  }
  return out;
}

control::ControllerLti Linearized(const control::LtiConfig& cfg) {
  return control::LtiController(control::MakeLtiDesign(cfg, kDt)).Linearize(0.0);
}

/// The PI (Tustin) with the phase margin pm_deg at f_hz on g, solved here from |L| = 1,
/// arg L = -180 + pm at f (the phase unwrapped from 0.1 Hz).
std::pair<double, double> PiWithMargin(const control::DiscreteSs& g, double f_hz, double pm_deg) {
  constexpr double pi = std::numbers::pi;
  double theta = std::arg(g.Response(0.1));
  const int n = 20000;
  for (int i = 1; i <= n; ++i) {
    const double f0 = 0.1 + (f_hz - 0.1) * (i - 1) / n, f1 = 0.1 + (f_hz - 0.1) * i / n;
    theta += std::arg(g.Response(f1) / g.Response(f0));
  }
  const double phc = -pi + pm_deg * pi / 180 - theta;
  const double mag = std::abs(g.Response(f_hz));
  const double h = 0.5 * kDt / std::tan(pi * f_hz * kDt);
  return {std::cos(phc) / mag, -std::sin(phc) / (mag * h)};
}

const std::vector<std::string> kConditions{"0.0A", "2.5A", "pulse"};
const std::vector<std::string> kBands{"0-5", "0-15"};
const std::vector<std::string> kControllers{"none", "ff", "ff_lqg", "ats", "ambc", "pi_lead"};

}  // namespace

TEST_CASE("pi_lead: the design rule gives a stable loop with the stated margin on the design model") {
  const auto avg = rths::models::ServoPreset("avg");
  const PiLeadDesign d = DesignPiLead(avg, kDt);
  MESSAGE(d.Describe());
  const control::DiscreteSs g = control::ServoZoh(avg, kDt);

  // The controller is an lti with C(s) = Kp + Ki/s and T(s) = k (s - zero)/(s - pole), by Tustin.
  REQUIRE(d.controller.kind == control::ControllerKind::kLti);
  CHECK(d.controller.lti.feedback.num == std::vector<double>{d.kp, d.ki});
  CHECK(d.controller.lti.feedback.den == std::vector<double>{1.0, 0.0});
  CHECK(d.controller.lti.reference.den == std::vector<double>{1.0, -d.pole});
  CHECK(d.controller.lti.domain == control::TfDomain::kS);
  CHECK(d.controller.lti.discretisation == control::Discretisation::kTustin);
  CHECK(d.kp > 0.0);
  CHECK(d.ki > 0.0);

  // The PI loop alone (T = 1), analysed here: stable, one crossover with the stated 60 deg margin,
  // the peak sensitivity within its bound (Ms <= 2).
  control::LtiConfig pi_only = d.controller.lti;
  pi_only.reference = {};
  const control::ControllerLti pi = Linearized(pi_only);
  const control::LoopAnalysis loop = control::AnalyzeLoop(pi.fb, g);
  CHECK(loop.stable);
  CHECK(loop.spectral_radius < 1.0);
  REQUIRE(loop.crossovers.size() == 1);
  CHECK(loop.crossovers[0].phase_margin_deg == doctest::Approx(d.target_pm_deg).epsilon(0.5 / 60));
  CHECK(loop.crossovers[0].f_hz == doctest::Approx(d.pi_crossover_hz).epsilon(0.01));
  CHECK(loop.peak_sensitivity_db <= d.max_sensitivity_db + 0.05);
  CHECK(d.target_pm_deg == 60.0);
  CHECK(d.max_sensitivity_db == doctest::Approx(20 * std::log10(2.0)).epsilon(1e-3));
  // |L| = 1 at the crossover, from the discretised C and the ZOH model directly.
  const std::complex<double> l = -pi.fb.Response(d.pi_crossover_hz) * g.Response(d.pi_crossover_hz);
  CHECK(std::abs(l) == doctest::Approx(1.0).epsilon(1e-6));

  // "The largest Ki": a PI with the same margin at a crossover 2 % higher has a larger Ki but
  // breaks the sensitivity bound (here the bound is what stops the rule, not Ki's maximum).
  const auto [kp_hi, ki_hi] = PiWithMargin(g, 1.02 * d.pi_crossover_hz, d.target_pm_deg);
  CHECK(ki_hi > d.ki);
  control::LtiConfig pi_hi = pi_only;
  pi_hi.feedback = {{kp_hi, ki_hi}, {1.0, 0.0}};
  CHECK(control::AnalyzeLoop(Linearized(pi_hi).fb, g).peak_sensitivity_db > d.max_sensitivity_db);
  // and the rule's own PI solves to the same gains at its crossover.
  const auto [kp_here, ki_here] = PiWithMargin(g, d.pi_crossover_hz, d.target_pm_deg);
  CHECK(kp_here == doctest::Approx(d.kp).epsilon(1e-4));
  CHECK(ki_here == doctest::Approx(d.ki).epsilon(1e-4));

  // The lead: the benchmark's formulas, T(0) = 1, and its low-frequency advance equal to the PI
  // loop's lag, so that the whole controller leaves (almost) no lag at 1 Hz on the design model.
  const double pi_lag = control::TrackingLagS(pi, g, 1.0);
  CHECK(1e3 * pi_lag == doctest::Approx(d.pi_lag_ms).epsilon(1e-9));
  CHECK(d.phi_deg == doctest::Approx(loop.critical.phase_margin_deg + 5.0).epsilon(1e-3));
  const double s = std::sin(d.phi_deg * std::numbers::pi / 180);
  CHECK(d.a == doctest::Approx((1 + s) / (1 - s)).epsilon(1e-12));
  CHECK(d.k == doctest::Approx(d.a * d.fac).epsilon(1e-12));
  CHECK(d.fac == 2.0);
  CHECK(d.pole == doctest::Approx(-d.fac / d.tl_s).epsilon(1e-12));
  CHECK(d.zero == doctest::Approx(-1.0 / (d.a * d.tl_s)).epsilon(1e-12));
  CHECK(d.w_m_rad_s == doctest::Approx(1.0 / (d.tl_s * std::sqrt(d.a))).epsilon(1e-12));
  CHECK(d.k * d.zero / d.pole == doctest::Approx(1.0).epsilon(1e-12));                   // T(0) = 1
  CHECK(d.a * d.tl_s - d.tl_s / d.fac == doctest::Approx(pi_lag).epsilon(1e-9));         // the advance
  const control::ControllerLti whole = Linearized(d.controller.lti);
  CHECK(std::abs(control::AnalyzeLoop(whole.fb, g).spectral_radius - loop.spectral_radius) < 1e-12);  // T is outside the loop
  CHECK(std::abs(control::TrackingLagS(whole, g, 1.0)) < 0.05e-3);
  CHECK(std::abs(control::TrackingResponse(whole, g, 1.0)) == doctest::Approx(1.0).epsilon(0.01));
  REQUIRE(d.check_hz.size() == 4);
  CHECK(d.gyr_lag_ms[0] == doctest::Approx(1e3 * control::TrackingLagS(whole, g, 1.0)).epsilon(1e-9));
}

TEST_CASE("table2 --quick --extended: every condition x band x controller; the paper's rows unchanged") {
  const auto dir = TempDir("table2_extended");
  ReproduceOptions plain;
  plain.out_dir = dir / "plain";
  plain.quick = true;
  plain.jobs = 2;
  const Table2Result a = ReproduceTable2(plain);
  ReproduceOptions ext = plain;
  ext.out_dir = dir / "extended";
  ext.extended = true;
  const Table2Result b = ReproduceTable2(ext);
  MESSAGE("table2 --quick: " << a.wall_s << " s; with --extended: " << b.wall_s << " s");

  // --- the paper's 36 rows and their files: the same with and without --extended ---
  CHECK(a.extended.empty());
  CHECK(!a.pi_lead.has_value());
  CHECK(!fs::exists(plain.out_dir / "table2_extended.csv"));
  CHECK(Slurp(plain.out_dir / "table2.csv") == Slurp(ext.out_dir / "table2.csv"));
  CHECK(WithoutStamp(Slurp(plain.out_dir / "table2.md")) == WithoutStamp(Slurp(ext.out_dir / "table2.md")));
  REQUIRE(a.rows.size() == 36);
  REQUIRE(b.rows.size() == 36);
  for (std::size_t i = 0; i < 36; ++i) {
    CHECK(a.rows[i].controller == b.rows[i].controller);
    CHECK(a.rows[i].ours_pct == b.rows[i].ours_pct);  // bit for bit
  }
  std::size_t runs_a = 0, runs_b = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(plain.out_dir / "runs")) ++runs_a;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(ext.out_dir / "runs")) ++runs_b;
  CHECK(runs_a == 36);
  CHECK(runs_b == 36 + 18);  // none, ff, ff_lqg are Table 2's runs

  // --- table2_extended.csv: exact header, 36 rows in order ---
  const auto csv = rths::io::ReadCsvFile(ext.out_dir / "table2_extended.csv");
  REQUIRE(csv.size() == 37);
  CHECK(csv[0] == std::vector<std::string>{"condition", "band_hz", "controller", "table2_row", "ours_pct",
                                           "second_half_pct", "peak_error_mm", "steps", "steps_planned", "stopped",
                                           "a0", "a1_s", "a2_s2", "a3_s3", "adapt_start_s"});
  std::map<std::string, std::string> table2;  // "cond|controller|band" -> ours_pct of table2.csv
  for (const auto& row : rths::io::ReadCsvFile(ext.out_dir / "table2.csv")) {
    if (row.size() == 5) table2[row[0] + "|" + row[1] + "|" + row[2]] = row[4];
  }
  std::size_t i = 1;
  for (const auto& cond : kConditions) {
    for (const auto& band : kBands) {
      for (const auto& name : kControllers) {
        REQUIRE(i < csv.size());
        const auto& row = csv[i++];
        REQUIRE(row.size() == 15);
        CHECK(row[0] == cond);
        CHECK(row[1] == band);
        CHECK(row[2] == name);
        const bool reused = name == "none" || name == "ff" || name == "ff_lqg";
        CHECK(row[3].empty() == !reused);
        const bool stopped = row[9] != "no";
        CHECK(!row[9].empty());
        for (int c : {4, 5, 6}) {
          const double v = Number(row[c]);
          CHECK_MESSAGE((stopped || (std::isfinite(v) && v >= 0.0)), cond, " ", band, " ", name, " column ", c, ": ",
                        row[c]);
        }
        if (!stopped) CHECK(row[7] == row[8]);  // every step
        if (reused) {  // the very number of table2.csv (same run, same Eq. 31)
          CHECK_MESSAGE(row[4] == table2.at(cond + "|" + row[3] + "|" + band), cond, " ", band, " ", name);
        }
        const int n_coef = name == "ats" ? 3 : name == "ambc" ? 4 : 0;
        for (int c = 0; c < 4; ++c) {
          if (c < n_coef && !stopped) {
            CHECK_MESSAGE(std::isfinite(Number(row[10 + c])), name, " a", c);
          } else if (c >= n_coef) {
            CHECK(row[10 + c].empty());
          }
        }
      }
    }
  }
  REQUIRE(b.extended.size() == 36);
  REQUIRE(b.pi_lead.has_value());
  // In this run (physical plant, defaults) nothing stops: every number is finite.
  for (const auto& r : b.extended) {
    CHECK_MESSAGE(r.stopped == "no", r.condition, " ", r.band, " ", r.controller, ": ", r.stopped);
    CHECK(std::isfinite(r.ours_pct));
  }

  // --- the new runs ran what the table says ---
  for (const auto& cond : kConditions) {
    const auto ctrls = Table2ExtendedControllers(cond, *b.pi_lead);
    for (const auto& band : kBands) {
      for (const auto& c : ctrls) {
        if (!c.table2_row.empty()) continue;
        const fs::path run = ext.out_dir / "runs" / Slug(cond + " " + band + "hz " + c.name);
        const auto s = rths::scenario::LoadScenario((run / "scenario.toml").string());
        CHECK(s.controller == c.controller);
        if (c.name == "ats") CHECK(s.controller.ats == control::AtsConfig{});
        if (c.name == "ambc") {
          CHECK(s.controller.ambc.start == control::AmbcStart::kModel);
          CHECK(s.controller.model.name == (cond == "pulse" ? "avg" : cond));  // the G_FF row's model
          control::AmbcConfig defaults;
          CHECK(s.controller.ambc.gain_log10 == defaults.gain_log10);
        }
        if (c.name == "pi_lead") CHECK(s.controller.lti == b.pi_lead->controller.lti);
      }
    }
  }

  const std::string md = Slurp(ext.out_dir / "table2_extended.md");
  CHECK(md.find("rths reproduce table2 --quick --extended --plant physical") != std::string::npos);
  CHECK(md.find(b.pi_lead->Describe()) != std::string::npos);
  for (const auto& name : kControllers) CHECK(md.find("| 0.0A | " + name + " |") != std::string::npos);
}

TEST_CASE("table2 --extended: a run the safety monitor stops is a row with its reason") {
  // An unstable pi_lead (feedback 40 + 0/s: far past the loop's gain margin); the key is read by
  // every scenario but used by the lti rows only, so Table 2's rows run as usual.
  const auto dir = TempDir("table2_extended_stop");
  ReproduceOptions opts;
  opts.out_dir = dir / "out";
  opts.quick = true;
  opts.plant = "linear";
  opts.extended = true;
  opts.overrides = {"controller.lti.feedback={num=[40.0,0.0],den=[1.0,0.0]}"};
  const Table2Result r = ReproduceTable2(opts);
  REQUIRE(r.extended.size() == 36);
  const auto csv = rths::io::ReadCsvFile(opts.out_dir / "table2_extended.csv");
  REQUIRE(csv.size() == 37);
  int stopped = 0;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    const auto& row = csv[i];
    if (row[2] != "pi_lead") {
      CHECK(row[9] == "no");
      continue;
    }
    ++stopped;
    CHECK_MESSAGE(row[9].find("safety") != std::string::npos, row[9]);
    CHECK(Number(row[7]) < Number(row[8]));  // it stopped early
  }
  CHECK(stopped == 6);
  const std::string md = Slurp(opts.out_dir / "table2_extended.md");
  CHECK(md.find("safety") != std::string::npos);
}
