// The live monitor (lib/monitor, `rths watch`, `rths run --watch`; docs/monitor.md): what it makes
// of a run's messages, its web server's token and Abort, and a real run watched and aborted from
// headless Chromium.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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
#include "core/exit_code.h"
#include "lockstep/live_feed.h"
#include "lockstep/realtime.h"
#include "monitor/in_process_feed.h"
#include "monitor/live_view.h"
#include "monitor/server.h"
#include "supervisor/ports.h"
#include "chromium_pipe.h"
#include "udpm_support.h"
#include "test_support.h"
// Last: it includes <resolv.h>, whose `_res` macro breaks Eigen's headers included before it.
#include <httplib.h>

namespace fs = std::filesystem;
using rths::monitor::LiveView;
using rths::monitor::WallClock;

namespace {

constexpr int kGo = 3, kAbort = 4, kClose = 7;

/// A sink that hands the clock's records straight to a LiveView, losing the ones listed.
struct ViewSink final : rths::lockstep::LiveSink {
  LiveView* view;
  std::vector<std::int64_t> lose;  ///< records (by order pushed) that never arrive
  std::int64_t pushed = 0;
  void Push(const rths::monitor_t& r) override {
    if (std::find(lose.begin(), lose.end(), pushed++) == lose.end()) view->OnRecord(r, WallClock::now());
  }
};

/// Runs the clock's feed over steps [0, n) of run `id` as ClockParticipant does: r = sin, u = r +
/// 0.1, y = r - 0.01 (but r - 5 at `spike`), f = 2 y, i = 0.5; the latency 0.2 ms, 1.5 ms (a miss)
/// for the steps in [miss_from, miss_to]. `*rt` ends as the clock's totals.
void FeedClock(rths::lockstep::LiveFeed* feed, ViewSink* sink, std::int64_t id, std::int64_t n, double dt,
               bool paced, std::int64_t spike, std::int64_t miss_from, std::int64_t miss_to,
               rths::lockstep::RealtimeStats* rt) {
  rt->paced = paced;
  feed->Start(id, n, dt, paced, {152.4, 556.0, 25.0});
  feed->Phase(rths::lockstep::kLiveRunning, sink);
  std::int64_t run = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const double r = std::sin(0.01 * static_cast<double>(k));
    const double y = k == spike ? r - 5.0 : r - 0.01;
    const bool missed = paced && k >= miss_from && k <= miss_to;
    const double latency_s = missed ? 1.5e-3 : 0.2e-3;
    rt->latency.Add(latency_s);
    ++rt->steps;
    if (missed) ++rt->misses;
    run = missed ? run + 1 : 0;
    rt->max_consecutive_misses = std::max(rt->max_consecutive_misses, run);
    feed->Add(k, r, r + 0.1, y, 2 * y, 0.5, latency_s, missed, *rt, sink);
  }
}

