// The README's "First steps" walk, run line by line as a new user would (after the install line,
// which CI has just run): a run with its report, an export to .mat, the .mat in GNU Octave, and a
// variant with --set and --compact. The lines are read from README.md, so the README cannot drift
// from what works.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scenario/scenario.h"
#include "udpm_support.h"
#include "test_support.h"

using rths_test::Slurp;

namespace {

namespace fs = std::filesystem;

/// The command lines of the README's walk block (between the walk markers, inside ```sh), with
/// their trailing comments removed.
std::vector<std::string> WalkLines() {
  const std::string readme = Slurp(fs::path(RTHS_SOURCE_DIR) / "README.md");
  const auto begin = readme.find("<!-- walk:begin");
  const auto end = readme.find("<!-- walk:end -->");
  REQUIRE(begin != std::string::npos);
  REQUIRE(end != std::string::npos);
  std::istringstream block(readme.substr(begin, end - begin));
  std::vector<std::string> lines;
  for (std::string line; std::getline(block, line);) {
    if (line.rfind("```", 0) == 0 || line.rfind("<!--", 0) == 0 || line.empty()) continue;
    if (const auto c = line.find("  # "); c != std::string::npos) line = line.substr(0, c);
    while (!line.empty() && line.back() == ' ') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

/// Runs `line` in `cwd` with ./rths and examples/ pointing into the source tree; output in *out.
int RunLine(std::string line, const fs::path& cwd, std::string* out) {
  const std::string src = RTHS_SOURCE_DIR;
  line = std::regex_replace(line, std::regex(R"(\./rths )"), src + "/rths ");
  line = std::regex_replace(line, std::regex("'examples/"), "'" + src + "/examples/");
  const fs::path txt = cwd / "out.txt";
  const std::string cmd = "cd '" + cwd.string() + "' && RTHS_BIN_DIR='" + RTHS_BIN_DIR + "' " + line + " > " +
                          txt.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  *out = Slurp(txt);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}


}  // namespace

TEST_CASE("README first steps: run + report, export, Octave, a --set variant, the two compared") {
  const std::vector<std::string> lines = WalkLines();
  REQUIRE(lines.size() == 6);
  CHECK(lines[0] == "bash scripts/bootstrap.sh");  // the install, which CI has run already
  if (!rths_test::UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const fs::path cwd = rths_test::TempDir("readme_walk");
  std::string out;

  // 2. The default scenario with its report.
  INFO(lines[1]);
  REQUIRE_MESSAGE(RunLine(lines[1], cwd, &out) == 0, out);
  const fs::path first = cwd / "runs" / "first";
  CHECK(out.find("report: ") != std::string::npos);
  const std::string html = Slurp(first / "report.html");
  const auto summary = nlohmann::json::parse(Slurp(first / "summary.json"));
  const double nrmse = summary["tracking_nrmse_pct"].get<double>();
  CHECK(html.find(fmt::format("{:.4g}", nrmse)) != std::string::npos);
  int figures = 0;
  for (const auto& e : fs::directory_iterator(first / "figures")) {
    if (e.path().extension() == ".png") {
      ++figures;
      CHECK(fs::file_size(e.path()) > 10000);
    }
  }
  CHECK(figures >= 5);

  // 3. The export.
  INFO(lines[2]);
  REQUIRE_MESSAGE(RunLine(lines[2], cwd, &out) == 0, out);
  CHECK(fs::file_size(first / "export.mat") > 100000);

  // 4. The .mat in Octave: the example prints Eq. 31 as rths run does.
  rths_test::RequireTool("octave-cli", "octave");
  INFO(lines[3]);
  CHECK_MESSAGE(RunLine(lines[3], cwd, &out) == 0, out);
  CHECK_MESSAGE(out.find(fmt::format("tracking error     {:.3f} %", nrmse)) != std::string::npos, out);

  // 5. The variant: --set takes, --compact leaves out signals.csv, and no compensation tracks worse.
  INFO(lines[4]);
  REQUIRE_MESSAGE(RunLine(lines[4], cwd, &out) == 0, out);
  const fs::path none = cwd / "runs" / "none";
  CHECK(fs::exists(none / "report.html"));
  CHECK_FALSE(fs::exists(none / "signals.csv"));
  CHECK(rths::scenario::LoadScenario((none / "scenario.toml").string()).controller.kind ==
        rths::control::ControllerKind::kNone);
  const auto summary_none = nlohmann::json::parse(Slurp(none / "summary.json"));
  CHECK(summary_none["tracking_nrmse_pct"].get<double>() > 5 * nrmse);

  // 6. The two side by side: the keys that differ (the controller, and what --compact set), both
  // Eq. 31 values, four figures.
  INFO(lines[5]);
  REQUIRE_MESSAGE(RunLine(lines[5], cwd, &out) == 0, out);
  CHECK(out.find("scenario keys that differ: controller.kind, run.csv_every") != std::string::npos);
  const std::string cmp = Slurp(cwd / "runs" / "first_vs_none" / "compare.html");
  CHECK(cmp.find(fmt::format("{:.4g} %", nrmse)) != std::string::npos);
  CHECK(cmp.find(fmt::format("{:.4g} %", summary_none["tracking_nrmse_pct"].get<double>())) != std::string::npos);
  int compare_figures = 0;
  for (const auto& e : fs::directory_iterator(cwd / "runs" / "first_vs_none" / "figures")) {
    compare_figures += e.path().extension() == ".png" ? 1 : 0;
  }
  CHECK(compare_figures == 4);
}
