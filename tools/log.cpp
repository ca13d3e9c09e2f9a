// rths-log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k).
//   rths log stats LOG...     per-channel counts, duplicates, complete steps, finished or truncated
//   rths log digest LOG...    payload digest (equal digests = bit-identical runs)
//   rths log compare A B      first (channel, k) whose payload differs, exit 1 if any
//   rths log dump LOG         decoded messages as CSV (every channel, or --channel NAME), for users
//                             without an LCM binding
// Every log is read by io::ReadRunLog's bounded reader: a file that is not an LCM event log of a
// run (random bytes, an empty file, a CSV) is refused naming the file and the byte offset.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "core/error.h"
#include "io/csv.h"
#include "io/event_log.h"
#include "io/log_compare.h"
#include "io/output_folder.h"
#include "io/run_log.h"
#include "lockstep/exit_code.h"
#include "lockstep/protocol.h"

namespace {

/// The exit codes (lockstep::LogExitCode) in the --help footer.

constexpr const char* kExitHelp =
    "Exit codes:\n"
    "  0  stats/digest/dump: every log is complete (the run finished: DONE is in it, no event cut short);\n"
    "     compare: identical payloads per (channel, k)\n"
    "  1  compare: the logs differ\n"
    "  2  bad input: a file cannot be read or is not an LCM event log of a run (garbage, empty,\n"
    "     corrupt); the message names the file and the byte offset; or a usage error\n"
    "  3  stats/digest/dump: a log was read but is truncated (the run did not finish, or the file ends\n"
    "     in the middle of an event); its complete steps are reported (dump: every complete event)";

void PrintStats(const std::string& f, const rths::io::RunLog& log) {
  const long long steps = log.CompleteSteps();
  std::printf("%s: run %lld, %lld complete steps", f.c_str(), static_cast<long long>(log.run_id), steps);
  if (log.n_steps > 0) std::printf(" of %lld planned", static_cast<long long>(log.n_steps));
  std::printf(", %lld events, %llu bytes\n", static_cast<long long>(log.events),
              static_cast<unsigned long long>(log.file_bytes));
  if (log.Complete()) {
    std::printf("  status           finished (the clock's DONE is in the log)\n");
  } else {
    std::printf("  status           %s\n", log.TruncationReason().c_str());
    if (steps > 0) {
      std::printf("  valid up to      step k = %lld (steps 0..%lld complete)\n", steps - 1, steps - 1);
    } else {
      std::printf("  valid up to      no complete step\n");
    }
  }
  for (const auto& [ch, n] : log.count) {
    const auto d = log.duplicates.count(ch) ? log.duplicates.at(ch) : 0;
    std::printf("  %-16s %8lld messages, %lld duplicates\n", ch.c_str(), static_cast<long long>(n),
                static_cast<long long>(d));
  }
  std::printf("  handshake        %8zu messages\n", log.handshakes.size());
  if (log.unknown_events > 0)
    std::printf("  other channels   %8lld messages\n", static_cast<long long>(log.unknown_events));
  if (const auto r = log.AbortReason(); !r.empty()) std::printf("  aborted: %s\n", r.c_str());
}


// --- log dump ---------------------------------------------------------------------------
// One CSV row per message, in log order. Every message has run_id and k; the field names are those
// of lcmtypes/*.lcm, arrays one column per element (x_mm[0] -> x1_mm, abs_acc_mm_s2[0] ->
// abs_acc1_mm_s2, as in rths export).

/// A channel the dump decodes: its short name and its columns after k and run_id.
struct DumpChannel {
  const char* channel;
  const char* short_name;
};
constexpr DumpChannel kDumpChannels[] = {{rths::lockstep::kChDesired, "desired"},
                                         {rths::lockstep::kChCommand, "command"},
                                         {rths::lockstep::kChMeasured, "measured"},
                                         {rths::lockstep::kChCurrent, "current"},
                                         {rths::lockstep::kChHandshake, "handshake"}};

/// The channel named by `name` (RTHS_DESIRED or desired, any case); throws listing the choices.
std::string DumpChannelName(const std::string& name) {
  std::string upper = name, lower = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  std::string choices;
  for (const auto& c : kDumpChannels) {
    if (upper == c.channel || lower == c.short_name) return c.channel;
    choices += fmt::format("{}{} ({})", choices.empty() ? "" : ", ", c.channel, c.short_name);
  }
  throw rths::Error("--channel " + name, "not a channel of a run log; one of " + choices);
}

/// Shortest text that reads back as the same double ("0.0005", not "0.00050000000000000001").
std::string Num(double v) { return fmt::format("{}", v); }
std::string Num(std::int64_t v) { return std::to_string(v); }

const char* PhaseName(int phase) {
  switch (phase) {
    case rths::lockstep::kRequest: return "REQUEST";
    case rths::lockstep::kHello: return "HELLO";
    case rths::lockstep::kGo: return "GO";
    case rths::lockstep::kAbort: return "ABORT";
    case rths::lockstep::kDone: return "DONE";
    case rths::lockstep::kBye: return "BYE";
    case rths::lockstep::kClose: return "CLOSE";
    case rths::lockstep::kHeartbeat: return "HEARTBEAT";
    default: return "?";
  }
}

/// The columns of `channel` after k and run_id (n_dof: the largest desired_t.n_dof of the log).
std::vector<std::string> DumpFieldNames(const std::string& channel, int n_dof) {
  namespace ls = rths::lockstep;
  if (channel == ls::kChDesired) {
    std::vector<std::string> f{"r_mm",           "rd_mm_s",       "rdd_mm_s2",        "rddd_mm_s3",
                               "acc_prev_mm_s2", "vel_prev_mm_s", "ground_acc_mm_s2", "n_dof"};
    for (int i = 1; i <= n_dof; ++i) f.push_back(fmt::format("x{}_mm", i));
    for (int i = 1; i <= n_dof; ++i) f.push_back(fmt::format("abs_acc{}_mm_s2", i));
    return f;
  }
  if (channel == ls::kChCommand) return {"u_mm", "u_ff_mm", "u_fb_mm"};
  if (channel == ls::kChMeasured) return {"y_mm", "f_kN", "current_A"};
  if (channel == ls::kChCurrent) return {"i_cmd_A", "f_desired_kN"};
  // roster: "name=sha256" per participant of a GO, separated by ';'.
  return {"phase", "phase_name", "participant", "scenario_sha256", "n_steps", "dt_s", "roster", "reason"};
}

/// One event's payload as T (ReadRunLog already checked that it decodes exactly).
template <typename T>
T Decode(const rths::io::LogEvent& e) {
  T m;
  if (m.decode(e.data.data(), 0, static_cast<int>(e.data.size())) != static_cast<int>(e.data.size()))
    throw rths::Error(fmt::format("byte {}", e.offset_bytes), "payload does not decode as " + e.channel);
  return m;
}
/// Decodes one event as its channel's type. Returns false for a channel the dump does not know.
/// k, run_id and the fields (DumpFieldNames order; arrays padded with "" up to n_dof) go to *out.
bool DecodeRow(const rths::io::LogEvent& e, int n_dof, std::vector<std::string>* out) {
  namespace ls = rths::lockstep;
  out->clear();
  if (e.channel == ls::kChDesired) {
    const auto m = Decode<rths::desired_t>(e);
    *out = {Num(m.k),           Num(m.run_id),         Num(m.r_mm),          Num(m.rd_mm_s),
            Num(m.rdd_mm_s2),   Num(m.rddd_mm_s3),     Num(m.acc_prev_mm_s2), Num(m.vel_prev_mm_s),
            Num(m.ground_acc_mm_s2), Num(std::int64_t{m.n_dof})};
    for (int i = 0; i < n_dof; ++i) out->push_back(i < m.n_dof ? Num(m.x_mm[static_cast<std::size_t>(i)]) : "");
    for (int i = 0; i < n_dof; ++i)
      out->push_back(i < m.n_dof ? Num(m.abs_acc_mm_s2[static_cast<std::size_t>(i)]) : "");
  } else if (e.channel == ls::kChCommand) {
    const auto m = Decode<rths::command_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.u_mm), Num(m.u_ff_mm), Num(m.u_fb_mm)};
  } else if (e.channel == ls::kChMeasured) {
    const auto m = Decode<rths::measured_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.y_mm), Num(m.f_kN), Num(m.current_A)};
  } else if (e.channel == ls::kChCurrent) {
    const auto m = Decode<rths::current_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.i_cmd_A), Num(m.f_desired_kN)};
  } else if (e.channel == ls::kChHandshake) {
    const auto m = Decode<rths::handshake_t>(e);
    std::string roster;
    for (int i = 0; i < m.n_roster; ++i)
      roster += fmt::format("{}{}={}", i ? ";" : "", m.roster_names[static_cast<std::size_t>(i)],
                            m.roster_sha256[static_cast<std::size_t>(i)]);
    *out = {Num(m.k),         Num(m.run_id),    Num(std::int64_t{m.phase}), PhaseName(m.phase), m.participant,
            m.scenario_sha256, Num(m.n_steps), Num(m.dt_s),                roster,             m.reason};
  } else {
    return false;
  }
  return true;
}

