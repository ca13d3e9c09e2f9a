// rths-log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k).
//   rths log stats LOG...     per-channel counts, duplicates, complete steps, finished or truncated
//   rths log digest LOG...    payload digest (equal digests = bit-identical runs)
//   rths log compare A B      first (channel, k) whose payload differs, exit 1 if any
// Every log is read by io::ReadRunLog's bounded reader: a file that is not an LCM event log of a
// run (random bytes, an empty file, a CSV) is refused naming the file and the byte offset.
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "io/log_compare.h"
#include "io/run_log.h"

namespace {

/// Exit codes (also in the --help footer).
enum Exit : int { kOk = 0, kDiffer = 1, kBadInput = 2, kTruncated = 3 };

constexpr const char* kExitHelp =
    "Exit codes:\n"
    "  0  stats/digest: every log is complete (the run finished: DONE is in it, no event cut short);\n"
    "     compare: identical payloads per (channel, k)\n"
    "  1  compare: the logs differ\n"
    "  2  bad input: a file cannot be read or is not an LCM event log of a run (garbage, empty,\n"
    "     corrupt); the message names the file and the byte offset; or a usage error\n"
    "  3  stats/digest: a log was read but is truncated (the run did not finish, or the file ends\n"
    "     in the middle of an event); its complete steps are reported";

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k)"};
  app.footer(kExitHelp);
  app.require_subcommand(1);
  std::vector<std::string> files;
  auto* stats = app.add_subcommand("stats", "messages per channel, duplicates, complete steps, finished or truncated");
  stats->add_option("log", files, "log.lcm files")->required();
  auto* digest = app.add_subcommand("digest", "SHA-256 of the payloads (run_id zeroed)");
  digest->add_option("log", files, "log.lcm files")->required();
  auto* compare = app.add_subcommand("compare", "compare two logs payload by payload");
  compare->add_option("log", files, "two log.lcm files")->required()->expected(2);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kOk : kBadInput;
  }
  try {
    if (*stats || *digest) {
      int code = kOk;
      for (const auto& f : files) {
        const auto log = rths::io::ReadRunLog(f);
        if (!log.Complete()) code = kTruncated;
        if (*digest) {
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
      if (pa.size() != it->second.size()) {
        std::printf("%s: %zu vs %zu steps\n", ch.c_str(), pa.size(), it->second.size());
        ++differences;
        continue;
      }
      for (std::size_t k = 0; k < pa.size(); ++k) {
        if (pa[k] != it->second[k]) {
          std::printf("%s: first difference at k = %zu\n", ch.c_str(), k);
          if (ch == "RTHS_DESIRED" || ch == "RTHS_COMMAND" || ch == "RTHS_MEASURED" || ch == "RTHS_CURRENT") {
            // How much, field by field (B - A).
            const auto d = rths::io::CompareChannel(a, b, ch, static_cast<std::int64_t>(pa.size()));
            const std::string text = rths::io::Describe(d);
            if (const auto nl = text.find('\n'); nl != std::string::npos) std::printf("%s\n", text.substr(nl + 1).c_str());
          }
          ++differences;
          break;
        }
      }
    }
    for (const auto& [ch, pb] : b.payload) {
      if (!a.payload.count(ch)) {
        std::printf("%s: only in %s (%zu steps)\n", ch.c_str(), files[1].c_str(), pb.size());
        ++differences;
      }
    }
    std::printf(differences ? "logs differ\n" : "identical payloads per (channel, k)\n");
    return differences ? kDiffer : kOk;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths log: %s\n", e.what());
    return kBadInput;
  }
}
