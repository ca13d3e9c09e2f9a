// The live monitor (lib/monitor, `rths watch`, `rths run --watch`; docs/monitor.md): what it makes
// of a run's messages, its web server's token and Abort, and a real run watched and aborted from
// headless Chromium.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "lockstep/exit_code.h"
#include "monitor/live_view.h"
#include "monitor/server.h"
#include "supervisor/ports.h"
#include "chromium_pipe.h"
#include "test_support.h"
// Last: it includes <resolv.h>, whose `_res` macro breaks Eigen's headers included before it.
#include <httplib.h>

namespace fs = std::filesystem;
using rths::monitor::LiveView;
using rths::monitor::WallClock;

namespace {

constexpr int kGo = 3, kAbort = 4, kClose = 7;

/// Feeds steps [from, to) of run `id`: r = sin, u = r + 0.1, y = r - 0.01 (except a spike at k =
/// `spike`), f = 2 y, i = 0.5; each step completes 0.1 ms after its release at t0 + k dt.
void Feed(LiveView* v, std::int64_t id, std::int64_t from, std::int64_t to, double dt, std::int64_t spike = -1,
          std::int64_t lose = -1, WallClock::time_point t0 = WallClock::now()) {
  for (std::int64_t k = from; k < to; ++k) {
    const auto release = t0 + std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(k * dt));
    const double r = std::sin(0.01 * static_cast<double>(k));
    v->OnDesired(id, k, r, release);
    v->OnCommand(id, k, r + 0.1);
    if (k == lose) continue;
    const double y = k == spike ? r - 5.0 : r - 0.01;
    v->OnMeasured(id, k, y, 2 * y, 0.5, release + std::chrono::microseconds(100));
    if (k == 7) v->OnMeasured(id, k, y, 2 * y, 0.5, release);  // repaired: sent twice, heard once
  }
}

/// A command run by `sh -c` in the background; interrupted (SIGINT) and waited for if the test
/// ends before Wait().
class BackgroundRun {
 public:
  explicit BackgroundRun(const std::string& cmd) {
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~BackgroundRun() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGINT);
    ::waitpid(pid_, nullptr, 0);
  }
  /// Waits for it to end; its exit code (-1 if killed by a signal).
  int Wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
};

}  // namespace

TEST_CASE("live view: a bucket keeps each signal's peak, a lost step is a gap, the phases follow the handshake") {
  rths::monitor::LiveViewOptions o;
  o.points_per_sim_s = 100;  // dt 1 ms: 10 steps a point
  LiveView v(o);
  CHECK(v.Status().phase == "waiting");
  v.OnHandshake(7, kGo, "integrator", 1000, 0.001, "");
  CHECK(v.Status().phase == "running");
  Feed(&v, 7, 0, 505, 0.001, /*spike=*/203, /*lose=*/300);
  const auto s = v.Status();
  CHECK(s.last_k == 504);
  CHECK(s.steps_seen == 504);  // step 300 was lost
  // Steps are joined kJoinLag behind the newest: 500 steps, 50 points.
  CHECK(v.PointsMade() == 50);
  const auto j = v.Since(0);
  REQUIRE(j["points"].size() == 50);
  const auto& p20 = j["points"][20];  // steps 200..209: the spike at 203 survives decimation
  CHECK(p20[0].get<double>() == doctest::Approx(0.209));
  CHECK(p20[4].get<double>() == doctest::Approx(5.0));  // e = r - y
  CHECK(p20[5].get<double>() == doctest::Approx(2 * (std::sin(2.03) - 5.0)));
  CHECK(j["points"][30][4].get<double>() == doctest::Approx(0.01));  // the bucket with the lost step
  CHECK(j["points"][5][7].is_null());  // unpaced: no latency
  // A cursor: only what is new.
  CHECK(v.Since(48)["points"].size() == 2);
  CHECK(v.Since(50)["points"].empty());
  // ABORT flushes the steps still waiting and names who and why.
  v.OnHandshake(7, kAbort, "monitor", 0, 0, "operator abort from the monitor");
  CHECK(v.PointsMade() == 51);
  CHECK(v.Status().phase == "aborted");
  CHECK(v.Status().abort_by == "monitor");
  CHECK(v.Status().abort_reason == "operator abort from the monitor");
  // A later CLOSE of the same run does not hide the abort; a new run starts over.
  v.OnHandshake(7, kClose, "integrator", 1000, 0.001, "");
  CHECK(v.Status().phase == "aborted");
  v.OnHandshake(9, 1, "integrator", 2000, 0.001, "");
  CHECK(v.Status().phase == "starting");
  CHECK(v.Status().n_steps == 2000);
  CHECK(v.PointsMade() == 0);
  CHECK(v.Since(51)["points"].empty());  // an old cursor is not an error
}