/// Writes the dump of `path` (already read as `log`) to `out`: with `channel` empty every known
/// channel, one header of all their fields (a message leaves the other channels' cells empty);
/// else that channel's messages only. Returns the rows written; *skipped counts the events on
/// channels it leaves out.
std::int64_t Dump(const std::string& path, const rths::io::RunLog& log, const std::string& channel, std::FILE* out,
                  const std::string& out_name, std::int64_t* skipped) {
  int n_dof = 0;
  for (const auto& d : log.desired) n_dof = std::max(n_dof, static_cast<int>(d.n_dof));
  // Where each channel's fields start in a row (after channel, k, run_id when dumping all).
  std::vector<std::string> header;
  std::vector<std::pair<std::string, std::size_t>> offsets;
  if (channel.empty()) header.push_back("channel");
  header.insert(header.end(), {"k", "run_id"});
  for (const auto& c : kDumpChannels) {
    if (!channel.empty() && channel != c.channel) continue;
    offsets.emplace_back(c.channel, header.size());
    const auto names = DumpFieldNames(c.channel, n_dof);
    header.insert(header.end(), names.begin(), names.end());
  }
  const auto write = [&](const std::vector<std::string>& fields) {
    const std::string rec = rths::io::CsvRecord(fields);
    if (std::fwrite(rec.data(), 1, rec.size(), out) != rec.size())
      throw rths::Error(out_name, fmt::format("write failed: {}", std::strerror(errno)));
  };
  write(header);
  rths::io::EventLogReader reader(path);
  rths::io::LogEvent e;
  std::vector<std::string> decoded, row(header.size());
  std::int64_t rows = 0;
  *skipped = 0;
  while (reader.Next(&e)) {
    const auto at = std::find_if(offsets.begin(), offsets.end(), [&](const auto& o) { return o.first == e.channel; });
    if (at == offsets.end() || !DecodeRow(e, n_dof, &decoded)) {
      ++*skipped;
      continue;
    }
    std::fill(row.begin(), row.end(), std::string());
    std::size_t col = 0;
    if (channel.empty()) row[col++] = e.channel;
    row[col++] = decoded[0];  // k
    row[col++] = decoded[1];  // run_id
    std::copy(decoded.begin() + 2, decoded.end(), row.begin() + static_cast<std::ptrdiff_t>(at->second));
    write(row);
    ++rows;
  }
  return rows;
}

