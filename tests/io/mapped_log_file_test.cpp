// io::MappedLogFile (the logger's log.lcm through a shared mapping): exact bytes, a killed writer
// leaves its appends and a zero tail that readers stop at and TrimZeroTail cuts, a refused
// reservation falls back to writes that fail on the append that does not fit.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/event_log.h"
#include "io/mapped_log_file.h"
#include "test_support.h"

using namespace rths_test;
using rths::io::MappedLogFile;

namespace {

int OpenRw(const fs::path& p) { return ::open(p.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644); }

/// Event k of a made-up log: a channel and a payload of `bytes` bytes, some of them zero at the end.
std::vector<std::uint8_t> Event(std::int64_t k, std::size_t bytes = 200) {
  std::vector<std::uint8_t> payload(bytes);
  for (std::size_t i = 0; i < bytes; ++i) payload[i] = static_cast<std::uint8_t>(i + 1 < bytes / 2 ? k + i : 0);
  std::vector<std::uint8_t> out;
  rths::io::AppendEvent(&out, k, 1000 * k, "RTHS_DESIRED", payload.data(), payload.size());
  return out;
}

std::int64_t EventsIn(const fs::path& p, bool* zero_tail = nullptr) {
  rths::io::EventLogReader r(p.string());
  rths::io::LogEvent ev;
  while (r.Next(&ev)) {
  }
  CHECK_FALSE(r.truncated());
  if (zero_tail) *zero_tail = r.zero_tail();
  return r.events();
}

}  // namespace

TEST_CASE("appends, across reservations, give exactly the bytes appended; Close cuts the reserve") {
  const auto dir = TempDir("mapped_exact");
  const fs::path p = dir / "log.lcm";
  std::string expected;
  {
    MappedLogFile f(OpenRw(p), p.string());
    for (std::int64_t k = 0; k < 40000; ++k) {  // ~9 MB: several reservations, the largest too
      const auto e = Event(k);
      REQUIRE(f.Append(e.data(), e.size()).empty());
      expected.append(e.begin(), e.end());
    }
    CHECK(f.mapped());
    CHECK(f.size() == static_cast<std::int64_t>(expected.size()));
    CHECK(fs::file_size(p) > expected.size());  // reserved ahead
    // A system call per reservation (fallocate, munmap, mmap), none per append.
    CHECK(f.system_calls() < 40);
    CHECK(f.Close().empty());
  }
  CHECK(Slurp(p) == expected);
  CHECK(EventsIn(p) == 40000);
  // Its last payload ends in zero bytes: read through, nothing to cut.
  CHECK(rths::io::TrimZeroTail(p.string()) == 0);
  CHECK(Slurp(p) == expected);
}

TEST_CASE("pre-faulted from a helper thread, or in small pieces (a paced run): the same bytes; the reserve stays "
          "within one small piece") {
  const auto dir = TempDir("mapped_variants");
  for (const bool paced : {false, true}) {
    CAPTURE(paced);
    const fs::path p = dir / (paced ? "paced.lcm" : "prefaulted.lcm");
    std::string expected;
    {
      MappedLogFile f(OpenRw(p), p.string(), 0, paced ? MappedLogFile::kFirstChunkBytes : MappedLogFile::kChunkBytes);
      if (!paced) f.PrefaultInBackground();
      std::uintmax_t largest_reserve = 0;
      for (std::int64_t k = 0; k < 20000; ++k) {  // ~4.5 MB
        const auto e = Event(k);
        REQUIRE(f.Append(e.data(), e.size()).empty());
        expected.append(e.begin(), e.end());
        if (k % 97 == 0) largest_reserve = std::max(largest_reserve, fs::file_size(p) - expected.size());
      }
      if (paced) {
        CHECK(largest_reserve <= static_cast<std::uintmax_t>(MappedLogFile::kFirstChunkBytes) + 4096);
      } else {
        CHECK(largest_reserve > static_cast<std::uintmax_t>(MappedLogFile::kFirstChunkBytes) + 4096);
      }
      CHECK(f.Close().empty());
    }
    CHECK(Slurp(p) == expected);
    CHECK(EventsIn(p) == 20000);
  }
}

