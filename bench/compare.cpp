// bench-compare: this checkout against another checkout of rths (a commit before a change), side by
// side in one invocation, because absolute times drift on shared machines: the default run's
// steps/s on udpm (one port, and a port per channel where both checkouts have it) and on memq,
// and the wall time of the full reproductions (Fig. 9, Table 2 by default). Every pair runs back
// to back, the two checkouts alternating which goes first, repeated; it prints medians and the
// median of per-pair speed-ups (this checkout's rate over the other's, the other's time over this one's). The reproductions' tables of the two checkouts are then
// compared cell by cell: identical, or how far apart.
//
//   build/bin/bench-compare --other DIR [--repeat N] [--seconds S] [--studies fig9,table2] [--out DIR]
//
// --studies also takes NAME:quick (`rths reproduce NAME --quick`, e.g. benchmark:quick) and `sweep`
// (`rths sweep` of chunk 0 of 40 of scenarios/sweeps/benchmark_mc.toml: 80 runs spread over the four
// cases and eight controllers; its table compared with the timing columns masked).
//
// --outputs: is the behaviour unchanged? The same commands run in both checkouts, into OUT/this and
// OUT/other (cwd), and EVERY file they wrote is compared (bench/compare_outputs.h):
//   - rths reproduce fig5 fig6 fig7 fig8 table2 fig9 fig11 benchmark, and table2 --extended
//     (--quick unless --full);
//   - rths design S --out S.json for every scenarios/**/*.toml (and its stdout);
//   - scripts/real_data_study.sh real_data (rths utfsm-convert, identify, diagnose on data/utfsm);
//   - rths run scenarios/rig_mode_example.toml (memq) twice: A as shipped (desired seed 3, noise
//     seed 7), B with desired seed 4 and noise seed 8; rths record both; rths diagnose --train A
//     --test B (the rig's unmodelled delay and damper scale, found on one seed, tested on another).
// Each command's stdout, stderr and exit code are files too (NAME.stdout, .stderr, .rc). Files are
// compared byte for byte; where they differ: log.lcm with `rths log compare` (payload per
// (channel, k), run_id aside); JSON with the volatile keys masked (VolatileKeys: run_id, wall_s,
// stepping_s, steps_per_s); text (CSV, Markdown, HTML, TOML, stdout) line by line with only the
// differing lines masked: the two sides' folders (<ROOT>, <OUT>), "Made by ... on <date>" lines,
// timestamps and wall-time phrases (TextMasks). PNG and other binaries: byte for byte. The masks
// are what differs between two runs of the same commit: `--other .` runs this checkout twice.
// It prints one line per file class and the verdict (identical, identical after masking with the
// masks used, different with the first differing line, on one side only); exit 0 only if nothing
// differs and no file is on one side only.
//
//   build/bin/bench-compare --outputs --other DIR [--full] [--only reproduce,design,real_data,rig]
//       [--out DIR] [--no-run] [--other-set "--set KEY=VALUE"] [--this DIR] [--side both|this|other]
//
// --no-run compares OUT/this and OUT/other as they are (e.g. after doctoring a file); --other-set
// adds arguments to the other side's reproduce, design and rig runs (to see a difference caught);
// --this takes another built checkout as this side (e.g. --this D --other D: one commit twice).
// --side this|other runs one side only and compares with the other side's folder as it is (the
// older checkout's outputs made once, while the change is still being built).
//
// DIR is a built checkout (its ./rths and build/bin), e.g.
//   git worktree add --detach /tmp/old COMMIT && cmake -S /tmp/old -B /tmp/old/build -G Ninja
//     -DCMAKE_BUILD_TYPE=RelWithDebInfo && cmake --build /tmp/old/build   (one command)
#include <sys/wait.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "compare_outputs.h"
#include "signal/stats.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

using rths::signal::Median;  // timings: the middle one, or the mean of the two middle ones

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `cmd` (output to `log`); its wall time [s], or a negative value if it exited with a code
/// above `max_ok_exit` (or was killed).
double Timed(const std::string& cmd, const fs::path& log, int max_ok_exit = 0) {
  const auto t0 = Clock::now();
  const int status = std::system((cmd + " > " + Quote(log.string()) + " 2>&1").c_str());
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  return WIFEXITED(status) && WEXITSTATUS(status) <= max_ok_exit ? s : -1.0;
}

/// One measurement kind: a command per checkout and what to read from it.
struct Kind {
  std::string name;
  std::string args;  ///< after `rths`
  bool run = true;   ///< a `rths run` (steps/s from summary.json); else a study (wall time)
  std::string table; ///< study: the table file to compare
  int max_ok_exit = 0;  ///< a sweep exits 1 when some of its runs stopped (the table is written)
};

