// The bounded LCM event log reader (io/event_log.h), ReadRunLog on it (io/run_log.h) and
// `rths log` on hostile input: garbage, empty files, CSVs, corrupt headers and payloads, cut
// files, logs without DONE. Every refusal names the file and the byte offset.
#include <cstdio>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "core/error.h"
#include "core/exit_code.h"
#include "io/event_log.h"
#include "io/rig_record.h"
#include "io/run_log.h"
#include "lockstep/protocol.h"
#include "run_support.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using rths::io::EventLogReader;
using rths::io::LogEvent;
using rths::io::ReadRunLog;
using rths::io::ReadRunLogBytes;
using Bytes = std::vector<std::uint8_t>;

template <class Msg>
Bytes Encoded(const Msg& m) {
  Bytes b;
  rths::lockstep::Encode(m, &b);
  return b;
}

rths::handshake_t Handshake(std::int8_t phase, std::int64_t n_steps, double dt_s = 0.0005) {
  rths::handshake_t h{};
  h.run_id = 77;
  h.phase = phase;
  h.participant = phase == rths::lockstep::kHello ? "plant" : "clock";
  h.scenario_sha256 = std::string(64, 'a');
  h.n_steps = n_steps;
  h.dt_s = dt_s;
  h.k = phase == rths::lockstep::kDone ? n_steps : -1;
  if (phase == rths::lockstep::kGo) {
    h.roster_names = {"integrator", "plant"};
    h.roster_sha256 = {h.scenario_sha256, h.scenario_sha256};
    h.n_roster = 2;
  }
  return h;
}

/// One event to write: channel and payload.
struct Ev {
  std::string channel;
  Bytes payload;
};

/// A run of `n` steps as events: GO, then desired/command/measured/current per step (k as given
/// by `k_of`), then DONE if `done`.
std::vector<Ev> SyntheticRun(std::int64_t n, bool done = true, double dt_s = 0.0005) {
  std::vector<Ev> evs;
  evs.push_back({rths::lockstep::kChHandshake, Encoded(Handshake(rths::lockstep::kGo, n, dt_s))});
  for (std::int64_t k = 0; k < n; ++k) {
    rths::desired_t d{};
    d.run_id = 77, d.k = k, d.r_mm = 0.1 * k, d.n_dof = 2, d.x_mm = {1.0, 2.0}, d.abs_acc_mm_s2 = {3.0, 4.0};
    rths::command_t c{};
    c.run_id = 77, c.k = k, c.u_mm = 0.2 * k;
    rths::measured_t m{};
    m.run_id = 77, m.k = k, m.y_mm = 0.1 * k, m.f_kN = -0.5 * k;
    rths::current_t i{};
    i.run_id = 77, i.k = k, i.i_cmd_A = 1.0;
    evs.push_back({rths::lockstep::kChDesired, Encoded(d)});
    evs.push_back({rths::lockstep::kChCommand, Encoded(c)});
    evs.push_back({rths::lockstep::kChMeasured, Encoded(m)});
    evs.push_back({rths::lockstep::kChCurrent, Encoded(i)});
  }
  if (done) evs.push_back({rths::lockstep::kChHandshake, Encoded(Handshake(rths::lockstep::kDone, n, dt_s))});
  return evs;
}

/// The events as an LCM event log; *offsets (if given) gets where each event starts. Event i has
/// the timestamp utimes[i] if given, else 1000 + i [us].
Bytes LogBytes(const std::vector<Ev>& evs, std::vector<std::size_t>* offsets = nullptr,
               const std::vector<std::int64_t>& utimes = {}) {
  Bytes out;
  std::int64_t num = 0;
  for (const auto& e : evs) {
    if (offsets) offsets->push_back(out.size());
    const std::int64_t utime = static_cast<std::size_t>(num) < utimes.size() ? utimes[num] : 1000 + num;
    rths::io::AppendEvent(&out, num, utime, e.channel, e.payload.data(), e.payload.size());
    ++num;
  }
  return out;
}

void WriteBytes(const fs::path& p, const Bytes& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

Bytes ReadBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The message of the rths::Error that ReadRunLogBytes throws on `b` ("" and a failed check if none).
std::string ErrorOf(const Bytes& b, const std::string& name = "x.lcm") {
  try {
    ReadRunLogBytes(name, b.data(), b.size());
  } catch (const rths::Error& e) {
    return e.what();
  }
  FAIL_CHECK("expected an rths::Error");
  return "";
}

bool Contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// Runs `rths-log ARGS`; returns the exit code and puts stdout+stderr in *out.
int RunLogTool(const std::string& args, std::string* out) {
  const std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-log " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  out->clear();
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out->append(buf, n);
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void PutBigEndian32(Bytes* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * (3 - i)));
}

}  // namespace