/// The monitor's address as `rths run --watch` printed it in `out_txt` (waits up to 15 s).
struct MonitorAddress {
  int port = 0;
  std::string token;
  std::string printed;  ///< the run's output so far
};
MonitorAddress WaitForMonitor(const fs::path& out_txt) {
  const std::regex line("monitor +http://127\\.0\\.0\\.1:([0-9]+)/\\?token=([0-9a-f]+)");
  MonitorAddress a;
  std::smatch m;
  for (int i = 0; i < 300; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    a.printed = rths_test::Slurp(out_txt);
    if (std::regex_search(a.printed, m, line)) break;
  }
  REQUIRE_MESSAGE(!m.empty(), a.printed);
  a.port = std::stoi(m[1]);
  a.token = m[2];
  return a;
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

TEST_CASE("live feed and view: a bucket keeps each signal's peak, a lost record is a gap, the phases follow") {
  LiveView v;
  CHECK(v.Status().phase == "waiting");
  ViewSink sink;
  sink.view = &v;
  sink.lose = {31};  // the phase record is pushed first: record 31 is the bucket of steps 300..309
  rths::lockstep::LiveFeed feed;
  rths::lockstep::RealtimeStats rt;
  FeedClock(&feed, &sink, 7, 505, 0.001, false, /*spike=*/203, -1, -1, &rt);
  CHECK(feed.bucket_steps() == 10);  // 100 records per simulated second at dt 1 ms
  const auto s = v.Status();
  CHECK(s.phase == "running");
  CHECK(s.n_steps == 505);
  CHECK(s.last_k == 504);
  // 50 full buckets and the last step's (the run's end closes a bucket): one of them lost.
  CHECK(v.PointsMade() == 50);
  CHECK(s.records_expected == 51);
  CHECK(s.records_heard == 50);
  const auto j = v.Since(0);
  REQUIRE(j["points"].size() == 50);
  const auto& p20 = j["points"][20];  // steps 200..209: the spike at 203 survives decimation
  CHECK(p20[0].get<double>() == doctest::Approx(0.209));
  CHECK(p20[4].get<double>() == doctest::Approx(5.0));  // e = r - y
  CHECK(p20[5].get<double>() == doctest::Approx(2 * (std::sin(2.03) - 5.0)));
  CHECK(j["points"][30][0].get<double>() == doctest::Approx(0.319));  // 300..309 lost: a gap
  // The safety limits and the peaks against them.
  CHECK(s.stroke_mm == 152.4);
  CHECK(s.max_error_mm == 25.0);
  CHECK(s.peak_error_mm == doctest::Approx(5.0));
  CHECK(s.peak_force_kN == doctest::Approx(2 * (5.0 - std::sin(2.03))));
  CHECK(j["status"]["limits"]["force_kN"] == 556.0);
  CHECK(j["status"]["peaks"]["error_mm"].get<double>() == doctest::Approx(5.0));
  // A cursor: only what is new.
  CHECK(v.Since(48)["points"].size() == 2);
  CHECK(v.Since(50)["points"].empty());
  // The clock's DONE and CLOSE, then an ABORT of the same run, which cannot hide the completion.
  feed.Phase(rths::lockstep::kLiveFinishing, &sink);
  CHECK(v.Status().phase == "finishing");
  feed.Phase(rths::lockstep::kLiveCompleted, &sink);
  CHECK(v.Status().phase == "completed");
  CHECK(v.PointsMade() == 50);  // phase records are not points
  v.OnHandshake(7, kAbort, "monitor", 0, 0, "late");
  CHECK(v.Status().phase == "completed");
  // A new run starts over; its ABORT names who and why.
  v.OnHandshake(9, 1, "integrator", 2000, 0.001, "");
  CHECK(v.Status().phase == "starting");
  CHECK(v.Status().n_steps == 2000);
  CHECK(v.PointsMade() == 0);
  CHECK(v.Since(51)["points"].empty());  // an old cursor is not an error
  v.OnHandshake(9, kGo, "integrator", 2000, 0.001, "");
  v.OnHandshake(9, kAbort, "monitor", 0, 0, "operator abort from the monitor");
  CHECK(v.Status().phase == "aborted");
  CHECK(v.Status().abort_by == "monitor");
  CHECK(v.Status().abort_reason == "operator abort from the monitor");
  v.OnHandshake(9, kClose, "integrator", 2000, 0.001, "");
  CHECK(v.Status().phase == "aborted");
}

TEST_CASE("live feed: with several actuators the peaks against the limits are every actuator's") {
  LiveView v;
  ViewSink sink;
  sink.view = &v;
  rths::lockstep::LiveFeed feed;
  rths::lockstep::RealtimeStats rt;
  feed.Start(3, 100, 0.001, false, {152.4, 556.0, 25.0});
  feed.Phase(rths::lockstep::kLiveRunning, &sink);
  for (std::int64_t k = 0; k < 100; ++k) {
    // Actuator 1 (the scalars, plotted) tracks within 0.1 mm; actuator 2 lags by 7 mm at step 40
    // and its command reaches 60 mm at step 70.
    const double r[2] = {1.0, 2.0};
    const double u[2] = {1.0, k == 70 ? -60.0 : 2.0};
    const double y[2] = {0.9, k == 40 ? -5.0 : 2.0};
    feed.KeepActuatorPeaks(2, r, u, y);
    ++rt.steps;
    feed.Add(k, r[0], u[0], y[0], 0.0, 0.0, 1e-4, false, rt, &sink);
  }
  const auto s = v.Status();
  CHECK(s.peak_error_mm == doctest::Approx(7.0));
  CHECK(s.peak_disp_mm == doctest::Approx(60.0));
  const auto j = v.Since(0);
  REQUIRE(j["points"].size() == 10);
  CHECK(j["points"][4][4].get<double>() == doctest::Approx(0.1));  // the plot: actuator 1's r - y
}

TEST_CASE("live feed and view: a paced run's latency and misses are the clock's own figures") {
  LiveView v;
  ViewSink sink;
  sink.view = &v;
  rths::lockstep::LiveFeed feed;
  rths::lockstep::RealtimeStats rt;
  FeedClock(&feed, &sink, 3, 100, 0.001, true, -1, /*misses:*/ 10, 12, &rt);
  const auto s = v.Status();
  CHECK(s.paced);
  CHECK(s.misses == rt.misses);
  CHECK(s.misses == 3);
  CHECK(s.longest_miss_run == rt.max_consecutive_misses);
  CHECK(s.longest_miss_run == 3);
  CHECK(s.latency_max_ms == doctest::Approx(1e3 * rt.latency.max_s()));
  CHECK(s.latency_ms == doctest::Approx(0.2));
  const auto j = v.Since(0);
  REQUIRE(j["points"].size() == 10);
  CHECK(j["points"][1][7].get<double>() == doctest::Approx(1.5));  // the bucket of steps 10..19
  CHECK(j["points"][1][8] == 3);
  CHECK(j["points"][0][8] == 0);
}

TEST_CASE("in-process feed: records cross the ring to the view; an abort is taken once and names the monitor") {
  LiveView v;
  rths::monitor::InProcessFeed feed(&v, 0.001);
  CHECK(feed.RequestAbort("operator abort from the monitor") == "the run has not started yet");
  feed.Start();
  rths::lockstep::LiveFeed clock;
  rths::lockstep::RealtimeStats rt;
  clock.Start(5, 1000, 0.001, false, {});
  clock.Phase(rths::lockstep::kLiveRunning, &feed);
  for (std::int64_t k = 0; k < 200; ++k) {
    ++rt.steps;
    clock.Add(k, 1.0, 1.0, 1.0, 0.0, 0.0, 1e-4, false, rt, &feed);
  }
  for (int i = 0; i < 200 && v.Status().last_k < 199; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  CHECK(v.Status().last_k == 199);
  CHECK(v.PointsMade() == 20);
  std::string reason;
  CHECK_FALSE(feed.TakeAbort(&reason));
  CHECK(feed.RequestAbort("operator abort from the monitor") == "");
  CHECK(feed.TakeAbort(&reason));
  CHECK(reason == "operator abort from the monitor");
  CHECK_FALSE(feed.TakeAbort(&reason));  // once
  clock.Phase(rths::lockstep::kLiveAborted, &feed);  // what the clock does when it takes it
  feed.Stop();
  CHECK(v.Status().phase == "aborted");
  CHECK(v.Status().abort_by == "monitor");
  CHECK(v.Status().abort_reason == "operator abort from the monitor");
  CHECK(feed.dropped() == 0);
  CHECK(feed.RequestAbort("again") == "the run has already ended (aborted)");
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
    // The plots are redrawn at most 4 times a second (a timer after the data came): wait for it.
    CHECK(chromium.WaitFor(page, "rths.updates > " + std::to_string(updates1), 30));
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
  CHECK(code == rths::kExitPeerAbort);
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

TEST_CASE("rths run --watch --realtime: memq by default; the page's misses and latency are the run's, and a "
          "snapshot is captured mid-run") {
  rths_test::RequireTool("chromium", "chromium");
  rths_test::RequireFile("/usr/share/javascript/dygraphs/dygraph.min.js", "libjs-dygraphs");
  const fs::path dir = rths_test::TempDir("monitor_paced");
  const fs::path out_txt = dir / "run.txt";
  BackgroundRun run("exec " + std::string(RTHS_BIN_DIR) + "/rths-run " + RTHS_SOURCE_DIR +
                    "/scenarios/default.toml --compact --realtime --set run.duration_s=30 --watch --watch-port 0 "
                    "--out " + (dir / "run").string() + " > " + out_txt.string() + " 2>&1");
  const MonitorAddress a = WaitForMonitor(out_txt);
  const std::string& text = a.printed;
  CHECK(text.find("transport memq") != std::string::npos);  // a paced run's default
  const int port = a.port;
  const std::string token = a.token;
  httplib::Client c("127.0.0.1", port);
  auto state = [&] {
    const auto res = c.Get("/state?token=" + token);
    return res && res->status == 200 ? nlohmann::json::parse(res->body) : nlohmann::json();
  };
  nlohmann::json st;
  for (int i = 0; i < 400; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    st = state();
    if (!st.is_null() && st["status"]["phase"] == "running" && st["status"]["last_k"].get<std::int64_t>() > 4000) break;
  }
  REQUIRE_MESSAGE(st["status"]["phase"] == "running", st.dump());
  CHECK(st["status"]["paced"] == true);
  CHECK(st["status"]["latency_max_ms"].get<double>() > 0);  // the clock's latency, not 0.00
  CHECK(st["status"]["limits"]["stroke_mm"].get<double>() > 0);
  CHECK(st["status"]["peaks"]["disp_mm"].get<double>() > 0);
  {
    // The live page in headless Chromium shows the clock's figures, not 0.00 ms.
    rths_test::ChromiumPipe chromium(dir / "chromium_live");
    const std::string page = chromium.Open("http://127.0.0.1:" + std::to_string(port) + "/?token=" + token);
    REQUIRE(chromium.WaitFor(page, "window.rths && rths.status && rths.status.paced && rths.points > 20", 60));
    const auto shown = chromium.Evaluate(page, "[document.getElementById('latency').textContent, "
                                               "document.getElementById('misses').textContent, "
                                               "document.getElementById('lim_disp').textContent, "
                                               "String(rths.status.misses), String(rths.status.latency_max_ms)]");
    CAPTURE(shown.dump());
    const std::string latency = shown[0].get<std::string>();
    CHECK(latency.find("(max 0.00 ms)") == std::string::npos);
    CHECK(latency.find(" ms (max ") != std::string::npos);
    CHECK(shown[1].get<std::string>().rfind(shown[3].get<std::string>(), 0) == 0);  // the status's count
    CHECK(shown[2].get<std::string>().find(" of 152.4 mm (") != std::string::npos);
    CHECK(std::stod(shown[4].get<std::string>()) > 0);
  }
  // A plain headless screenshot of the snapshot page returns while the run goes on.
  const std::string shot = (dir / "snapshot.png").string();
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/?token=" + token + "&snapshot=1";
  const int rc = std::system(("timeout 60 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
                              "--user-data-dir=" + (dir / "chromium").string() + " --window-size=1400,1000 "
                              "--screenshot=" + shot + " '" + url + "' > /dev/null 2>&1").c_str());
  CHECK(rc == 0);
  REQUIRE(fs::exists(shot));
  CHECK(fs::file_size(shot) > 20000);
  CHECK(state()["status"]["phase"] == "running");  // captured mid-run
  // The snapshot page holds the points and draws them without an event stream.
  const auto page = c.Get("/?token=" + token + "&snapshot=1");
  REQUIRE(page);
  CHECK(page->body.find("window.rthsSnapshot = {") != std::string::npos);
  // Follow the page to the end: its last word is the run's summary.
  nlohmann::json last;
  for (int i = 0; i < 1200; ++i) {
    const auto now = state();
    if (now.is_null()) break;  // the monitor stopped with the run
    last = now;
    if (last["status"]["phase"] == "completed") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  CHECK(run.Wait() == 0);
  REQUIRE_MESSAGE(last["status"]["phase"] == "completed", last.dump());
  const auto summary = nlohmann::json::parse(rths_test::Slurp(dir / "run" / "summary.json"));
  const auto& rt = summary["realtime"];
  CAPTURE(rt.dump());
  CAPTURE(last.dump());
  CHECK(last["status"]["last_k"].get<std::int64_t>() + 1 == summary["steps"].get<std::int64_t>());
  CHECK(last["status"]["misses"] == rt["deadline_misses"]);
  CHECK(last["status"]["longest_miss_run"] == rt["max_consecutive_misses"]);
  CHECK(last["status"]["latency_max_ms"].get<double>() == doctest::Approx(rt["latency_max_us"].get<double>() / 1e3));
  CHECK(last["status"]["records_heard"] == last["status"]["records_expected"]);  // in-process: nothing lost
}

TEST_CASE("rths run --watch --transport memq: the page's ABORT stops an in-process run as it stops a udpm one") {
  rths_test::RequireFile("/usr/share/javascript/dygraphs/dygraph.min.js", "libjs-dygraphs");
  const fs::path dir = rths_test::TempDir("monitor_memq_abort");
  const fs::path out_txt = dir / "run.txt";
  BackgroundRun run("exec " + std::string(RTHS_BIN_DIR) + "/rths-run " + RTHS_SOURCE_DIR +
                    "/scenarios/default.toml --compact --transport memq --set run.duration_s=600 --watch "
                    "--watch-port 0 --out " + (dir / "run").string() + " > " + out_txt.string() + " 2>&1");
  const MonitorAddress a = WaitForMonitor(out_txt);
  httplib::Client c("127.0.0.1", a.port);
  const std::string token = a.token;
  nlohmann::json st;
  for (int i = 0; i < 400; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto res = c.Get("/state?token=" + token);
    if (!res || res->status != 200) continue;
    st = nlohmann::json::parse(res->body);
    if (st["status"]["phase"] == "running" && st["status"]["last_k"].get<std::int64_t>() > 2000) break;
  }
  REQUIRE_MESSAGE(st["status"]["phase"] == "running", st.dump());
  CHECK(st["status"]["paced"] == false);
  const auto abort = c.Post("/abort?token=" + token, "", "text/plain");
  REQUIRE(abort);
  CHECK(abort->status == 200);
  nlohmann::json end;
  for (int i = 0; i < 200; ++i) {
    const auto res = c.Get("/state?token=" + token);
    if (!res || res->status != 200) break;
    end = nlohmann::json::parse(res->body);
    if (end["status"]["phase"] == "aborted" && end["status"]["ended"] == true) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  CHECK(end["status"]["ended"] == true);
  CHECK(end["status"]["abort_by"] == "monitor");
  CHECK(end["status"]["abort_reason"] == "operator abort from the monitor");
  CHECK(run.Wait() == rths::kExitPeerAbort);
  const std::string output = rths_test::Slurp(out_txt);
  CAPTURE(output);
  CHECK(output.find("rths run: ABORTED: monitor aborted the run: operator abort from the monitor") != std::string::npos);
  const auto summary = nlohmann::json::parse(rths_test::Slurp(dir / "run" / "summary.json"));
  CHECK(summary["status"] == "aborted");
  CHECK(summary["stopped"] == "monitor aborted the run: operator abort from the monitor");
  const auto log = rths::io::ReadRunLog((dir / "run" / "log.lcm").string());
  CHECK_FALSE(log.truncated_tail);
  CHECK(log.CompleteSteps() == summary["steps"].get<std::int64_t>());
  CHECK(log.CompleteSteps() < 1200000);
  // The page's last word on the step count is the run's own (it was one behind after an abort).
  CHECK(end["status"]["last_k"].get<std::int64_t>() + 1 == summary["steps"].get<std::int64_t>());
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
  CHECK(run.Wait() == rths::kExitPeerAbort);
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
  CHECK(code == rths::kExitUsage);
  CHECK(out.find("rths run: --watch: cannot serve on 127.0.0.1:" + std::to_string(taken.port())) != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "run" / "log.lcm"));
  taken.Stop();
}
