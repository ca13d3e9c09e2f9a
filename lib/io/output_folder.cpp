#include "io/output_folder.h"

#include <algorithm>
#include <ctime>
#include <system_error>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::io {

namespace fs = std::filesystem;

fs::path NewOutputFolder(const std::string& label) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  const fs::path base = fs::path("runs") / (std::string(stamp) + "-" + label);
  fs::path p = base;
  for (int i = 2; fs::exists(p); ++i) p = base.string() + "-" + std::to_string(i);
  return p;
}

void RequireNewOrEmptyFolder(const fs::path& dir, std::string_view what) {
  if (dir.empty()) throw Error("--out", "empty output folder name");
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (!fs::exists(st)) return;
  if (!fs::is_directory(st)) throw Error(dir.string(), "exists and is a file, not a folder (choose another --out)");
  if (!fs::is_empty(dir, ec)) {
    throw Error(dir.string(),
                fmt::format("output folder exists and is not empty; refusing to overwrite {} (choose another --out)", what));
  }
}

const std::vector<std::string>& RecordedRunFiles() {
  static const std::vector<std::string> files = {"log.lcm", "scenario.toml", "summary.json", "signals.csv"};
  return files;
}

namespace {

/// The same file: by identity when both exist, else by their absolute normal paths.
bool SameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  return fs::absolute(a, ec).lexically_normal() == fs::absolute(b, ec).lexically_normal();
}

}  // namespace

void RefuseToReplaceRecord(const fs::path& out, const std::vector<fs::path>& inputs, std::string_view option) {
  const std::string where = fmt::format("{} {}", option, out.string());
  for (const auto& in : inputs) {
    if (!in.empty() && SameFile(out, in)) {
      throw Error(where, fmt::format("is the input {}; refusing to overwrite what is being read (choose another file)",
                                     in.string()));
    }
  }
  std::error_code ec;
  fs::path parent = fs::absolute(out, ec).parent_path();
  const std::string name = out.filename().string();
  const auto& recorded = RecordedRunFiles();
  if (fs::exists(parent / "log.lcm", ec) && std::find(recorded.begin(), recorded.end(), name) != recorded.end() &&
      fs::exists(parent / name, ec)) {
    throw Error(where, fmt::format("would replace the {} of the run in {}; refusing to overwrite a run's record "
                                   "(choose another file name)",
                                   name, parent.string()));
  }
}

}  // namespace rths::io
