#include "io/output_folder.h"

#include <ctime>

namespace rths::io {

std::filesystem::path NewOutputFolder(const std::string& label) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  const std::filesystem::path base = std::filesystem::path("runs") / (std::string(stamp) + "-" + label);
  std::filesystem::path p = base;
  for (int i = 2; std::filesystem::exists(p); ++i) p = base.string() + "-" + std::to_string(i);
  return p;
}

}  // namespace rths::io