struct Sample {
  std::vector<double> mine, other, ratio;  ///< steps/s (run) or seconds (study); ratio this/other
};

double Measure(const fs::path& tree, const Kind& k, const fs::path& out) {
  fs::remove_all(out);
  std::string args = k.args;  // "{tree}" stands for the checkout's own folder
  for (std::size_t at; (at = args.find("{tree}")) != std::string::npos;) args.replace(at, 6, tree.string());
  const std::string cmd = fmt::format("{} {} --out {}", Quote((tree / "rths").string()), args, Quote(out.string()));
  const double wall = Timed(cmd, out.string() + ".log", k.max_ok_exit);
  if (wall < 0) return -1.0;
  if (!k.run) return wall;
  std::ifstream in(out / "summary.json");
  const auto j = nlohmann::json::parse(in, nullptr, false);
  return j.is_discarded() ? -1.0 : j.value("steps_per_s", -1.0);
}

/// Cells of a CSV file.
std::vector<std::vector<std::string>> Cells(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

/// "identical", or how the two tables differ.
std::string CompareTables(const fs::path& a, const fs::path& b) {
  if (!fs::exists(a) || !fs::exists(b)) return "missing";
  auto ra = Cells(a), rb = Cells(b);
  // A sweep's timing columns differ from run to run, and its scenario_sha256 from checkout to
  // checkout (each run's scenario names the data files under its own checkout): masked.
  int masked = 0;
  for (std::size_t j = 0; !ra.empty() && j < ra[0].size(); ++j) {
    const std::string& name = ra[0][j];
    if (name.find("steps_per_s") == std::string::npos && name.find("wall_s") == std::string::npos &&
        name != "scenario_sha256")
      continue;
    ++masked;
    for (auto* t : {&ra, &rb})
      for (auto& row : *t)
        if (j < row.size() && &row != &t->front()) row[j] = "";
  }
  const std::string note = masked ? fmt::format(" ({} timing or hash column(s) masked)", masked) : "";
  if (ra == rb) return "identical, cell for cell" + note;
  if (ra.size() != rb.size()) return fmt::format("different shapes: {} rows against {}", ra.size(), rb.size());
  int text = 0, numeric = 0;
  double max_abs = 0, max_rel = 0;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    if (ra[i].size() != rb[i].size()) return fmt::format("row {} has {} cells against {}", i, ra[i].size(), rb[i].size());
    for (std::size_t j = 0; j < ra[i].size(); ++j) {
      if (ra[i][j] == rb[i][j]) continue;
      char* ea = nullptr;
      char* eb = nullptr;
      const double x = std::strtod(ra[i][j].c_str(), &ea), y = std::strtod(rb[i][j].c_str(), &eb);
      if (*ea != '\0' || *eb != '\0' || ea == ra[i][j].c_str()) {
        ++text;
        continue;
      }
      ++numeric;
      max_abs = std::max(max_abs, std::abs(x - y));
      if (y != 0) max_rel = std::max(max_rel, std::abs(x - y) / std::abs(y));
    }
  }
  return fmt::format("{} numbers differ (largest difference {:.3g}, relative {:.3g}), {} text cells differ", numeric,
                     max_abs, max_rel, text);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-compare: this checkout against another (an older commit), side by side: run rates and "
               "reproduction wall times, and whether the reproductions' numbers are the same"};
  std::string other_dir, out_dir, studies = "fig9,table2";
  int repeat = 3;
  double seconds = 10.0;
  app.add_option("--other", other_dir, "the other checkout (built: its ./rths and build/bin)")->required();
  app.add_option("--repeat", repeat, "pairs of each measurement (medians printed)")->capture_default_str();
  app.add_option("--seconds", seconds, "simulated seconds of the default runs")->capture_default_str();
  app.add_option("--studies", studies,
                 "reproductions to time, comma-separated ('' for none); NAME:quick for `reproduce NAME --quick`; "
                 "'sweep' for a fortieth of scenarios/sweeps/benchmark_mc.toml (80 runs)")
      ->capture_default_str();
  app.add_option("--out", out_dir, "where the runs go (default: a temporary folder, removed)");
  bool outputs_mode = false;
  outputs::Options oo;
  app.add_flag("--outputs", outputs_mode, "compare every output file of the same commands in both checkouts");
  app.add_flag("--full", oo.full, "--outputs: reproductions without --quick");
  app.add_option("--only", oo.only, "--outputs: groups to run (reproduce,design,real_data,rig; default all)");
  app.add_flag("--no-run", [&](std::int64_t) { oo.run = false; }, "--outputs: compare OUT/this and OUT/other as they are");
  std::string this_dir;
  app.add_option("--this", this_dir, "--outputs: the checkout taken as this one (default: this program's)");
  app.add_option("--side", oo.side, "--outputs: run both sides, or only 'this' or 'other' (then compare)")
      ->capture_default_str();
  app.add_option("--other-set", oo.other_set, "--outputs: arguments for the other side's runs, e.g. \"--set K=V\"");
  CLI11_PARSE(app, argc, argv);

  const fs::path mine = fs::canonical(this_dir.empty() ? fs::read_symlink("/proc/self/exe").parent_path() / "../.."
                                                      : fs::path(this_dir));
  const fs::path other = fs::canonical(other_dir);
  const bool keep = !out_dir.empty();
  const fs::path tmp = keep ? fs::path(out_dir) : fs::temp_directory_path() / fmt::format("rths_bench_compare_{}", ::getpid());
  fs::create_directories(tmp);
  if (outputs_mode) {
    oo.mine = mine, oo.other = other, oo.out = fs::absolute(tmp);
    const auto t0 = Clock::now();
    const int code = outputs::Run(oo);
    std::printf("wall time %.0f s; outputs in %s\n", std::chrono::duration<double>(Clock::now() - t0).count(), tmp.c_str());
    return code;
  }

  const std::string set = fmt::format("--set run.duration_s={}", seconds);
  std::vector<Kind> kinds = {{"udpm, one port", "run " + set, true, ""},
                             {"udpm, port per channel", "run --port-per-channel " + set, true, ""},
                             {"memq", "run --transport memq " + set, true, ""}};
  std::stringstream ss(studies);
  for (std::string name; std::getline(ss, name, ',');) {
    if (name.empty()) continue;
    if (name == "sweep") {  // a fortieth of the benchmark Monte Carlo SPEC: 80 runs over cases and controllers
      kinds.push_back({"sweep benchmark_mc 1/40", "sweep {tree}/scenarios/sweeps/benchmark_mc.toml --chunk 0 --chunks 40",
                       false, "table.csv", 1});
      continue;
    }
    const bool quick = name.size() > 6 && name.compare(name.size() - 6, 6, ":quick") == 0;
    const std::string study = quick ? name.substr(0, name.size() - 6) : name;
    kinds.push_back({"reproduce " + name, "reproduce " + study + (quick ? " --quick" : ""), false, study + ".csv"});
  }
  std::printf("bench-compare: %s (this) against %s (other), %d pairs each, alternating which runs first\n",
              mine.c_str(), other.c_str(), repeat);
  std::printf("%-26s %14s %14s %12s\n", "", "this", "other", "speed-up");
  for (const Kind& k : kinds) {
    Sample s;
    bool other_lacks = false;
    for (int r = 0; r < repeat && !other_lacks; ++r) {
      const fs::path a = tmp / fmt::format("this_{}_{}", &k - kinds.data(), r);
      const fs::path b = tmp / fmt::format("other_{}_{}", &k - kinds.data(), r);
      double x, y;
      if (r % 2 == 0) {
        x = Measure(mine, k, a);
        y = Measure(other, k, b);
      } else {
        y = Measure(other, k, b);
        x = Measure(mine, k, a);
      }
      if (x < 0) {
        std::fprintf(stderr, "bench-compare: %s failed in this checkout (see %s.log)\n", k.name.c_str(), a.c_str());
        return 1;
      }
      if (y < 0) {
        other_lacks = true;  // e.g. an option the older checkout does not have
        s.mine.push_back(x);
        break;
      }
      s.mine.push_back(x), s.other.push_back(y), s.ratio.push_back(k.run ? x / y : y / x);
    }
    if (other_lacks) {
      std::printf("%-26s %10.*f %-3s %14s %12s  (the other checkout cannot run it)\n", k.name.c_str(), k.run ? 0 : 1,
                  Median(s.mine), k.run ? "/s" : "s", "-", "-");
      continue;
    }
    std::printf("%-26s %10.*f %-3s %10.*f %-3s %11.2fx\n", k.name.c_str(), k.run ? 0 : 1, Median(s.mine),
                k.run ? "/s" : "s", k.run ? 0 : 1, Median(s.other), k.run ? "/s" : "s", Median(s.ratio));
    if (!k.run) {
      const std::string same = CompareTables(tmp / fmt::format("this_{}_0", &k - kinds.data()) / k.table,
                                             tmp / fmt::format("other_{}_0", &k - kinds.data()) / k.table);
      std::printf("%-26s %s: %s\n", "", k.table.c_str(), same.c_str());
    }
  }
  std::printf("(runs: steps/s from summary.json; reproductions: wall time; speed-up: median over the pairs of this\n"
              " checkout's rate over the other's, or the other's time over this one's)\n");
  if (!keep) fs::remove_all(tmp);
  return 0;
}