/// `rths log dump`: the CSV to standard output or --csv (no half-written file left behind).
int DumpCommand(const std::string& path, const std::string& channel_arg, const std::string& csv) {
  const std::string channel = channel_arg.empty() ? "" : DumpChannelName(channel_arg);
  if (!csv.empty()) rths::io::RefuseToReplaceRecord(csv, {path}, "--csv");
  const auto log = rths::io::ReadRunLog(path);
  std::FILE* out = stdout;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(nullptr, std::fclose);
  if (!csv.empty()) {
    file.reset(std::fopen(csv.c_str(), "wb"));
    if (!file) throw rths::Error(csv, fmt::format("cannot write the file: {}", std::strerror(errno)));
    out = file.get();
  }
  std::int64_t skipped = 0, rows = 0;
  const std::string out_name = csv.empty() ? "standard output" : csv;
  try {
    rows = Dump(path, log, channel, out, out_name, &skipped);
    if (std::fflush(out) != 0 || (file && std::fclose(file.release()) != 0))
      throw rths::Error(out_name, fmt::format("write failed: {}", std::strerror(errno)));
  } catch (...) {
    // No half-written file is left behind (a device or FIFO is left alone).
    std::error_code ec;
    file.reset();
    if (!csv.empty() && std::filesystem::is_regular_file(std::filesystem::symlink_status(csv, ec)))
      std::filesystem::remove(csv, ec);
    throw;
  }
  if (!csv.empty())
    std::fprintf(stderr, "rths log: %s: %lld messages to %s\n", path.c_str(), static_cast<long long>(rows),
                 csv.c_str());
  if (channel.empty() && skipped > 0)
    std::fprintf(stderr, "rths log: note: %s: %lld events on other channels not dumped\n", path.c_str(),
                 static_cast<long long>(skipped));
  if (!log.Complete()) {
    std::fprintf(stderr, "rths log: note: %s: %s; dumped every complete event\n", path.c_str(),
                 log.TruncationReason().c_str());
    return rths::lockstep::kLogTruncated;
  }
  return rths::lockstep::kLogOk;
}

