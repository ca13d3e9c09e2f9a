#pragma once
// The live monitor's flags, shared by `rths watch` and `rths run --watch`, and the plotting
// library read here at the edge (docs/monitor.md).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "monitor/monitor.h"

namespace rths::tools {

/// Where Debian's libjs-dygraphs puts the library the page plots with.
inline constexpr const char* kDygraphsJs = "/usr/share/javascript/dygraphs/dygraph.min.js";

struct WatchFlags {
  int port = 8765;
  bool lan = false;
  std::string dygraphs = kDygraphsJs;

  /// Adds the flags with `prefix` ("--" for watch, "--watch-" for run).
  void Add(CLI::App& app, const std::string& prefix) {
    app.add_option(prefix + "port", port, "the monitor's TCP port (0: any free port)")
        ->check(CLI::Range(0, 65535))
        ->capture_default_str();
    app.add_flag(prefix + "lan", lan,
                 "serve on every interface (0.0.0.0), not only this host (127.0.0.1): anyone on the LAN who has the "
                 "printed URL, token included, can see the run and ABORT it");
    app.add_option(prefix + "dygraphs", dygraphs, "the dygraphs library the page plots with (libjs-dygraphs)")
        ->group("");
  }

  /// The monitor's options for a run on `lcm_url` ("": a run in this process); reads the plotting
  /// library (throws Error naming the file and the package if it cannot).
  monitor::MonitorOptions Options(const std::string& lcm_url, const std::string& title) const {
    monitor::MonitorOptions o;
    o.lcm_url = lcm_url;
    o.server.host = lan ? "0.0.0.0" : "127.0.0.1";
    o.server.port = port;
    o.server.title = title;
    std::ifstream in(dygraphs, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    if (!in || bytes.str().empty()) {
      throw Error(dygraphs, "cannot read the monitor's plotting library (install Debian's libjs-dygraphs: apt-get "
                            "install libjs-dygraphs)");
    }
    o.server.dygraphs_js = bytes.str();
    return o;
  }

  /// A monitor on `lcm_url` ("": a run in this process), not started.
  std::unique_ptr<monitor::Monitor> Make(const std::string& lcm_url, const std::string& title) const {
    return std::make_unique<monitor::Monitor>(Options(lcm_url, title));
  }
  /// Starts `m` and prints its address (and the LAN warning) on `out`.
  void Announce(monitor::Monitor* m, const std::string& command, std::FILE* out) const {
    m->Start();
    if (lan) {
      std::fprintf(stderr,
                   "rths %s: warning: the monitor serves the whole network (--%slan): anyone with its URL can see "
                   "this run and ABORT it; share the URL only with the test's operators\n",
                   command.c_str(), command == "run" ? "watch-" : "");
    }
    std::fprintf(out, "  monitor          %s\n", m->Url().c_str());
    std::fflush(out);
  }
  /// Make and Announce.
  std::unique_ptr<monitor::Monitor> Start(const std::string& lcm_url, const std::string& title,
                                          const std::string& command, std::FILE* out) const {
    auto m = Make(lcm_url, title);
    Announce(m.get(), command, out);
    return m;
  }
};

/// The monitor of `rths run --watch` (docs/monitor.md) through the run: a run in this process
/// (memq, mixed) feeds it through a live sink made before the run; a udpm run's monitor listens to
/// the run's URL, made when it is known. Announced just before the participants start; told the
/// run's end (the page shows it for a second) and stopped after it.
class RunWatch {
 public:
  RunWatch(const WatchFlags& flags, std::string title) : flags_(flags), title_(std::move(title)) {}

  /// For a run in this process: the monitor, its live sink for RunRequest::live_sink. Throws
  /// Error if it cannot be made (the plotting library).
  lockstep::LiveSink* InProcessSink() {
    monitor_ = std::make_unique<monitor::Monitor>(flags_.Options("", title_));
    return monitor_->live_sink();
  }
  /// Just before the participants start (RunRequest::on_start): makes a udpm run's monitor on
  /// `url` and starts and announces it on stdout. Throws Error("--watch") if it cannot: nothing runs.
  void Start(const std::string& url) {
    try {
      if (!monitor_) monitor_ = flags_.Make(url, title_);
      flags_.Announce(monitor_.get(), "run", stdout);
    } catch (const std::exception& e) {
      throw Error("--watch", e.what());
    }
  }
  /// The run ended: the page shows how (status, who stopped it, why, its steps) for a second.
  void End(std::int64_t run_id, const std::string& status, const std::string& by, const std::string& stopped,
           std::int64_t steps) {
    if (!monitor_) return;
    monitor_->OnEnd(run_id, status, by, stopped, steps);
    std::this_thread::sleep_for(std::chrono::seconds(1));
    monitor_->Stop();
  }

 private:
  const WatchFlags& flags_;
  std::string title_;
  std::unique_ptr<monitor::Monitor> monitor_;
};

}  // namespace rths::tools