TEST_CASE("a real run's log: every event read from the file and from memory, DONE, complete") {
  const auto dir = rths_test::TempDir("event_log_real");
  const auto s = rths::scenario::LoadScenario(
      rths_test::WriteScenario(dir, "[run]\nname = \"ten\"\nduration_s = 0.005\n").string());
  REQUIRE(s.steps() == 10);
  REQUIRE(rths_test::RunMemq({s}, dir).code == 0);
  const fs::path path = dir / "log.lcm";
  const Bytes bytes = ReadBytes(path);

  EventLogReader file(path.string());
  EventLogReader mem("mem", bytes.data(), bytes.size());
  CHECK(file.size_bytes() == bytes.size());
  LogEvent a, b;
  std::uint64_t next = 0;
  std::int64_t n = 0;
  while (file.Next(&a)) {
    REQUIRE(mem.Next(&b));
    CHECK(a.offset_bytes == next);
    CHECK(b.offset_bytes == next);
    CHECK(a.channel == b.channel);
    CHECK(a.data == b.data);
    CHECK(a.event_number == b.event_number);
    next += rths::io::EventBytes(a.channel, a.data.size());
    ++n;
  }
  CHECK_FALSE(mem.Next(&b));
  CHECK(next == bytes.size());
  CHECK(file.events() == n);
  CHECK_FALSE(file.truncated());
  CHECK_FALSE(mem.truncated());

  const auto log = ReadRunLog(path.string());
  CHECK(log.done);
  CHECK(log.Complete());
  CHECK(log.TruncationReason().empty());
  CHECK(log.n_steps == 10);
  CHECK(log.events == n);
  CHECK(log.file_bytes == bytes.size());
  CHECK(log.CompleteSteps() == 10);
  CHECK(log.unknown_events == 0);
  // The GO's roster and desired_t's arrays went through the payload checks.
  bool roster = false;
  for (const auto& h : log.handshakes) roster = roster || h.n_roster > 0;
  CHECK(roster);
  CHECK(log.desired[3].n_dof == 1);
  CHECK(rths::io::PayloadDigest(ReadRunLogBytes("mem", bytes.data(), bytes.size())) == rths::io::PayloadDigest(log));
}

TEST_CASE("garbage, empty files, CSVs, folders and missing files are refused naming the file and byte 0") {
  const auto dir = rths_test::TempDir("event_log_garbage");
  std::mt19937 rng(9);
  Bytes noise(3000);
  for (auto& x : noise) x = static_cast<std::uint8_t>(rng());
  noise[0] = 0x11;  // not the sync word's first byte
  WriteBytes(dir / "random.bin", noise);
  WriteBytes(dir / "empty.lcm", {});
  std::ofstream(dir / "signals.csv") << "k,t_s,r_mm\n0,0,0\n1,0.0005,0.1\n";
  auto error = [](const fs::path& p) {
    try {
      ReadRunLog(p.string());
    } catch (const rths::Error& e) {
      return std::string(e.what());
    }
    FAIL_CHECK("expected an rths::Error for " << p);
    return std::string();
  };
  const std::string r = error(dir / "random.bin");
  CHECK(Contains(r, (dir / "random.bin").string() + ": byte 0: no event sync word"));
  CHECK(Contains(error(dir / "empty.lcm"), "empty.lcm: empty file, not an LCM event log"));
  CHECK(Contains(error(dir / "signals.csv"), "signals.csv: byte 0: no event sync word (not an LCM event log)"));
  CHECK(Contains(error(dir), "not a regular file"));
  CHECK(Contains(error(dir / "missing.lcm"), "missing.lcm: cannot open the LCM event log"));
  CHECK_THROWS_AS(EventLogReader("buf", nullptr, 0), rths::Error);
}

