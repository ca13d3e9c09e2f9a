#pragma once
/// @file The live monitor (docs/monitor.md): a lossy listener on a run's LCM traffic
/// (monitor/listener.h), the state it keeps (monitor/live_view.h) and the web page that shows it
/// and carries the Abort button (monitor/server.h), as one object for `rths watch` and
/// `rths run --watch`.
#include <memory>
#include <string>

#include "monitor/listener.h"
#include "monitor/live_view.h"
#include "monitor/server.h"

namespace rths::monitor {

struct MonitorOptions {
  std::string lcm_url;     ///< the run's udpm URL
  LiveViewOptions view;
  ServerOptions server;
};

class Monitor {
 public:
  /// Opens the URL and prepares the server; throws Error if the URL cannot be listened to. Its
  /// threads block every signal (they never take the process's SIGCHLD or SIGINT).
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

 private:
  LiveView view_;
  std::unique_ptr<Listener> listener_;
  std::unique_ptr<MonitorServer> server_;
};

}  // namespace rths::monitor
