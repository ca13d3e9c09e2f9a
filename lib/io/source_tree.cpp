#include "io/source_tree.h"

#include <unistd.h>

#include <system_error>
#include <vector>

#include "core/error.h"

namespace rths::io {

namespace fs = std::filesystem;

fs::path FindSourceFile(const std::string& rel, const fs::path& root) {
  std::vector<fs::path> roots;
  if (!root.empty()) roots.push_back(root);
  std::error_code ec;
  for (fs::path p = fs::current_path(ec); !ec && !p.empty(); p = p.parent_path()) {
    roots.push_back(p);
    if (p == p.root_path()) break;
  }
  char exe[4096];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    exe[n] = '\0';
    for (fs::path p = fs::path(exe).parent_path(); !p.empty(); p = p.parent_path()) {
      roots.push_back(p);
      if (p == p.root_path()) break;
    }
  }
  roots.push_back(fs::path(__FILE__).parent_path().parent_path().parent_path());  // lib/io/..
  for (const auto& r : roots) {
    if (fs::exists(r / rel, ec)) return fs::weakly_canonical(r / rel);
  }
  throw Error(rel, "not found in the source tree (set RTHS_SOURCE_DIR to the rths checkout, or run "
                   "from inside it)");
}

}  // namespace rths::io
