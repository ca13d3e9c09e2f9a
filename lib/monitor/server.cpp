#include "monitor/server.h"

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <random>

#include <fmt/format.h>
#include <httplib.h>

#include "core/error.h"
#include "monitor/page.h"

namespace rths::monitor {
namespace {

/// Points a snapshot page holds: 60 s of simulated time at the clock's 100 records per second.
constexpr std::int64_t kSnapshotPoints = 6000;

bool Authorized(const httplib::Request& req, const std::string& token) {
  return req.has_param("token") && req.get_param_value("token") == token;
}

void Refuse(httplib::Response& res) {
  res.status = 403;
  res.set_content("rths monitor: a token is required: open the URL the monitor printed (…/?token=…)\n",
                  "text/plain");
}

/// One server-sent event: the points after `*cursor` and the status; advances the cursor.
std::string Event(const LiveView& view, std::int64_t* cursor) {
  nlohmann::json j = view.Since(*cursor);
  *cursor = j["cursor"].get<std::int64_t>();
  return fmt::format("id: {}\ndata: {}\n\n", *cursor, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace

std::string NewToken() {
  std::random_device rd;
  std::string t;
  for (int i = 0; i < 4; ++i) t += fmt::format("{:08x}", rd());
  return t;
}

MonitorServer::MonitorServer(ServerOptions options, const LiveView* view, AbortFunction abort)
    : options_(std::move(options)), view_(view), abort_(std::move(abort)), server_(std::make_unique<httplib::Server>()) {
  if (options_.token.empty()) options_.token = NewToken();
  Routes();
}

MonitorServer::~MonitorServer() { Stop(); }

void MonitorServer::Routes() {
  auto& s = *server_;
  s.Get("/", [this](const httplib::Request& req, httplib::Response& res) {
    if (!Authorized(req, options_.token)) return Refuse(res);
    res.set_header("Cache-Control", "no-store");
    std::string snapshot;
    if (req.has_param("snapshot")) {  // the newest kSnapshotPoints points, drawn once
      const std::int64_t made = view_->PointsMade();
      snapshot = view_->Since(std::max<std::int64_t>(0, made - kSnapshotPoints), kSnapshotPoints)
                     .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    }
    res.set_content(PageHtml(options_.title, snapshot), "text/html; charset=utf-8");
  });
  s.Get("/dygraph.min.js", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(options_.dygraphs_js, "text/javascript");
  });
  s.Get("/state", [this](const httplib::Request& req, httplib::Response& res) {
    if (!Authorized(req, options_.token)) return Refuse(res);
    const std::int64_t made = view_->PointsMade();
    res.set_content(view_->Since(made, 0).dump(), "application/json");
  });
  s.Get("/events", [this](const httplib::Request& req, httplib::Response& res) {
    if (!Authorized(req, options_.token)) return Refuse(res);
    std::int64_t cursor = 0;  // a reconnecting browser says where it was
    if (req.has_header("Last-Event-ID")) cursor = std::atoll(req.get_header_value("Last-Event-ID").c_str());
    res.set_header("Cache-Control", "no-store");
    res.set_chunked_content_provider("text/event-stream", [this, cursor](std::size_t, httplib::DataSink& sink) mutable {
      if (stopping_) return false;
      const std::string event = Event(*view_, &cursor);
      if (!sink.write(event.data(), event.size())) return false;
      std::this_thread::sleep_for(std::chrono::duration<double>(options_.push_period_s));
      return !stopping_.load();
    });
  });
  s.Post("/abort", [this](const httplib::Request& req, httplib::Response& res) {
    if (!Authorized(req, options_.token)) return Refuse(res);
    const std::string why = abort_ ? abort_(kOperatorAbortReason) : "this monitor cannot abort";
    if (why.empty()) ++aborts_;
    res.status = why.empty() ? 200 : 409;
    res.set_content(nlohmann::json{{"ok", why.empty()}, {"message", why.empty() ? "ABORT sent" : why}}.dump(),
                    "application/json");
  });
}

void MonitorServer::Start() {
  if (thread_.joinable()) return;
  auto& s = *server_;
  // cpp-httplib's default sets SO_REUSEPORT, with which a second server (ours or anyone's of this
  // user) binds the same port and takes some of its connections. SO_REUSEADDR alone still allows a
  // restart over connections in TIME_WAIT, and a port in use fails.
  s.set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  if (options_.port == 0) {
    port_ = s.bind_to_any_port(options_.host);
  } else {
    port_ = s.bind_to_port(options_.host, options_.port) ? options_.port : -1;
  }
  if (port_ <= 0) {
    throw Error("", fmt::format("cannot serve on {}:{} (in use, or not an address of this host; try --port 0 for "
                                "any free port)",
                                options_.host, options_.port));
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
}

void MonitorServer::Stop() {
  stopping_ = true;
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

std::string MonitorServer::Url() const {
  std::string host = options_.host;
  if (host == "0.0.0.0") {
    char name[256] = {};
    host = ::gethostname(name, sizeof name - 1) == 0 && name[0] ? name : "localhost";
  }
  return fmt::format("http://{}:{}/?token={}", host, port_, options_.token);
}

}  // namespace rths::monitor
