#include "io/reserved_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/core.h>

namespace rths::io {

namespace {
bool WriteAll(int fd, const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(fd, data + done, size - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}
}  // namespace

bool ReserveFile(const std::string& path, std::size_t bytes, const std::string& placeholder) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  std::string text = placeholder;
  if (text.size() < bytes) text.append(bytes - text.size(), ' ');
  const bool ok = WriteAll(fd, text.data(), text.size());
  return (::close(fd) == 0) && ok;
}

bool OverwriteFile(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  bool ok = WriteAll(fd, text.data(), text.size());
  ok = ok && ::ftruncate(fd, static_cast<off_t>(text.size())) == 0;
  return (::close(fd) == 0) && ok;
}

std::string AppendWhole(int fd, const std::string& path, std::int64_t end, const void* data, std::size_t size,
                        std::int64_t* system_calls, bool* cut_back) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  std::size_t done = 0;
  if (cut_back) *cut_back = false;
  while (done < size) {
    ++*system_calls;
    const ssize_t n = ::pwrite(fd, bytes + done, size - done, static_cast<off_t>(end + static_cast<std::int64_t>(done)));
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const std::string err = n < 0 ? std::strerror(errno) : "no progress (device full?)";
    ++*system_calls;
    if (::ftruncate(fd, static_cast<off_t>(end)) != 0) {
      return fmt::format("writing {} failed: {}; cutting it back to {} bytes failed too: {}", path, err, end,
                         std::strerror(errno));
    }
    if (cut_back) *cut_back = true;
    return fmt::format("writing {} failed: {}", path, err);
  }
  return {};
}

}  // namespace rths::io
