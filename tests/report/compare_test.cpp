// lib/report/compare_page + rths-compare (docs/compare.md): the scenario keys that differ, a page
// comparing three memq runs (one a shorter run of another controller), its figures and table, and
// the tool's refusals.
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "report/compare_page.h"
#include "plot_data.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths_test::RunCli;
using rths_test::Slurp;
using rths_test::TempDir;

namespace {

/// A compact memq run of the default scenario with `sets`; its folder.
fs::path MakeRun(const fs::path& dir, const std::string& name, const std::string& sets) {
  const fs::path out = dir / name;
  std::string output;
  const int code = RunCli(std::string(RTHS_SOURCE_DIR) + "/scenarios/default.toml --transport memq --compact --quiet "
                          "--skip-space-check --set run.duration_s=1 " + sets + " --out " + out.string(), &output);
  REQUIRE_MESSAGE(code == 0, output);
  return out;
}

int Compare(const std::string& args, std::string* output) {
  const fs::path txt = fs::temp_directory_path() / fmt::format("rths_compare_{}.txt", ::getpid());
  const int status = std::system((std::string(RTHS_BIN_DIR) + "/rths-compare " + args + " > " + txt.string() + " 2>&1").c_str());
  *output = Slurp(txt);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("scenario keys: flattened, and those that differ between texts (or some lack)") {
  const std::string a = "[run]\nname = \"a\"\ndt_s = 0.0005\n[plant.damper]\nc0_a = 21.0\nlist = [1, 2]\n";
  const std::string b = "[run]\nname = \"a\"\ndt_s = 0.001\n[plant.damper]\nc0_a = 21.0\nlist = [1, 3]\nextra = true\n";
  const auto flat = rths::scenario::FlattenScenario(a);
  REQUIRE(flat.size() == 4);
  CHECK(flat[0].key == "plant.damper.c0_a");
  CHECK(flat[0].value == "21.0");
  CHECK(rths::report::DifferingKeys({a, a}).empty());
  CHECK(rths::report::DifferingKeys({a, b}) ==
        std::vector<std::string>{"plant.damper.list", "run.dt_s", "plant.damper.extra"});
  CHECK(rths::scenario::FlattenScenario("not toml [").empty());
  // Floats as the shortest text that reads back (toml++ alone writes 0.00080000000000000004).
  const auto f = rths::scenario::FlattenScenario("x = 0.0008\ny = [0.1, 2.0, 3]\nz = 1e-9\n");
  REQUIRE(f.size() == 3);
  CHECK(f[0].value == "0.0008");
  CHECK(f[1].value == "[ 0.1, 2.0, 3 ]");
  CHECK(std::stod(f[2].value) == 1e-9);
  CHECK(f[2].value.size() <= 5);
}

TEST_CASE("rths compare: three runs in one page, aligned by step over the steps they all have") {
  const fs::path dir = TempDir("compare");
  const fs::path ff = MakeRun(dir, "ff", "");
  const fs::path none = MakeRun(dir, "none", "--set controller.kind=none");
  const fs::path shorter = MakeRun(dir, "lqg_short", "--set controller.kind=ff_lqg --set run.duration_s=0.5");

  std::string output;
  const fs::path out = dir / "cmp";
  REQUIRE_MESSAGE(Compare(fmt::format("{} {} {} --out {}", ff.string(), none.string(), shorter.string(), out.string()),
                          &output) == 0,
                  output);
  CHECK(output.find("3 runs over 1000 common steps") != std::string::npos);
  CHECK(output.find("scenario keys that differ: controller.kind, run.duration_s") != std::string::npos);
  const std::string html = Slurp(out / "compare.html");
  for (const char* fig : {"compare_histories", "compare_error", "compare_loops", "compare_spectra"}) {
    CAPTURE(fig);
    CHECK(fs::file_size(out / "figures" / (std::string(fig) + ".png")) > 10000);
    CHECK(html.find(std::string("figures/") + fig + ".png") != std::string::npos);
  }
  // The table quotes each run's own Eq. 31 value, and the differing keys with their values.
  for (const fs::path& run : {ff, none, shorter}) {
    const auto summary = nlohmann::json::parse(Slurp(run / "summary.json"));
    CHECK(html.find(fmt::format("{:.4g} %", summary["tracking_nrmse_pct"].get<double>())) != std::string::npos);
  }
  CHECK(html.find("<code>controller.kind</code></th><td><code>&#39;ff&#39;</code></td><td><code>&#39;none&#39;</code>"
                  "</td><td><code>&#39;ff_lqg&#39;</code></td>") != std::string::npos);
  CHECK(html.find("1000 of 1000 (0.5 s)") != std::string::npos);

  // The same run twice: no differences; the default folder is beside the first run.
  REQUIRE(Compare(fmt::format("{} {}", ff.string(), ff.string()), &output) == 0);
  CHECK(output.find("the scenarios are the same, key by key") != std::string::npos);
  CHECK(fs::exists(dir / "compare-ff-ff" / "compare.html"));
  CHECK(Slurp(dir / "compare-ff-ff" / "compare.html").find("ff (2)") != std::string::npos);

  // Refusals (exit 2): one run, an output folder that is not empty, a folder that is not a run,
  // labels that are not one per run.
  CHECK(Compare(ff.string(), &output) == 2);
  CHECK(Compare(fmt::format("{} {} --out {}", ff.string(), none.string(), out.string()), &output) == 2);
  CHECK(output.find("not empty") != std::string::npos);
  CHECK(Compare(fmt::format("{} {} --out {}", ff.string(), dir.string(), (dir / "x").string()), &output) == 2);
  CHECK(output.find("log.lcm") != std::string::npos);
  CHECK(Compare(fmt::format("{} {} --labels a --out {}", ff.string(), none.string(), (dir / "y").string()), &output) == 2);
  CHECK(output.find("1 labels for 2 runs") != std::string::npos);
}

TEST_CASE("rths compare: runs with different steps are refused, naming both") {
  const fs::path dir = TempDir("compare_dt");
  const fs::path a = MakeRun(dir, "a", "");
  const fs::path b = MakeRun(dir, "b", "--set run.dt_s=0.001");
  std::string output;
  CHECK(Compare(fmt::format("{} {} --out {}", a.string(), b.string(), (dir / "c").string()), &output) == 2);
  CHECK(output.find("must share dt") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "c" / "compare.html"));
}

TEST_CASE("rths compare: benchmark runs show their J1-J9, in the terminal and on the page") {
  const fs::path dir = TempDir("compare_benchmark");
  std::vector<fs::path> runs;
  for (const char* kind : {"lti", "ff_lqg"}) {
    const fs::path out = dir / kind;
    std::string output;
    REQUIRE_MESSAGE(RunCli(std::string(RTHS_SOURCE_DIR) + "/scenarios/benchmark/case2_example.toml --transport memq "
                           "--skip-space-check --set controller.kind=" + kind + " --out " + out.string(),
                           &output) == 0,
                    output);
    runs.push_back(out);
  }
  std::string output;
  const fs::path out = dir / "cmp";
  REQUIRE_MESSAGE(Compare(fmt::format("{} {} --labels example,ff_lqg --out {}", runs[0].string(), runs[1].string(),
                                      out.string()),
                          &output) == 0,
                  output);
  CAPTURE(output);
  // The example controller's documented row (docs/benchmark.md), and the ff_lqg run's own.
  CHECK(output.find("  example: J1 4.6 ms  J2 9.78 %  J3 10.94 %") != std::string::npos);
  CHECK(output.find("  ff_lqg: J1 ") != std::string::npos);
  const std::string html = Slurp(out / "compare.html");
  CHECK(html.find("<th>benchmark J2</th><td>9.78 %</td>") != std::string::npos);
  CHECK(html.find("<th>benchmark J9</th>") != std::string::npos);
}

TEST_CASE("rths compare: figures a reviewer can read (loops, differences, drawing order, legends)") {
  // Three benchmark runs of case 2 (its spring specimen and sensor noise), the worst given last.
  const fs::path dir = TempDir("compare_reviewer");
  const std::vector<std::string> kinds = {"ff_lqg", "ff", "lti"};
  std::vector<fs::path> runs;
  for (const auto& kind : kinds) {
    const fs::path out = dir / kind;
    std::string output;
    REQUIRE_MESSAGE(RunCli(std::string(RTHS_SOURCE_DIR) + "/scenarios/benchmark/case2_example.toml --transport memq "
                           "--skip-space-check --set run.duration_s=12 --set controller.kind=" + kind + " --out " +
                           out.string(),
                           &output) == 0,
                    output);
    runs.push_back(out);
  }
  std::string output;
  const fs::path out = dir / "cmp";
  REQUIRE_MESSAGE(Compare(fmt::format("{} {} {} --out {}", runs[0].string(), runs[1].string(), runs[2].string(),
                                      out.string()),
                          &output) == 0,
                  output);
  const fs::path figs = out / "figures";
  std::vector<double> peak_e;
  std::vector<std::vector<double>> y;
  for (const auto& r : runs) {
    const auto d = rths::report::LoadRunData(r);
    double p = 0;
    for (double e : d.signals.At("e_mm").values) p = std::max(p, std::abs(e));
    peak_e.push_back(p);
    y.push_back(d.signals.At("y_mm").values);
  }
  REQUIRE(peak_e[2] > peak_e[1]);
  REQUIRE(peak_e[1] > peak_e[0]);

  // Force-velocity: the velocity is y's low-passed derivative, not its central difference, whose
  // sensor noise (0.016 mm at 4096 Hz: 46 mm/s RMS) made the loop a cloud. A smooth curve changes
  // little from one drawn point to the next; noise changes by its whole size.
  const auto loops = rths_test::ReadPlotData(figs / "compare_loops.dat");
  const auto fv = rths_test::PanelCurves(loops, 2);
  REQUIRE(fv.size() == 3);
  for (const auto& c : fv) {
    CAPTURE(c.title);
    double ss = 0, sd = 0;
    for (std::size_t i = 1; i < c.x.size(); ++i) ss += c.x[i] * c.x[i], sd += std::pow(c.x[i] - c.x[i - 1], 2);
    CHECK(std::sqrt(sd / ss) < 0.3);
  }
  CHECK(Slurp(figs / "compare_loops.gp").find("y'' [mm/s] (low-passed at 50 Hz)") != std::string::npos);

  // The worst run is drawn first (beneath), the best last, in every overlay.
  for (const char* fig : {"compare_error", "compare_loops"}) {
    CAPTURE(fig);
    const auto first = rths_test::PanelCurves(rths_test::ReadPlotData(figs / (std::string(fig) + ".dat")), 1);
    REQUIRE(first.size() == 3);
    CHECK(first[0].title == "lti");
    CHECK(first[1].title == "ff");
    CHECK(first[2].title == "ff_lqg");
  }

  // Histories: each other run's y and f minus the first run's, on their own axes; the difference
  // of y keeps its peak (min/max decimation).
  const auto hist = rths_test::ReadPlotData(figs / "compare_histories.dat");
  const auto dy = rths_test::PanelCurves(hist, 2);
  REQUIRE(dy.size() == 2);
  CHECK(dy[0].title == "lti");
  double peak_dy = 0;
  for (std::size_t k = 0; k < y[0].size() && k < y[2].size(); ++k)
    peak_dy = std::max(peak_dy, std::abs(y[2][k] - y[0][k]));
  double drawn = 0;
  for (double v : dy[0].y) drawn = std::max(drawn, std::abs(v));
  CHECK(drawn == doctest::Approx(peak_dy).epsilon(1e-6));
  REQUIRE(rths_test::PanelCurves(hist, 4).size() == 2);
  const std::string hist_gp = Slurp(figs / "compare_histories.gp");
  CHECK(hist_gp.find("difference [kN]") != std::string::npos);

  // Legends: small, and once per figure (a run has one colour in every panel), again only where a
  // panel adds an entry (the zoom's r).
  auto keys = [](const std::string& gp) {
    int on = 0;
    for (std::size_t at = gp.find("set key on"); at != std::string::npos; at = gp.find("set key on", at + 1)) {
      ++on;
      CHECK(gp.substr(at, gp.find('\n', at) - at).find("font ',9'") != std::string::npos);
    }
    return on;
  };
  CHECK(keys(hist_gp) == 1);
  CHECK(keys(Slurp(figs / "compare_loops.gp")) == 1);
  CHECK(keys(Slurp(figs / "compare_spectra.gp")) == 1);  // r and the runs over y's; e's adds none
  CHECK(keys(Slurp(figs / "compare_error.gp")) == 2);    // the runs over e; the zoom adds r
}
