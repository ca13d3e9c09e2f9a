// rths-sweep: a study of the user's own (issue 28): the runs a SPEC defines (lib/sweep/spec.h), on
// this machine, `--jobs` at a time, one row per run and a table (lib/sweep/run_sweep.h).
//
//   rths sweep SPEC.toml [--out DIR] [--jobs N] [--only INDEX] [--resume] [--keep-logs] [--chunk C --chunks N]
//
// The Slurm executor, the HDF5 table, the per-group summary and the plots are not built yet.
#include <cstdio>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "core/error.h"
#include "io/output_folder.h"
#include "lockstep/exit_code.h"
#include "sweep/run_sweep.h"

int main(int argc, char** argv) {
  CLI::App app{"rths sweep: run a SPEC's grid, cases and random draws on this machine; a row per run and a table"};
  rths::tools::NameCommand(app, "sweep");
  std::string spec_path, out;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::int64_t only = -1;
  bool resume = false, keep_logs = false;
  std::int64_t chunk = 0, chunks = 1;
  app.add_option("spec", spec_path, "the sweep's SPEC (TOML; lib/sweep/spec.h)")->required();
  app.add_option("--out", out, "output folder (default: runs/<time>-sweep-<name>)");
  app.add_option("--jobs", jobs, "runs at a time (default: every core)")->check(CLI::Range(1, 4096));
  app.add_option("--only", only, "make run INDEX alone (bit for bit as in the whole sweep)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  app.add_flag("--resume", resume, "skip the runs whose row is already in OUT/rows (needs --out)");
  app.add_flag("--keep-logs", keep_logs, "keep every run's log.lcm and signals.csv");
  app.add_option("--chunk", chunk, "run only the indices i with i % CHUNKS == CHUNK (one task of a job array)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  app.add_option("--chunks", chunks, "the number of chunks the sweep is split into")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  app.footer("Exit codes: 0 every run completed; 1 some runs did not (their rows say why); 2 bad input.");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    const rths::sweep::Spec spec = rths::sweep::LoadSpec(spec_path);
    if (resume && out.empty()) throw rths::Error("--resume", "needs --out DIR, the sweep's folder to resume");
    rths::sweep::SweepOptions o;
    o.out = out.empty() ? rths::io::NewOutputFolder("sweep-" + spec.name) : std::filesystem::path(out);
    o.jobs = jobs;
    if (only >= 0) o.only = only;
    o.resume = resume;
    o.keep_logs = keep_logs;
    o.chunk = chunk;
    o.chunks = chunks;
    rths::ProgressLine line("rths sweep");
    o.progress = &line;
    std::printf("rths sweep: %s: %lld runs (%zu cases x %lld grid points x %lld draws), %d at a time\n",
                spec_path.c_str(), static_cast<long long>(spec.runs()), spec.cases.size(),
                static_cast<long long>(spec.combinations()), static_cast<long long>(std::max<std::int64_t>(spec.draws, 1)),
                jobs);
    std::fflush(stdout);
    const auto r = rths::sweep::RunSweep(spec, o);
    std::printf("ran %lld, skipped %lld (rows already there), not completed %lld\ntable: %s\n",
                static_cast<long long>(r.ran), static_cast<long long>(r.skipped), static_cast<long long>(r.failed),
                r.table.string().c_str());
    return r.failed > 0 ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths sweep: %s\n", e.what());
    return rths::lockstep::kExitUsage;
  }
}
