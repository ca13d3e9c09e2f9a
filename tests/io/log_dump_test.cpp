// io/log_dump.h (a log's messages decoded to CSV columns) and io::CompareLogs (two logs payload by
// payload): the decoding and the comparison `rths log dump` and `rths log compare` print.
#include <doctest/doctest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/log_compare.h"
#include "io/log_dump.h"
#include "io/run_log.h"

namespace {

template <typename T>
rths::io::LogEvent EventOf(const std::string& channel, const T& m) {
  rths::io::LogEvent e;
  e.channel = channel;
  e.data.resize(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(e.data.data(), 0, static_cast<int>(e.data.size()));
  return e;
}

std::vector<std::uint8_t> Bytes(std::initializer_list<std::uint8_t> b) { return b; }

}  // namespace

TEST_CASE("log dump: channel names, columns and one decoded row per message type") {
  CHECK(rths::io::DumpChannelName("measured") == "RTHS_MEASURED");
  CHECK(rths::io::DumpChannelName("rths_desired") == "RTHS_DESIRED");
  CHECK_THROWS_WITH_AS(rths::io::DumpChannelName("RTHS_ACK"),
                       doctest::Contains("one of RTHS_DESIRED (desired), RTHS_COMMAND (command)"), rths::Error);
  const auto desired = rths::io::DumpFieldNames("RTHS_DESIRED", 2);
  REQUIRE(desired.size() == 8 + 2 * 2);
  CHECK(desired[0] == "r_mm");
  CHECK(desired[8] == "x1_mm");
  CHECK(desired[11] == "abs_acc2_mm_s2");
  CHECK(rths::io::DumpFieldNames("RTHS_MEASURED", 0) == std::vector<std::string>{"y_mm", "f_kN", "current_A"});

  rths::measured_t m{};
  m.k = 7;
  m.run_id = 42;
  m.y_mm = 0.0005;
  m.f_kN = -1.25;
  m.current_A = 2.5;
  std::vector<std::string> row;
  REQUIRE(rths::io::DecodeDumpRow(EventOf("RTHS_MEASURED", m), 0, &row));
  CHECK(row == std::vector<std::string>{"7", "42", "0.0005", "-1.25", "2.5"});

  rths::desired_t d{};
  d.k = 3;
  d.n_dof = 1;
  d.x_mm = {1.5};
  d.abs_acc_mm_s2 = {-2.0};
  REQUIRE(rths::io::DecodeDumpRow(EventOf("RTHS_DESIRED", d), 2, &row));
  REQUIRE(row.size() == 2 + 8 + 2 * 2);
  CHECK(row[10] == "1.5");
  CHECK(row[11] == "");  // DOF 2 of a one-DOF message: padded
  CHECK(row[12] == "-2");
  CHECK_FALSE(rths::io::DecodeDumpRow(EventOf("OTHER", m), 0, &row));
  auto cut = EventOf("RTHS_MEASURED", m);
  cut.data.pop_back();
  CHECK_THROWS_AS(rths::io::DecodeDumpRow(cut, 0, &row), rths::Error);
}

TEST_CASE("CompareLogs: identical, a differing step, a step count, a channel in one log only") {
  rths::io::RunLog a, b;
  a.payload["RTHS_ACK"] = {Bytes({1, 2}), Bytes({3, 4})};
  b.payload = a.payload;
  CHECK(rths::io::CompareLogs(a, b).empty());

  b.payload["RTHS_ACK"][1] = Bytes({3, 5});
  auto d = rths::io::CompareLogs(a, b);
  REQUIRE(d.size() == 1);
  CHECK(d[0].kind == rths::io::PayloadDifference::kPayload);
  CHECK(d[0].first_k == 1);
  CHECK(rths::io::Describe(d[0], "A", "B") == "RTHS_ACK: first difference at k = 1\n");

  b.payload["RTHS_ACK"].pop_back();
  b.payload["RTHS_X"] = {Bytes({9})};
  d = rths::io::CompareLogs(a, b);
  REQUIRE(d.size() == 2);
  CHECK(rths::io::Describe(d[0], "A", "B") == "RTHS_ACK: 2 vs 1 steps\n");
  CHECK(rths::io::Describe(d[1], "A", "B") == "RTHS_X: only in B (1 steps)\n");
  d = rths::io::CompareLogs(b, a);
  REQUIRE(d.size() == 2);
  CHECK(rths::io::Describe(d[1], "B", "A") == "RTHS_X: only in B (1 steps)\n");
}
