#pragma once
/// @file The live monitor's web server (docs/monitor.md): one page with scrolling plots of a run
/// (monitor/page.h), the run's new points pushed to it as server-sent events, its status as JSON,
/// and the Abort button's request. Every request but the plotting library's must carry the
/// monitor's token (`?token=`): a monitor that can stop a test is not open to whoever can reach
/// the port, nor to another web page's script in the operator's browser.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "monitor/live_view.h"

namespace httplib {
class Server;
}

namespace rths::monitor {

struct ServerOptions {
  std::string host = "127.0.0.1";  ///< the address to bind: 127.0.0.1 (this host) or 0.0.0.0 (the LAN)
  int port = 8765;                 ///< TCP port; 0: any free port
  std::string token;               ///< required on every request but /dygraph.min.js (non-empty)
  std::string dygraphs_js;         ///< the plotting library's bytes (Debian's libjs-dygraphs), served as is
  std::string title = "rths monitor";  ///< the page's title (e.g. the scenario's name)
  double push_period_s = 0.2;      ///< [s] between two pushes to a browser
};

/// Stops the watched run: returns "" if ABORT was sent, else why not.
using AbortFunction = std::function<std::string(const std::string& reason)>;

/// The reason every Abort from the page carries (summary.json "stopped" names it).
inline constexpr const char* kOperatorAbortReason = "operator abort from the monitor";

class MonitorServer {
 public:
  MonitorServer(ServerOptions options, const LiveView* view, AbortFunction abort);
  ~MonitorServer();
  MonitorServer(const MonitorServer&) = delete;
  MonitorServer& operator=(const MonitorServer&) = delete;

  /// Binds and starts serving in a thread of its own. Throws Error naming host:port if it cannot
  /// bind (in use, not an address of this host).
  void Start();
  /// Closes every connection and stops (also done on destruction).
  void Stop();

  int port() const { return port_; }
  /// The page's address with its token, e.g. http://127.0.0.1:8765/?token=3f9c...; a LAN monitor
  /// (host 0.0.0.0) names this host's name instead of 0.0.0.0.
  std::string Url() const;
  /// Aborts sent from the page so far.
  int aborts() const { return aborts_; }

 private:
  void Routes();

  ServerOptions options_;
  const LiveView* view_;
  AbortFunction abort_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<int> aborts_{0};
};

/// A fresh random token (32 hex digits, from std::random_device).
std::string NewToken();

}  // namespace rths::monitor