/// `rths log stats` and `rths log digest`.
int StatsCommand(const std::vector<std::string>& files, bool digest) {
  int code = rths::lockstep::kLogOk;
  for (const auto& f : files) {
    const auto log = rths::io::ReadRunLog(f);
    if (!log.Complete()) code = rths::lockstep::kLogTruncated;
    if (digest) {
      std::printf("%s  %s\n", rths::io::PayloadDigest(log).c_str(), f.c_str());
      if (!log.Complete())
        std::fprintf(stderr, "rths log: %s: %s; the digest covers what it holds (%lld complete steps)\n", f.c_str(),
                     log.TruncationReason().c_str(), static_cast<long long>(log.CompleteSteps()));
      continue;
    }
    PrintStats(f, log);
  }
  return code;
}

/// Prints where channel `ch` of the two logs first differs (and by how much, for the step channels);
/// returns whether it does.
bool CompareChannelPayloads(const rths::io::RunLog& a, const rths::io::RunLog& b, const std::string& ch,
                            const std::vector<std::vector<std::uint8_t>>& pa,
                            const std::vector<std::vector<std::uint8_t>>& pb) {
  if (pa.size() != pb.size()) {
    std::printf("%s: %zu vs %zu steps\n", ch.c_str(), pa.size(), pb.size());
    return true;
  }
  for (std::size_t k = 0; k < pa.size(); ++k) {
    if (pa[k] == pb[k]) continue;
    std::printf("%s: first difference at k = %zu\n", ch.c_str(), k);
    if (ch == "RTHS_DESIRED" || ch == "RTHS_COMMAND" || ch == "RTHS_MEASURED" || ch == "RTHS_CURRENT") {
      // How much, field by field (B - A).
      const auto d = rths::io::CompareChannel(a, b, ch, static_cast<std::int64_t>(pa.size()));
      const std::string text = rths::io::Describe(d);
      if (const auto nl = text.find('\n'); nl != std::string::npos) std::printf("%s\n", text.substr(nl + 1).c_str());
    }
    return true;
  }
  return false;
}

/// `rths log compare A B`.
int CompareCommand(const std::vector<std::string>& files) {
  const auto a = rths::io::ReadRunLog(files[0]);
  const auto b = rths::io::ReadRunLog(files[1]);
  for (const auto* l : {&a, &b})
    if (!l->Complete()) std::fprintf(stderr, "rths log: note: %s: %s\n", l->source.c_str(), l->TruncationReason().c_str());
  int differences = 0;
  for (const auto& [ch, pa] : a.payload) {
    const auto it = b.payload.find(ch);
    if (it == b.payload.end()) {
      std::printf("%s: only in %s (%zu steps)\n", ch.c_str(), files[0].c_str(), pa.size());
      ++differences;
      continue;
    }
    if (CompareChannelPayloads(a, b, ch, pa, it->second)) ++differences;
  }
  for (const auto& [ch, pb] : b.payload) {
    if (!a.payload.count(ch)) {
      std::printf("%s: only in %s (%zu steps)\n", ch.c_str(), files[1].c_str(), pb.size());
      ++differences;
    }
  }
  std::printf(differences ? "logs differ\n" : "identical payloads per (channel, k)\n");
  return differences ? rths::lockstep::kLogDiffer : rths::lockstep::kLogOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k)"};
  rths::tools::NameCommand(app, "log");
  app.footer(kExitHelp);
  app.require_subcommand(1);
  std::vector<std::string> files;
  auto* stats = app.add_subcommand("stats", "messages per channel, duplicates, complete steps, finished or truncated");
  stats->add_option("log", files, "log.lcm files")->required();
  auto* digest = app.add_subcommand("digest", "SHA-256 of the payloads (run_id zeroed)");
  digest->add_option("log", files, "log.lcm files")->required();
  auto* compare = app.add_subcommand("compare", "compare two logs payload by payload");
  compare->add_option("log", files, "two log.lcm files")->required()->expected(2);
  auto* dump = app.add_subcommand(
      "dump", "decoded messages as CSV, one row per message in log order: channel, k, run_id, then the "
              "channel's fields (lcmtypes/*.lcm names and units; arrays one column per element: x1_mm, ...)");
  std::string dump_channel, dump_csv;
  dump->add_option("log", files, "log.lcm file")->required()->expected(1);
  dump->add_option("--channel", dump_channel,
                   "only this channel, its fields as columns (no channel column): RTHS_DESIRED, RTHS_COMMAND, "
                   "RTHS_MEASURED, RTHS_CURRENT, RTHS_HANDSHAKE, or desired, command, measured, current, "
                   "handshake (default: every channel, all their fields, other channels' cells empty)");
  dump->add_option("--csv", dump_csv, "write the CSV to this file (default: standard output)");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    if (*dump) return DumpCommand(files[0], dump_channel, dump_csv);
    if (*stats || *digest) return StatsCommand(files, static_cast<bool>(*digest));
    return CompareCommand(files);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths log: %s\n", e.what());
    return rths::lockstep::kLogBadInput;
  }
}
