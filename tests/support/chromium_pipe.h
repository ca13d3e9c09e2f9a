#pragma once
// A headless Chromium driven by its DevTools protocol over a pipe (--remote-debugging-pipe: the
// browser reads commands on fd 3 and writes replies and events on fd 4, each a JSON text ended by
// a NUL byte), for the tests that load a page, read its state, click and take a screenshot.
// No WebSocket and no network port are needed.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

namespace rths_test {

class ChromiumPipe {
 public:
  using Clock = std::chrono::steady_clock;

  /// Starts `chromium --headless` with a fresh profile in `profile` and a `width` x `height` window.
  explicit ChromiumPipe(const std::filesystem::path& profile, int width = 1400, int height = 1000) {
    int to_browser[2], from_browser[2];
    if (::pipe(to_browser) != 0 || ::pipe(from_browser) != 0) throw std::runtime_error("pipe failed");
    const std::string user_dir = "--user-data-dir=" + profile.string();
    const std::string size = "--window-size=" + std::to_string(width) + "," + std::to_string(height);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(to_browser[0], 3);
      ::dup2(from_browser[1], 4);
      for (int fd = 5; fd < 1024; ++fd) ::close(fd);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      ::execlp("chromium", "chromium", "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-extensions", "--hide-scrollbars", "--remote-debugging-pipe", user_dir.c_str(), size.c_str(),
               "about:blank", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(to_browser[0]);
    ::close(from_browser[1]);
    out_ = to_browser[1];
    in_ = from_browser[0];
  }

  ~ChromiumPipe() {
    try {
      Send("Browser.close", {}, "");
    } catch (...) {
    }
    const auto until = Clock::now() + std::chrono::seconds(5);
    while (::waitpid(pid_, nullptr, WNOHANG) == 0) {
      if (Clock::now() > until) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ::close(out_);
    ::close(in_);
  }
  ChromiumPipe(const ChromiumPipe&) = delete;
  ChromiumPipe& operator=(const ChromiumPipe&) = delete;

  /// Sends a command and waits for its reply's "result"; throws on an error reply or a timeout.
  nlohmann::json Call(const std::string& method, const nlohmann::json& params = nlohmann::json::object(),
                      const std::string& session = "", double timeout_s = 30) {
    const int id = Send(method, params, session);
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
    while (true) {
      const nlohmann::json m = Read(until, method);
      if (!m.contains("id") || m["id"] != id) continue;  // an event, or another reply
      if (m.contains("error")) throw std::runtime_error(method + ": " + m["error"].dump());
      return m.value("result", nlohmann::json::object());
    }
  }

  /// Opens `url` in a new tab of `width` x `height`; returns the session to address it.
  std::string Open(const std::string& url, int width = 1400, int height = 1000) {
    const auto target = Call("Target.createTarget", {{"url", "about:blank"}});
    const auto attached = Call("Target.attachToTarget", {{"targetId", target["targetId"]}, {"flatten", true}});
    const std::string session = attached["sessionId"];
    Call("Emulation.setDeviceMetricsOverride",
         {{"width", width}, {"height", height}, {"deviceScaleFactor", 1}, {"mobile", false}}, session);
    Call("Page.navigate", {{"url", url}}, session);
    return session;
  }

  /// The value of a JavaScript expression in the page (JSON null if it threw or is undefined).
  nlohmann::json Evaluate(const std::string& session, const std::string& expression) {
    const auto r = Call("Runtime.evaluate", {{"expression", expression}, {"returnByValue", true}}, session);
    if (r.contains("exceptionDetails") || !r.contains("result")) return nullptr;
    return r["result"].value("value", nlohmann::json(nullptr));
  }

  /// Polls `expression` every 0.1 s until it is true; false after `timeout_s`.
  bool WaitFor(const std::string& session, const std::string& expression, double timeout_s) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
    while (Clock::now() < until) {
      if (Evaluate(session, "Boolean(" + expression + ")") == true) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  /// Saves a PNG of the page's viewport.
  void Screenshot(const std::string& session, const std::filesystem::path& png) {
    const auto r = Call("Page.captureScreenshot", {{"format", "png"}}, session);
    std::ofstream(png, std::ios::binary) << Base64Decode(r["data"].get<std::string>());
  }

  static std::string Base64Decode(const std::string& in) {
    std::string out;
    std::uint32_t bits = 0;
    int count = 0;
    for (const char c : in) {
      int v;
      if (c >= 'A' && c <= 'Z') v = c - 'A';
      else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
      else if (c >= '0' && c <= '9') v = c - '0' + 52;
      else if (c == '+') v = 62;
      else if (c == '/') v = 63;
      else continue;  // '=' padding, line breaks
      bits = (bits << 6) | static_cast<std::uint32_t>(v);
      if ((count += 6) >= 8) {
        count -= 8;
        out.push_back(static_cast<char>((bits >> count) & 0xff));
      }
    }
    return out;
  }

 private:
  int Send(const std::string& method, const nlohmann::json& params, const std::string& session) {
    nlohmann::json m = {{"id", ++next_id_}, {"method", method}, {"params", params}};
    if (!session.empty()) m["sessionId"] = session;
    const std::string text = m.dump() + '\0';
    for (std::size_t done = 0; done < text.size();) {
      const ssize_t n = ::write(out_, text.data() + done, text.size() - done);
      if (n <= 0) throw std::runtime_error("chromium: the DevTools pipe is closed (did chromium start?)");
      done += static_cast<std::size_t>(n);
    }
    return next_id_;
  }

  /// The next message from the browser.
  nlohmann::json Read(Clock::time_point until, const std::string& waiting_for) {
    while (true) {
      if (const auto end = buffer_.find('\0'); end != std::string::npos) {
        const std::string text = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        return nlohmann::json::parse(text);
      }
      const int ms = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count());
      if (ms <= 0) throw std::runtime_error("chromium: no reply to " + waiting_for + " in time");
      pollfd p{in_, POLLIN, 0};
      if (::poll(&p, 1, ms) <= 0) continue;
      char chunk[65536];
      const ssize_t n = ::read(in_, chunk, sizeof chunk);
      if (n <= 0) throw std::runtime_error("chromium: the DevTools pipe closed while waiting for " + waiting_for);
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }

  pid_t pid_ = -1;
  int out_ = -1, in_ = -1;
  int next_id_ = 0;
  std::string buffer_;
};

}  // namespace rths_test