TEST_CASE("live view: a paced run's latency and the steps heard after their deadline") {
  rths::monitor::LiveViewOptions o;
  o.paced = true;
  LiveView v(o);
  v.OnHandshake(3, kGo, "integrator", 100, 0.001, "");
  const auto t0 = WallClock::now();
  auto at = [&](double s) { return t0 + std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(s)); };
  for (int k = 0; k < 20; ++k) {
    // Steps 10..12 complete 1.5 ms after their release: after their deadline t0 + (k + 1) dt.
    const double done_s = (k >= 10 && k <= 12) ? 1.5e-3 : 0.2e-3;
    v.OnDesired(3, k, 0.0, at(k * 1e-3));
    v.OnMeasured(3, k, 0.0, 0.0, 0.0, at(k * 1e-3 + done_s));
  }
  const auto s = v.Status();
  CHECK(s.misses == 3);
  CHECK(s.longest_miss_run == 3);
  CHECK(s.latency_max_ms == doctest::Approx(1.5).epsilon(1e-6));
  CHECK(s.latency_ms == doctest::Approx(0.2).epsilon(1e-6));
}

TEST_CASE("monitor server: every request needs the token; Abort calls back and says whether it was sent") {
  LiveView view;
  std::string reason;
  bool run_known = false;
  rths::monitor::ServerOptions o;
  o.port = 0;
  o.dygraphs_js = "/* dygraphs */";
  o.title = "rths monitor: <sdof>";
  rths::monitor::MonitorServer server(o, &view, [&](const std::string& r) {
    if (!run_known) return std::string("no run heard yet");
    reason = r;
    return std::string();
  });
  server.Start();
  const std::string url = server.Url();
  const std::string token = url.substr(url.find("token=") + 6);
  CHECK(token.size() == 32);
  httplib::Client c("127.0.0.1", server.port());
  CHECK(c.Get("/")->status == 403);
  CHECK(c.Get("/?token=wrong")->status == 403);
  CHECK(c.Get("/state")->status == 403);
  CHECK(c.Post("/abort", "", "text/plain")->status == 403);
  const auto page = c.Get("/?token=" + token);
  REQUIRE(page);
  CHECK(page->status == 200);
  CHECK(page->body.find("rths monitor: &lt;sdof&gt;") != std::string::npos);
  CHECK(page->body.find("id=\"abort\"") != std::string::npos);
  CHECK(c.Get("/dygraph.min.js")->body == "/* dygraphs */");
  const auto state = nlohmann::json::parse(c.Get("/state?token=" + token)->body);
  CHECK(state["status"]["phase"] == "waiting");
  auto no_run = c.Post("/abort?token=" + token, "", "text/plain");
  CHECK(no_run->status == 409);
  CHECK(no_run->body.find("no run heard yet") != std::string::npos);
  run_known = true;
  auto sent = c.Post("/abort?token=" + token, "", "text/plain");
  CHECK(sent->status == 200);
  CHECK(reason == "operator abort from the monitor");
  CHECK(server.aborts() == 1);
  server.Stop();
}

