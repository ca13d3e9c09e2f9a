#pragma once
/// @file The live monitor (docs/monitor.md): the clock's live records of a run, heard on a udpm
/// run's URL (monitor/listener.h) or handed over in the run's own process (a memq or mixed run,
/// monitor/in_process_feed.h), the state they make (monitor/live_view.h) and the web page that
/// shows it and carries the Abort button (monitor/server.h), as one object for `rths watch` and
/// `rths run --watch`.
#include <cstdint>
#include <memory>
#include <string>

#include "monitor/in_process_feed.h"
#include "monitor/listener.h"
#include "monitor/live_view.h"
#include "monitor/server.h"

namespace rths::monitor {

struct MonitorOptions {
  /// The run's udpm URL; "": the run is in this process (live_sink() feeds the monitor).
  std::string lcm_url;
  LiveViewOptions view;
  ServerOptions server;
};

class Monitor {
 public:
  /// Opens the URL (if any) and prepares the server; throws Error if the URL cannot be listened
  /// to. Its threads block every signal (they never take the process's SIGCHLD or SIGINT).
  explicit Monitor(MonitorOptions options);
  ~Monitor();
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;
  /// Starts listening and serving; throws Error if the port cannot be bound.
  void Start();
  void Stop();
  std::string Url() const { return server_->Url(); }
  LiveStatus Status() const { return view_.Status(); }
  int aborts() const { return server_->aborts(); }
  /// A run in this process: where its clock's records go (RunRequest::live_sink); nullptr for a
  /// monitor on a URL.
  lockstep::LiveSink* live_sink() { return feed_.get(); }
  /// A run in this process has ended as its summary says (status, who stopped it why, its
  /// complete steps).
  void OnEnd(std::int64_t run_id, const std::string& status, const std::string& by, const std::string& reason,
             std::int64_t steps);

 private:
  LiveView view_;
  std::unique_ptr<Listener> listener_;    ///< a run on a URL
  std::unique_ptr<InProcessFeed> feed_;  ///< a run in this process
  std::unique_ptr<MonitorServer> server_;
};

}  // namespace rths::monitor
