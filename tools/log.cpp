// rths-log: inspect and compare run logs (log.lcm) by decoded payload per (channel, k).
//   rths log stats LOG        per-channel counts, duplicates, complete steps, abort reason
//   rths log digest LOG...    payload digest (equal digests = bit-identical runs)
//   rths log compare A B      first (channel, k) whose payload differs, exit 1 if any
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "io/run_log.h"

int main(int argc, char** argv) {
  CLI::App app{"rths log: inspect and compare run logs by decoded payload per (channel, k)"};
  app.require_subcommand(1);
  std::vector<std::string> files;
  auto* stats = app.add_subcommand("stats", "messages per channel, duplicates, complete steps");
  stats->add_option("log", files, "log.lcm files")->required();
  auto* digest = app.add_subcommand("digest", "SHA-256 of the payloads (run_id zeroed)");
  digest->add_option("log", files, "log.lcm files")->required();
  auto* compare = app.add_subcommand("compare", "compare two logs payload by payload");
  compare->add_option("log", files, "two log.lcm files")->required()->expected(2);
  CLI11_PARSE(app, argc, argv);
  try {
    if (*stats || *digest) {
      for (const auto& f : files) {
        const auto log = rths::io::ReadRunLog(f);
        if (*digest) {
          std::printf("%s  %s\n", rths::io::PayloadDigest(log).c_str(), f.c_str());
          continue;
        }
        std::printf("%s: run %lld, %lld complete steps\n", f.c_str(), static_cast<long long>(log.run_id),
                    static_cast<long long>(log.CompleteSteps()));
        for (const auto& [ch, n] : log.count) {
          const auto d = log.duplicates.count(ch) ? log.duplicates.at(ch) : 0;
          std::printf("  %-16s %8lld messages, %lld duplicates\n", ch.c_str(), static_cast<long long>(n),
                      static_cast<long long>(d));
        }
        std::printf("  handshake        %8zu messages\n", log.handshakes.size());
        if (const auto r = log.AbortReason(); !r.empty()) std::printf("  aborted: %s\n", r.c_str());
      }
      return 0;
    }
    const auto a = rths::io::ReadRunLog(files[0]);
    const auto b = rths::io::ReadRunLog(files[1]);
    int differences = 0;
    for (const auto& [ch, pa] : a.payload) {
      const auto it = b.payload.find(ch);
      const std::size_t nb = it == b.payload.end() ? 0 : it->second.size();
      if (pa.size() != nb) {
        std::printf("%s: %zu vs %zu steps\n", ch.c_str(), pa.size(), nb);
        ++differences;
        continue;
      }
      for (std::size_t k = 0; k < pa.size(); ++k) {
        if (pa[k] != it->second[k]) {
          std::printf("%s: first difference at k = %zu\n", ch.c_str(), k);
          ++differences;
          break;
        }
      }
    }
    if (a.payload.size() != b.payload.size()) ++differences;
    std::printf(differences ? "logs differ\n" : "identical payloads per (channel, k)\n");
    return differences ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths log: %s\n", e.what());
    return 2;
  }
}