TEST_CASE("rths run --watch: the page in headless Chromium follows the run, and its ABORT button stops it") {
  if (!rths_test::UdpmAvailable()) {
    FAIL("no multicast route for udpm (as root: ip route add 224.0.0.0/4 dev lo; scripts/bootstrap.sh adds it)");
  }
  rths_test::RequireTool("chromium", "chromium");
  rths_test::RequireFile("/usr/share/javascript/dygraphs/dygraph.min.js", "libjs-dygraphs");
  const fs::path dir = rths_test::TempDir("monitor_watch");
  const fs::path out_txt = dir / "run.txt";
  // Long enough that it is still running when the button is pressed (about 1 minute of stepping).
  const std::string cmd = "exec " + std::string(RTHS_BIN_DIR) + "/rths-run " + RTHS_SOURCE_DIR +
                          "/scenarios/default.toml --compact --set run.duration_s=300 --watch --watch-port 0 --out " +
                          (dir / "run").string() + " > " + out_txt.string() + " 2>&1";
  BackgroundRun run(cmd);
  // The monitor's address, as printed.
  std::string url;
  const std::regex line("monitor +(http://\\S+)");
  for (int i = 0; i < 300 && url.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::smatch m;
    const std::string text = rths_test::Slurp(out_txt);
    if (std::regex_search(text, m, line)) url = m[1];
  }
  REQUIRE_MESSAGE(!url.empty(), rths_test::Slurp(out_txt));
  {
    rths_test::ChromiumPipe chromium(dir / "chromium");
    const std::string page = chromium.Open(url);
    REQUIRE(chromium.WaitFor(page, "window.rths && rths.status && rths.status.phase === 'running' && rths.points > 20", 60));
    // The plots advance while the run does.
    const double t1 = chromium.Evaluate(page, "rths.lastT").get<double>();
    const int updates1 = chromium.Evaluate(page, "rths.updates").get<int>();
    CHECK(chromium.WaitFor(page, "rths.lastT > " + std::to_string(t1 + 0.5), 30));
    CHECK(chromium.Evaluate(page, "rths.updates").get<int>() > updates1);
    CHECK(chromium.Evaluate(page, "document.getElementById('step').textContent").get<std::string>().find(" of 600,000") !=
          std::string::npos);
    chromium.Screenshot(page, dir / "monitor.png");
    CHECK(fs::file_size(dir / "monitor.png") > 20000);
    if (const char* keep = std::getenv("RTHS_MONITOR_SCREENSHOT")) {  // docs/img/monitor.png: 8 s into the run
      chromium.WaitFor(page, "rths.lastT > 8", 120);
      chromium.Screenshot(page, keep);
    }
    // The operator presses ABORT.
    CHECK(chromium.Evaluate(page, "document.getElementById('abort').disabled") == false);
    chromium.Evaluate(page, "document.getElementById('abort').click(), true");
    CHECK(chromium.WaitFor(page, "rths.status.phase === 'aborted'", 30));
    CHECK(chromium.Evaluate(page, "document.getElementById('message').textContent").get<std::string>() ==
          "Aborted by monitor: operator abort from the monitor");
  }
  const int code = run.Wait();
  const std::string output = rths_test::Slurp(out_txt);
  CAPTURE(output);
  CHECK(code == rths::lockstep::kExitPeerAbort);
  CHECK(output.find("rths run: ABORTED: monitor aborted the run: operator abort from the monitor") != std::string::npos);
  const auto summary = nlohmann::json::parse(rths_test::Slurp(dir / "run" / "summary.json"));
  CHECK(summary["status"] == "aborted");
  CHECK(summary["stopped"] == "monitor aborted the run: operator abort from the monitor");
  // The log is valid and complete to its last step, which is the summary's.
  const auto log = rths::io::ReadRunLog((dir / "run" / "log.lcm").string());
  CHECK_FALSE(log.truncated_tail);
  CHECK(log.CompleteSteps() == summary["steps"].get<std::int64_t>());
  CHECK(log.CompleteSteps() > 1000);
  CHECK(log.CompleteSteps() < 600000);
}

