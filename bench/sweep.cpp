// bench-sweep: a sweep's throughput on this machine (issue 28): the same runs of a SPEC made with
// one job and with N jobs, side by side, alternating which goes first, repeated; prints runs per
// minute per core for each and the scaling (N jobs' throughput over one job's), as medians over the
// pairs (absolute times drift on shared machines; the ratio of a pair does not, much).
//
//   build/bin/bench-sweep [--spec scenarios/sweeps/benchmark_mc.toml] [--chunks 200] [--jobs 2]
//                         [--repeat 2] [--out DIR]
//
// The runs: chunk 0 of --chunks (indices 0, K, 2K, ...: spread over the cases and the grid), each
// pass into a fresh folder. The tables of every pass must be equal but for the timing fields;
// the bench says so.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "io/source_tree.h"
#include "sweep/run_sweep.h"
#include "sweep/table.h"
#include "signal/stats.h"

namespace fs = std::filesystem;

namespace {

using rths::signal::Median;  // timings: the middle one, or the mean of the two middle ones

/// The table's rows without the timing fields (steps_per_s, wall_s), to compare passes.
std::vector<std::vector<nlohmann::json>> Comparable(const rths::sweep::Table& t) {
  std::vector<std::vector<nlohmann::json>> rows = t.rows;
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    const std::string& name = t.columns[c];
    if (name.find("steps_per_s") == std::string::npos && name.find("wall_s") == std::string::npos) continue;
    for (auto& r : rows) r[c] = nullptr;
  }
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-sweep: a sweep's runs per minute per core with 1 and N jobs, side by side"};
  std::string spec_path = "scenarios/sweeps/benchmark_mc.toml", out = "/tmp/rths_bench_sweep";
  std::int64_t chunks = 200;
  int jobs = 2, repeat = 2;
  app.add_option("--spec", spec_path, "the SPEC (relative paths: the source tree's)");
  app.add_option("--chunks", chunks, "run chunk 0 of this many (every K-th run)")->check(CLI::Range(1, 1000000));
  app.add_option("--jobs", jobs, "the parallel side's jobs")->check(CLI::Range(2, 4096));
  app.add_option("--repeat", repeat, "pairs")->check(CLI::Range(1, 100));
  app.add_option("--out", out, "scratch folder (removed and made again)");
  CLI11_PARSE(app, argc, argv);
  try {
    const fs::path spec_file = fs::path(spec_path).is_absolute() ? fs::path(spec_path) : rths::io::FindSourceFile(spec_path, "");
    const rths::sweep::Spec spec = rths::sweep::LoadSpec(spec_file.string());
    fs::remove_all(out);
    std::vector<double> rate1, rateN, scaling;
    std::vector<std::vector<nlohmann::json>> first_table;
    bool same = true;
    std::int64_t runs = 0;
    for (int r = 0; r < repeat; ++r) {
      double pair[2] = {0, 0};  // runs per minute: [1 job, N jobs]
      for (int k = 0; k < 2; ++k) {
        const int side = (r + k) % 2;  // alternate which side goes first
        rths::sweep::SweepOptions o;
        o.out = fs::path(out) / fmt::format("pass{}_{}", r, side ? "N" : "1");
        o.jobs = side ? jobs : 1;
        o.chunks = chunks;
        const auto t0 = std::chrono::steady_clock::now();
        const auto outcome = rths::sweep::RunSweep(spec, o);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        runs = outcome.ran;
        pair[side] = 60.0 * static_cast<double>(outcome.ran) / s;
        std::printf("pass %d, %d job%s: %lld runs in %.1f s: %.1f runs/min\n", r + 1, o.jobs, o.jobs > 1 ? "s" : "",
                    static_cast<long long>(outcome.ran), s, pair[side]);
        std::fflush(stdout);
        const auto table = Comparable(rths::sweep::ReadTable(spec, o.out));
        if (first_table.empty()) first_table = table;
        same = same && table == first_table;
      }
      rate1.push_back(pair[0]);
      rateN.push_back(pair[1] / jobs);
      scaling.push_back(pair[1] / pair[0]);
    }
    std::printf("\n%s: %lld of its %lld runs (every %lld-th), %d pair%s\n", spec_file.string().c_str(),
                static_cast<long long>(runs), static_cast<long long>(spec.runs()), static_cast<long long>(chunks),
                repeat, repeat > 1 ? "s" : "");
    std::printf("throughput, 1 job:  %.1f runs/min/core (median)\n", Median(rate1));
    std::printf("throughput, %d jobs: %.1f runs/min/core (median)\n", jobs, Median(rateN));
    std::printf("scaling 1 -> %d cores: %.2fx (median of per-pair ratios; ideal %d)\n", jobs, Median(scaling), jobs);
    std::printf("whole sweep at %d jobs: about %.0f min\n", jobs,
                static_cast<double>(spec.runs()) / (Median(rateN) * jobs));
    std::printf("tables of every pass %s (timing fields aside)\n", same ? "identical" : "DIFFER");
    return same ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench-sweep: %s\n", e.what());
    return 2;
  }
}
