// io::SignalsCsvWriter: every row added is in signals.csv, in order, byte for byte as formatted on
// the step; a full queue waits, never drops; a failed write (a file size limit, a full disk) is
// reported by Add naming the file and leaves the file on a whole row.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/core.h>

#include "io/signals_csv_writer.h"
#include "test_support.h"

namespace {

using namespace rths_test;
using rths::io::SignalsCsvWriter;

SignalsCsvWriter::Row RowOf(std::int64_t k) {
  SignalsCsvWriter::Row r{k, static_cast<double>(k) * 0.0005, {}};
  for (std::size_t j = 0; j < r.values.size(); ++j) r.values[j] = std::sin(0.001 * static_cast<double>(k) + j) * 1e3 / 7.0;
  return r;
}

/// The file signals.csv should hold for rows 0 .. n-1: the header, each row by FormatSignalsRow.
std::string Expected(std::int64_t n) {
  std::string s = rths::io::kSignalsCsvHeader;
  char row[rths::io::kSignalsRowMaxBytes + 1];
  for (std::int64_t k = 0; k < n; ++k) {
    const auto r = RowOf(k);
    s.append(row, rths::io::FormatSignalsRow(row, r.k, r.t_s, r.values));
  }
  return s;
}

/// In a child process (the limits stay there): rows are added to `path` until Add fails or `max`
/// rows; the child writes "<rows added> <threaded at the start> <threaded at the end> <Add's error>"
/// to `result` and exits 0.
void AddUntilFailure(const fs::path& path, const fs::path& result, std::int64_t max, rlim_t fsize_limit) {
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead of killing us
    if (fsize_limit != RLIM_INFINITY) {
      const rlimit r{fsize_limit, fsize_limit};
      ::setrlimit(RLIMIT_FSIZE, &r);
    }
    std::string why;
    std::int64_t k = 0;
    bool threaded_at_start = false, threaded_at_end = false;
    {
      SignalsCsvWriter w(path.string());
      threaded_at_start = w.threaded();
      for (; k < max && why.empty(); ++k) why = w.Add(RowOf(k));
      threaded_at_end = w.threaded();
      if (why.empty()) why = w.Close();
    }
    std::ofstream(result) << k << ' ' << threaded_at_start << ' ' << threaded_at_end << ' ' << why;
    ::_exit(0);
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
}

/// The file holds the header and rows 0 .. n-1 for some n, each whole; returns n.
std::int64_t WholeRows(const fs::path& p) {
  const std::string text = Slurp(p);
  REQUIRE(!text.empty());
  CHECK(text.back() == '\n');
  const std::int64_t n = static_cast<std::int64_t>(std::count(text.begin(), text.end(), '\n')) - 1;
  CHECK(text == Expected(n));
  return n;
}

}  // namespace

TEST_CASE("signals.csv through the writer thread: every row, in order, the bytes the step would write") {
  const auto dir = TempDir("csv_writer");
  const auto path = dir / "signals.csv";
  // Far more rows than the queue holds, added as fast as this thread can: the queue fills (Add
  // waits: stalls), nothing is dropped.
  const std::int64_t n = 20 * static_cast<std::int64_t>(SignalsCsvWriter::kQueueRows);
  SignalsCsvWriter w(path.string());
  REQUIRE_MESSAGE(w.threaded(), "this file system refused the reservation: the writer thread is not used");
  for (std::int64_t k = 0; k < n; ++k) REQUIRE(w.Add(RowOf(k)).empty());
  CHECK(w.Close().empty());
  CHECK(w.Close().empty());  // once; later calls say the same
  MESSAGE("stalls on a full queue: " << w.stalls() << ", system calls: " << w.system_calls());
  // Adding is a copy, formatting a microsecond: the queue filled and Add waited, counted.
  CHECK(w.stalls() > 0);
  CHECK(Slurp(path) == Expected(n));
  // One write per 64 kB of rows, a reservation per stretch: far fewer calls than rows.
  CHECK(w.system_calls() < n / 100);
  const std::string after = w.Add(RowOf(n));
  CHECK(after.find(path.string()) != std::string::npos);
  CHECK(after.find("closed") != std::string::npos);
  CHECK(Slurp(path) == Expected(n));  // nothing added after Close
}

TEST_CASE("signals.csv: a few rows, then the writer closed while idle or busy, holds exactly those rows") {
  const auto dir = TempDir("csv_writer_close");
  for (const std::int64_t n : {0, 1, 7, 5000}) {
    CAPTURE(n);
    const auto path = dir / ("signals_" + std::to_string(n) + ".csv");
    {
      SignalsCsvWriter w(path.string());
      for (std::int64_t k = 0; k < n; ++k) REQUIRE(w.Add(RowOf(k)).empty());
    }  // the destructor closes
    CHECK(Slurp(path) == Expected(n));
    CHECK(fs::file_size(path) == Expected(n).size());  // the reserved space past the rows is not in the size
  }
}

TEST_CASE("signals.csv: a write the file size limit refuses (EFBIG) is reported by Add, naming the file; the file "
          "ends on a whole row") {
  const auto dir = TempDir("csv_writer_efbig");
  const auto path = dir / "signals.csv", result = dir / "result.txt";
  AddUntilFailure(path, result, 100000, 1 << 20);  // about 4000 rows fit
  std::ifstream in(result);
  std::int64_t added = 0;
  bool threaded_at_start = false, threaded_at_end = false;
  in >> added >> threaded_at_start >> threaded_at_end;
  CHECK(threaded_at_start);  // a reservation is not a write: the file size limit does not refuse it
  std::string why;
  std::getline(in, why);
  CAPTURE(why);
  CHECK(why.find("writing " + path.string() + " failed: File too large") != std::string::npos);
  const std::int64_t rows = WholeRows(path);
  CHECK(rows > 1000);
  CHECK(rows < added);  // the rows in the queue when the write failed are the ones missing
  CHECK(fs::file_size(path) <= (1u << 20));
}

TEST_CASE("signals.csv on a full disk (tmpfs, ENOSPC), root only (mount): every row but the failing one is "
          "there, the file on a whole row" * doctest::skip(!IsRoot())) {
  // 1 MB: no space to reserve at all, each row is written by its Add. 4 MB: the first reservations
  // are granted (rows go through the writer thread), a later one is refused, the writer stops
  // once it has written what it took and Add writes from there on.
  const auto dir = TempDir("csv_writer_enospc");
  for (const char* size : {"1m", "4m"}) {
    CAPTURE(size);
    const auto mnt = dir / size;
    fs::create_directories(mnt);
    REQUIRE_MESSAGE(std::system(fmt::format("mount -t tmpfs -o size={} tmpfs {}", size, mnt.string()).c_str()) == 0,
                    "mount -t tmpfs failed as root");
    const auto path = mnt / "signals.csv", result = dir / (std::string(size) + ".txt");
    AddUntilFailure(path, result, 1000000, RLIM_INFINITY);
    std::ifstream in(result);
    std::int64_t added = 0;
    bool threaded_at_start = false, threaded_at_end = false;
    in >> added >> threaded_at_start >> threaded_at_end;
    CHECK(threaded_at_start == (std::string(size) == "4m"));
    CHECK_FALSE(threaded_at_end);
    std::string why;
    std::getline(in, why);
    CAPTURE(why);
    CHECK(why.find("writing " + path.string() + " failed: No space left on device") != std::string::npos);
    CHECK(WholeRows(path) == added - 1);
    std::system(("umount " + mnt.string()).c_str());
  }
}