TEST_CASE("corrupt event headers: sync word, channel length, channel bytes, payload length; named by offset") {
  std::vector<std::size_t> at;
  const Bytes good = LogBytes(SyntheticRun(5), &at);
  REQUIRE(at.size() == 22);
  CHECK(ReadRunLogBytes("x.lcm", good.data(), good.size()).Complete());

  Bytes b = good;
  b[at[7]] ^= 0xFF;  // sync word of event 7
  CHECK(Contains(ErrorOf(b), "x.lcm: byte " + std::to_string(at[7]) + ": no event sync word (not an LCM event log, or corrupt)"));

  b = good;
  PutBigEndian32(&b, at[3] + 24, 0x7FFFFFFFu);  // the length that crashes liblcm's reader
  CHECK(Contains(ErrorOf(b), "byte " + std::to_string(at[3]) + ": payload length 2147483647 is out of range [0, 16777216]"));
  b = good;
  PutBigEndian32(&b, at[3] + 24, 0xFFFFFFFFu);
  CHECK(Contains(ErrorOf(b), "payload length -1 is out of range"));

  for (std::uint32_t len : {0u, 64u, 0x80000000u}) {
    b = good;
    PutBigEndian32(&b, at[4] + 20, len);
    const std::string e = ErrorOf(b);
    CHECK(Contains(e, "byte " + std::to_string(at[4]) + ": channel name length"));
    CHECK(Contains(e, "out of range [1, 63]"));
  }
  b = good;
  b[at[5] + rths::io::kEventHeaderBytes + 2] = 0x07;
  CHECK(Contains(ErrorOf(b), "byte " + std::to_string(at[5]) + ": channel name byte 2 is 0x07, not printable"));

  // A payload length that overruns the file is a cut-short last event, not garbage, if it fits the
  // maximum: the events before it are read.
  b = good;
  PutBigEndian32(&b, at[21] + 24, 1000000u);
  const auto log = ReadRunLogBytes("x.lcm", b.data(), b.size());
  CHECK(log.truncated_tail);
  CHECK(log.truncated_at_byte == at[21]);
  CHECK_FALSE(log.done);
  CHECK(log.CompleteSteps() == 5);
}

TEST_CASE("a file cut at any byte reads up to its last whole event and says where it ends") {
  std::vector<std::size_t> at;
  const Bytes good = LogBytes(SyntheticRun(3), &at);
  for (std::size_t len = 1; len < good.size(); ++len) {
    CAPTURE(len);
    const auto log = ReadRunLogBytes("cut.lcm", good.data(), len);
    std::size_t whole = 0;  // events that end within the first len bytes
    while (whole < at.size() && (whole + 1 < at.size() ? at[whole + 1] : good.size()) <= len) ++whole;
    REQUIRE(log.events == static_cast<std::int64_t>(whole));
    const bool boundary = std::find(at.begin(), at.end(), len) != at.end();
    REQUIRE(log.truncated_tail == !boundary);
    if (!boundary) REQUIRE(log.truncated_at_byte == at[whole]);
    REQUIRE_FALSE(log.done);  // DONE is the last event
    REQUIRE(log.CompleteSteps() <= 3);
  }
}

TEST_CASE("a log without DONE is truncated: the run did not finish, its complete steps still count") {
  const Bytes b = LogBytes(SyntheticRun(4, /*done=*/false));
  const auto log = ReadRunLogBytes("nodone.lcm", b.data(), b.size());
  CHECK_FALSE(log.done);
  CHECK_FALSE(log.truncated_tail);
  CHECK_FALSE(log.Complete());
  CHECK(log.TruncationReason() == "truncated (the run did not finish: no DONE handshake)");
  CHECK(log.CompleteSteps() == 4);
  CHECK(log.n_steps == 4);
}

TEST_CASE("a truncated log as a rig record: its complete steps, with a warning saying so") {
  const Bytes whole = LogBytes(SyntheticRun(6, true, 0.5));
  const auto ok = rths::io::RigRecordFromRunLog(ReadRunLogBytes("whole.lcm", whole.data(), whole.size()), "whole.lcm");
  CHECK(ok.size() == 6);
  CHECK(ok.warnings.empty());
  const Bytes cut = LogBytes(SyntheticRun(6, false, 0.5));
  const auto rec = rths::io::RigRecordFromRunLog(ReadRunLogBytes("cut.lcm", cut.data(), cut.size() - 3), "cut.lcm");
  CHECK(rec.size() == 5);
  REQUIRE(rec.warnings.size() == 1);
  CHECK(rec.warnings[0].rfind("cut.lcm: the log is truncated (the run did not finish: no DONE handshake); the file "
                              "ends in the middle of an event at byte ",
                              0) == 0);
  CHECK(Contains(rec.warnings[0], "the record holds its 5 complete steps"));
}