TEST_CASE("a writer killed without closing: every append is in the file, then zeros; TrimZeroTail cuts them") {
  const auto dir = TempDir("mapped_killed");
  const fs::path p = dir / "log.lcm";
  constexpr std::int64_t kEvents = 3000;
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    MappedLogFile f(OpenRw(p), p.string());
    for (std::int64_t k = 0; k < kEvents; ++k) {
      const auto e = Event(k);
      if (!f.Append(e.data(), e.size()).empty()) ::_exit(3);
    }
    ::kill(::getpid(), SIGKILL);  // no Close, no destructor
    ::_exit(4);
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFSIGNALED(status));
  std::string expected;
  for (std::int64_t k = 0; k < kEvents; ++k) {
    const auto e = Event(k);
    expected.append(e.begin(), e.end());
  }
  const std::string bytes = Slurp(p);
  REQUIRE(bytes.size() > expected.size());
  CHECK(bytes.compare(0, expected.size(), expected) == 0);
  CHECK(bytes.find_first_not_of('\0', expected.size()) == std::string::npos);
  bool zero_tail = false;
  CHECK(EventsIn(p, &zero_tail) == kEvents);
  CHECK(zero_tail);
  CHECK(rths::io::TrimZeroTail(p.string()) == static_cast<std::int64_t>(bytes.size() - expected.size()));
  CHECK(Slurp(p) == expected);
  CHECK(rths::io::TrimZeroTail(p.string()) == 0);
  CHECK(EventsIn(p, &zero_tail) == kEvents);
  CHECK_FALSE(zero_tail);
}

TEST_CASE("an append cut short by a kill has no sync word yet: readers end before it") {
  // What a kill in the middle of Append leaves: its bytes but the first four, then zeros.
  const auto dir = TempDir("mapped_torn");
  const fs::path p = dir / "log.lcm";
  std::string bytes;
  for (std::int64_t k = 0; k < 5; ++k) {
    const auto e = Event(k);
    bytes.append(e.begin(), e.end());
  }
  const auto torn = Event(5);
  bytes.append(4, '\0');
  bytes.append(torn.begin() + 4, torn.begin() + 100);
  bytes.append(4096, '\0');
  std::ofstream(p, std::ios::binary) << bytes;
  bool zero_tail = false;
  CHECK(EventsIn(p, &zero_tail) == 5);
  CHECK(zero_tail);
  CHECK(rths::io::TrimZeroTail(p.string()) == 4 + 96 + 4096);
  CHECK(EventsIn(p) == 5);
}

TEST_CASE("CutBack forgets the last appends; a later kill still leaves the file readable to the cut") {
  const auto dir = TempDir("mapped_cut");
  const fs::path p = dir / "log.lcm";
  MappedLogFile f(OpenRw(p), p.string());
  std::int64_t good = 0;
  for (std::int64_t k = 0; k < 10; ++k) {
    const auto e = Event(k);
    REQUIRE(f.Append(e.data(), e.size()).empty());
    if (k == 6) good = f.size();
  }
  f.CutBack(good);
  CHECK(f.size() == good);
  bool zero_tail = false;
  CHECK(EventsIn(p, &zero_tail) == 7);  // before Close: the cut is a zero word already
  CHECK(zero_tail);
  CHECK(f.Close().empty());
  CHECK(static_cast<std::int64_t>(fs::file_size(p)) == good);
  CHECK(EventsIn(p) == 7);
}

TEST_CASE("a refused reservation (file size limit): appends are written until one does not fit, whole") {
  const auto dir = TempDir("mapped_fsize");
  const fs::path p = dir / "log.lcm";
  const fs::path result = dir / "result.txt";
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit lim{100000, 100000};  // bytes: past the first 64 kB reservation, short of the next
    ::setrlimit(RLIMIT_FSIZE, &lim);
    MappedLogFile f(OpenRw(p), p.string());
    std::string why;
    std::int64_t k = 0;
    for (; k < 10000 && why.empty(); ++k) {
      const auto e = Event(k);
      why = f.Append(e.data(), e.size());
    }
    const bool mapped = f.mapped();
    const std::int64_t size = f.size();
    f.Close();
    std::ofstream(result) << k - 1 << "\n" << size << "\n" << mapped << "\n" << why << "\n";
    ::_exit(0);
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  std::ifstream in(result);
  std::int64_t failed_at = 0, size = 0;
  bool mapped = true;
  std::string why;
  in >> failed_at >> size >> mapped;
  in.ignore();
  std::getline(in, why);
  const std::int64_t event_bytes = static_cast<std::int64_t>(Event(0).size());
  CHECK_FALSE(mapped);
  CHECK(why == "writing " + p.string() + " failed: File too large");
  CHECK(failed_at == 100000 / event_bytes);  // the first append that crosses the limit
  CHECK(size == failed_at * event_bytes);
  CHECK(static_cast<std::int64_t>(fs::file_size(p)) == size);
  CHECK(EventsIn(p) == failed_at);
}