TEST_CASE("rths watch --lcm-url: a run started elsewhere is watched and stopped; --exit-at-end ends with it") {
  if (!rths_test::UdpmAvailable()) {
    FAIL("no multicast route for udpm (as root: ip route add 224.0.0.0/4 dev lo; scripts/bootstrap.sh adds it)");
  }
  rths_test::RequireFile("/usr/share/javascript/dygraphs/dygraph.min.js", "libjs-dygraphs");
  const fs::path dir = rths_test::TempDir("monitor_watch_cli");
  const std::string url = "udpm://239.255.76.67:" + std::to_string(rths::supervisor::FreeUdpPort()) + "?ttl=0";
  // The monitor first, as an operator would open it before the test.
  BackgroundRun watch("exec " + std::string(RTHS_BIN_DIR) + "/rths-watch --lcm-url '" + url +
                      "' --port 0 --exit-at-end > " + (dir / "watch.txt").string() + " 2>&1");
  std::string address;
  const std::regex line("monitor +http://127\\.0\\.0\\.1:([0-9]+)/\\?token=([0-9a-f]+)");
  std::smatch m;
  for (int i = 0; i < 200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const std::string text = rths_test::Slurp(dir / "watch.txt");
    if (std::regex_search(text, m, line)) break;
  }
  REQUIRE_MESSAGE(!m.empty(), rths_test::Slurp(dir / "watch.txt"));
  const int port = std::stoi(m[1]);
  const std::string token = m[2];
  BackgroundRun run("exec " + std::string(RTHS_BIN_DIR) + "/rths-run " + RTHS_SOURCE_DIR +
                    "/scenarios/default.toml --compact --set run.duration_s=300 --lcm-url '" + url + "' --out " +
                    (dir / "run").string() + " > " + (dir / "run.txt").string() + " 2>&1");
  httplib::Client c("127.0.0.1", port);
  nlohmann::json state;
  for (int i = 0; i < 600; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto res = c.Get("/state?token=" + token);
    if (!res || res->status != 200) continue;
    state = nlohmann::json::parse(res->body);
    if (state["status"]["phase"] == "running" && state["status"]["last_k"].get<std::int64_t>() > 2000) break;
  }
  REQUIRE_MESSAGE(state["status"]["phase"] == "running", state.dump());
  CHECK(state["status"]["n_steps"] == 600000);
  const auto abort = c.Post("/abort?token=" + token, "", "text/plain");
  REQUIRE(abort);
  CHECK(abort->status == 200);
  CHECK(run.Wait() == rths::lockstep::kExitPeerAbort);
  CHECK(watch.Wait() == 0);  // --exit-at-end: it ends with the run
  const std::string said = rths_test::Slurp(dir / "watch.txt");
  CAPTURE(said);
  CHECK(said.find("running") != std::string::npos);
  CHECK(said.find("aborted by monitor: operator abort from the monitor") != std::string::npos);
  const auto summary = nlohmann::json::parse(rths_test::Slurp(dir / "run" / "summary.json"));
  CHECK(summary["status"] == "aborted");
}

TEST_CASE("rths run --watch on a port in use: nothing runs, exit 2, the option and the port named") {
  if (!rths_test::UdpmAvailable()) {
    FAIL("no multicast route for udpm (as root: ip route add 224.0.0.0/4 dev lo; scripts/bootstrap.sh adds it)");
  }
  rths_test::RequireFile("/usr/share/javascript/dygraphs/dygraph.min.js", "libjs-dygraphs");
  LiveView view;
  rths::monitor::ServerOptions o;
  o.port = 0;
  rths::monitor::MonitorServer taken(o, &view, {});
  taken.Start();
  const fs::path dir = rths_test::TempDir("monitor_port_taken");
  std::string out;
  const int code = rths_test::RunCli(std::string(RTHS_SOURCE_DIR) + "/scenarios/default.toml --compact --set "
                                     "run.duration_s=1 --watch --watch-port " + std::to_string(taken.port()) +
                                     " --out " + (dir / "run").string(),
                                     &out);
  CAPTURE(out);
  CHECK(code == rths::lockstep::kExitUsage);
  CHECK(out.find("rths run: --watch: cannot serve on 127.0.0.1:" + std::to_string(taken.port())) != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "run" / "log.lcm"));
  taken.Stop();
}