TEST_CASE("payloads: step indices bounded, negative k, wrong types, hostile array and string lengths") {
  std::vector<std::size_t> at;
  auto evs = SyntheticRun(5);

  // k = 1e9 would resize the per-step vectors to 1e9 entries: refused with the event's offset.
  auto bad = evs;
  rths::command_t c{};
  c.run_id = 77, c.k = 1000000000;
  bad[6].payload = Encoded(c);
  at.clear();
  Bytes b = LogBytes(bad, &at);
  std::string e = ErrorOf(b);
  CHECK(Contains(e, "x.lcm: byte " + std::to_string(at[6]) + ": RTHS_COMMAND message with step index k = 1000000000"));
  CHECK(Contains(e, "cannot belong to this log (the handshake plans 5 steps: k in [0, 4])"));
  // Without a handshake, the number of events bounds k.
  bad.erase(bad.begin());
  bad.pop_back();
  at.clear();
  b = LogBytes(bad, &at);
  CHECK(Contains(ErrorOf(b), "byte " + std::to_string(at[5]) + ": RTHS_COMMAND message with step index k = 1000000000 "
                             "cannot belong to this log (the file holds only 20 events)"));
  // k = n_steps is one too many.
  bad = evs;
  c.k = 5;
  bad[6].payload = Encoded(c);
  CHECK(Contains(ErrorOf(LogBytes(bad)), "step index k = 5 cannot belong"));
  c.k = -3;
  bad[6].payload = Encoded(c);
  CHECK(Contains(ErrorOf(LogBytes(bad)), "step index k = -3 cannot belong to this log (a step index is never negative)"));

  // A command_t on the desired channel: another type's fingerprint.
  bad = evs;
  c.k = 0;
  bad[1].payload = Encoded(c);
  at.clear();
  b = LogBytes(bad, &at);
  e = ErrorOf(b);
  CHECK(Contains(e, "byte " + std::to_string(at[1]) + ": event 1 on RTHS_DESIRED: the payload is not a desired_t"));
  CHECK(Contains(e, "type fingerprint"));

  // desired_t with n_dof = 2^31-1 (lcm-gen's decode would allocate 16 GB first) and n_dof < 0.
  for (std::uint32_t n_dof : {0x7FFFFFFFu, 0xFFFFFFFFu, 3u}) {
    bad = evs;
    Bytes& p = bad[1].payload;
    // n_dof precedes two arrays of 2 doubles, then n_act = 0 (one actuator: no array) ends the message
    const std::size_t n_at = p.size() - 4 - 2 * 2 * 8 - 4;
    PutBigEndian32(&p, n_at, n_dof);
    e = ErrorOf(LogBytes(bad));
    CHECK(Contains(e, "the payload is not a desired_t"));
    CHECK(Contains(e, n_dof == 3u ? "does not fit" : "array length"));
  }
  // Bytes after the message, and a payload cut short.
  bad = evs;
  bad[2].payload.push_back(0);
  CHECK(Contains(ErrorOf(LogBytes(bad)), "1 bytes left over after the message"));
  bad = evs;
  bad[3].payload.resize(20);
  CHECK(Contains(ErrorOf(LogBytes(bad)), "the payload is not a measured_t (the message ends inside a field"));

  // Handshake strings: length 0 (lcm-gen would take it as 2^64-1), too long, no NUL; roster count.
  const std::size_t participant_at = 8 + 8 + 1;
  for (std::uint32_t len : {0u, 0x80000000u, 100000u}) {
    bad = evs;
    PutBigEndian32(&bad[0].payload, participant_at, len);
    e = ErrorOf(LogBytes(bad));
    CHECK(Contains(e, "byte 0: event 0 on RTHS_HANDSHAKE: the payload is not a handshake_t (string length"));
  }
  bad = evs;
  bad[0].payload[participant_at + 4 + 5] = 'x';  // "clock\0": the NUL
  CHECK(Contains(ErrorOf(LogBytes(bad)), "lacks its terminating NUL"));
  bad = evs;
  {
    Bytes& p = bad[0].payload;
    // n_roster follows run_id, phase, participant, sha256, n_steps, dt_s, k.
    const std::size_t n_roster_at = 8 + 8 + 1 + (4 + 6) + (4 + 65) + 8 + 8 + 8;
    PutBigEndian32(&p, n_roster_at, 0x7FFFFFFFu);
    CHECK(Contains(ErrorOf(LogBytes(bad)), "array length 2147483647 is out of range"));
  }
}

