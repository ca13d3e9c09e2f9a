#pragma once
// The flags of `rths run` (the command-line front of the supervisor, tools/run.cpp), as
// watch_flags.h and slurm_flags.h hold theirs.
#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "watch_flags.h"

namespace rths::tools {

/// The command line of `rths run` (docs/lockstep.md; `rths run --help`).
struct RunFlags {
  std::string scenario_path, default_scenario = "scenarios/default.toml";
  std::string out, transport, bin_dir, url, external;  ///< transport "": ResolveTransport
  bool quiet = false, skip_space_check = false, port_per_channel = false, realtime = false;
  bool compact = false, report = false, watch = false;
  WatchFlags watch_flags;
  std::int64_t run_id = 0;
  double join_timeout_s = 120.0;
  std::vector<std::string> sets;

  void Add(CLI::App& app) {
    RunFlags* o = this;
    app.add_option("scenario", o->scenario_path, "scenario TOML file (default: scenarios/default.toml)");
    app.add_option("--default-scenario", o->default_scenario, "used when no scenario is given")->group("");
    app.add_option("--out", o->out, "output folder (default: a new folder under runs/)");
    app.add_option("--transport", o->transport,
                   "udpm: one process per participant (the default); memq: one process (the default of a paced "
                   "run, --realtime: it holds the pace best; docs/realtime.md); mixed: the built-in participants "
                   "in one process, bridged to the --external ones on udpm (the default with --external; "
                   "docs/lockstep.md, Transports)")
        ->check(CLI::IsMember({"udpm", "memq", "mixed"}));
    app.add_option("--bin-dir", o->bin_dir, "where the rths-* programs are (default: next to this one)");
    app.add_flag("--quiet", o->quiet, "print only the output folder");
    app.add_option("--lcm-url", o->url,
                   "udpm URL of the run (default: udpm://239.255.76.67:<a free port>?ttl=0); ttl=1 to reach "
                   "participants on other hosts of the LAN (docs/participant.md)");
    app.add_flag("--port-per-channel", o->port_per_channel,
                 "udpm: carry each channel on its own UDP port (the run's port + 0..6), so each process "
                 "receives only the channels it reads: fewer deliveries per step, a faster run; the same "
                 "payloads (as --lcm-url 'udpm://239.255.76.67:PORT?ttl=0&port_per_channel=1'; "
                 "docs/lockstep.md, Transports)");
    app.add_option("--run-id", o->run_id, "run id every participant must use (default: random)")
        ->check(CLI::Range(std::int64_t{1}, std::int64_t{0x3fffffffffffffff}));
    app.add_option("--external", o->external,
                   "ROLE[,ROLE...]: do not start these participants (controller, plant, semiactive); wait "
                   "for the user's own to join the handshake (docs/participant.md)");
    app.add_flag("--realtime", o->realtime,
                 "pace the run to the wall clock at the scenario's dt (as [realtime] enabled = true): "
                 "latency percentiles and deadline misses in summary.json (docs/realtime.md)");
    app.add_option("--join-timeout-s", o->join_timeout_s,
                   "with --external: how long to wait for the external participants to say HELLO [s]")
        ->check(CLI::Range(0.1, 86400.0))
        ->capture_default_str();
    app.add_flag("--skip-space-check", o->skip_space_check, "tests only: do not check the free disk space first")
        ->group("");
    app.footer("Exit codes: 0 ok; 2 bad input or not enough disk (nothing ran); 3 a participant stopped "
               "answering (named); 4 stopped by an abort; 5 a participant's computation failed; 6 stopped "
               "by the safety monitor; 7 the output could not be written (disk full); 8 real-time mode: too many "
               "consecutive deadline misses; 9 an external participant sent ABORT; 10 an external participant was lost "
               "(heartbeats stopped, or its process ended unseen); 128+N a participant was killed by signal N; 130 "
               "interrupted.");
    AddSetOption(app, &o->sets);
    app.add_flag("--compact", o->compact,
                 "no signals.csv (as --set run.csv_every=0): log.lcm alone holds every step; `rths export` makes "
                 "a CSV or .mat of it when needed");
    app.add_flag("--report", o->report, "at the end, write RUN_DIR/report.html with figures (as `rths report RUN_DIR`)");
    app.add_flag("--watch", o->watch,
                 "watch the run live in a browser, with an ABORT button: prints the monitor's address "
                 "(http://127.0.0.1:8765/?token=...; any transport; docs/monitor.md)");
    o->watch_flags.Add(app, "--watch-");
  }
};

}  // namespace rths::tools
