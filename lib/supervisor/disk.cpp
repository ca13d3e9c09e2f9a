#include "supervisor/disk.h"

#include <sys/statvfs.h>

#include <fmt/format.h>

#include "core/error.h"
#include "participants/factory.h"

namespace rths::supervisor {

namespace fs = std::filesystem;

OutputEstimate EstimateOutput(const scenario::Scenario& s) {
  const auto b = participants::EstimateOutputBytes(s);
  return {b.log, b.csv, b.total() + static_cast<double>(kSummaryReserve) + 256.0 * 1024.0};
}

double FreeBytes(fs::path dir) {
  dir = fs::absolute(dir);
  while (!fs::exists(dir) && dir.has_parent_path() && dir != dir.parent_path()) dir = dir.parent_path();
  struct statvfs st {};
  if (::statvfs(dir.c_str(), &st) != 0) return -1.0;
  return static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
}

void CheckDiskSpace(const fs::path& out, const scenario::Scenario& s, const OutputEstimate& estimate) {
  const double free_bytes = FreeBytes(out);
  if (free_bytes >= 0 && estimate.total_bytes > free_bytes) {
    throw Error(out.string(), fmt::format("not enough free disk space: this run writes about {} ({} steps), and "
                                          "the file system has {} free; free some space, shorten run.duration_s "
                                          "or choose another --out",
                                          Megabytes(estimate.total_bytes), s.steps(), Megabytes(free_bytes)));
  }
}

std::string Megabytes(double bytes) { return fmt::format("{:.1f} MB", bytes / 1e6); }

}  // namespace rths::supervisor