TEST_CASE("rths log: garbage, empty files and CSVs fail with the file and offset; truncated logs are told") {
  const auto dir = rths_test::TempDir("event_log_tool");
  std::mt19937 rng(3);
  Bytes noise(2000);
  for (auto& x : noise) x = static_cast<std::uint8_t>(rng());
  noise[0] = 0x42;  // not the sync word's first byte
  WriteBytes(dir / "garbage.lcm", noise);
  WriteBytes(dir / "empty.lcm", {});
  std::ofstream(dir / "other.txt") << "t_s,u_mm\n0,1\n";
  WriteBytes(dir / "good.lcm", LogBytes(SyntheticRun(6)));
  const Bytes unfinished = LogBytes(SyntheticRun(6, false));
  WriteBytes(dir / "cut.lcm", Bytes(unfinished.begin(), unfinished.end() - 5));
  const std::string d = dir.string() + "/";
  std::string out;

  for (const char* sub : {"stats", "digest"}) {
    CAPTURE(sub);
    CHECK(RunLogTool(std::string(sub) + " " + d + "garbage.lcm", &out) == 2);
    CHECK(Contains(out, d + "garbage.lcm: byte 0: no event sync word"));
    CHECK(RunLogTool(std::string(sub) + " " + d + "empty.lcm", &out) == 2);
    CHECK(Contains(out, d + "empty.lcm: empty file, not an LCM event log"));
    CHECK(RunLogTool(std::string(sub) + " " + d + "other.txt", &out) == 2);
    CHECK(Contains(out, d + "other.txt: byte 0: no event sync word"));
  }
  CHECK(RunLogTool("compare " + d + "garbage.lcm " + d + "other.txt", &out) == 2);
  CHECK_FALSE(Contains(out, "identical"));
  CHECK(RunLogTool("compare " + d + "good.lcm " + d + "other.txt", &out) == 2);
  CHECK(Contains(out, "other.txt: byte 0"));

  CHECK(RunLogTool("stats " + d + "good.lcm", &out) == 0);
  CHECK(Contains(out, "6 complete steps of 6 planned"));
  CHECK(Contains(out, "finished (the clock's DONE is in the log)"));
  CHECK(RunLogTool("stats " + d + "cut.lcm", &out) == rths::kExitTruncated);  // 12 (3 before issue 45: it collided with kExitLockstep)
  CHECK(Contains(out, "truncated (the run did not finish: no DONE handshake)"));
  CHECK(Contains(out, "the file ends in the middle of an event at byte"));
  CHECK(Contains(out, "valid up to      step k = 4 (steps 0..4 complete)"));
  CHECK(RunLogTool("compare " + d + "good.lcm " + d + "good.lcm", &out) == 0);
  CHECK(RunLogTool("compare " + d + "good.lcm " + d + "cut.lcm", &out) == 1);
  CHECK(RunLogTool("--help", &out) == 0);
  CHECK(Contains(out, "Exit codes:"));
}

TEST_CASE("regression (fuzz_event_log): steps/s from timestamps at the ends of int64 does not overflow") {
  // Found by fuzz/event_log_fuzz.cpp (UBSan): ComputeMetrics took last - first desired_t timestamp
  // in int64. The timestamps are whatever the file says.
  const auto evs = SyntheticRun(3);
  std::vector<std::int64_t> utimes(evs.size(), 0);
  utimes[1] = std::numeric_limits<std::int64_t>::min() + 1;  // desired_t k = 0
  utimes[9] = std::numeric_limits<std::int64_t>::max();      // desired_t k = 2
  const Bytes b = LogBytes(evs, nullptr, utimes);
  const auto log = ReadRunLogBytes("utime.lcm", b.data(), b.size());
  REQUIRE(log.first_desired_utime == utimes[1]);
  REQUIRE(log.last_desired_utime == utimes[9]);
  const auto m = rths::io::ComputeMetrics(log);
  const double span_s = (static_cast<double>(utimes[9]) - static_cast<double>(utimes[1])) * 1e-6;
  CHECK(m.steps == 3);
  CHECK(m.steps_per_s > 0.0);  // an int64 difference wraps to a negative span: 0 steps/s
  CHECK(m.steps_per_s == doctest::Approx(2.0 / span_s));
}
