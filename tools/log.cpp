// rths-log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k).
//   rths log stats LOG...     per-channel counts, duplicates, complete steps, finished or truncated
//   rths log digest LOG...    payload digest (equal digests = bit-identical runs)
//   rths log compare A B      first (channel, k) whose payload differs, exit 1 if any
//   rths log dump LOG         decoded messages as CSV (every channel, or --channel NAME), for users
//                             without an LCM binding
// Every log is read by io::ReadRunLog's bounded reader: a file that is not an LCM event log of a
// run (random bytes, an empty file, a CSV) is refused naming the file and the byte offset.
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
#include "io/log_compare.h"
#include "io/log_dump.h"
#include "io/output_folder.h"
#include "io/run_log.h"
#include "core/exit_code.h"

namespace {

/// The exit codes (core/exit_code.h) in the --help footer.

constexpr const char* kExitHelp =
    "Exit codes:\n"
    "  0  stats/digest/dump: every log is complete (the run finished: DONE is in it, no event cut short);\n"
    "     compare: identical payloads per (channel, k)\n"
    "  1  compare: the logs differ\n"
    "  2  bad input: a file cannot be read or is not an LCM event log of a run (garbage, empty,\n"
    "     corrupt); the message names the file and the byte offset; or a usage error\n"
    "  12 stats/digest/dump: a log was read but is truncated (the run did not finish, or the file ends\n"
    "     in the middle of an event); its complete steps are reported (dump: every complete event)\n"
    "(one table for every rths program: docs/lockstep.md \"Exit codes\"; 12 was 3 before issue 45)";

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


/// `rths log dump`: the CSV to standard output or --csv (no half-written file left behind).
int DumpCommand(const std::string& path, const std::string& channel_arg, const std::string& csv) {
  const std::string channel = channel_arg.empty() ? "" : rths::io::DumpChannelName(channel_arg);
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
    rows = rths::io::WriteLogDump(path, log, channel, out, out_name, &skipped);
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
    return rths::kExitTruncated;
  }
  return rths::kExitOk;
}

/// `rths log stats` and `rths log digest`.
int StatsCommand(const std::vector<std::string>& files, bool digest) {
  int code = rths::kExitOk;
  for (const auto& f : files) {
    const auto log = rths::io::ReadRunLog(f);
    if (!log.Complete()) code = rths::kExitTruncated;
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

/// `rths log compare A B` (io::CompareLogs).
int CompareCommand(const std::vector<std::string>& files) {
  const auto a = rths::io::ReadRunLog(files[0]);
  const auto b = rths::io::ReadRunLog(files[1]);
  for (const auto* l : {&a, &b})
    if (!l->Complete()) std::fprintf(stderr, "rths log: note: %s: %s\n", l->source.c_str(), l->TruncationReason().c_str());
  const auto differences = rths::io::CompareLogs(a, b);
  for (const auto& d : differences) std::fputs(rths::io::Describe(d, files[0], files[1]).c_str(), stdout);
  std::printf(!differences.empty() ? "logs differ\n" : "identical payloads per (channel, k)\n");
  return !differences.empty() ? rths::kExitNegative : rths::kExitOk;
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
    return rths::kExitUsage;
  }
}
