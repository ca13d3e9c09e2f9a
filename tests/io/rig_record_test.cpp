// Rig records (io/rig_record.h): the CSV format of docs/diagnosis.md with every error it names, our
// LCM run logs as records, and the UTFSM measured data (io/utfsm.h).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "core/error.h"
#include "io/rig_record.h"
#include "io/run_log.h"
#include "io/utfsm.h"
#include "models/servo_linear.h"
#include "run_support.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using rths::io::ReadRigRecord;
using rths::io::RigRecord;

/// A valid record text: 2.5 s at dt = 0.0005 (5000 rows), columns in the given order.
std::string Valid(const std::string& header = "t_s,u_mm,y_mm,f_kN,i_A", double dt = 0.0005, std::size_t n = 5000) {
  std::string s = "# rths rig record v1\n# dt_s: " + std::to_string(dt) + "\n# lab: UIUC\n# specimen: MR damper\n" +
                   header + "\n";
  for (std::size_t k = 0; k < n; ++k) {
    const double t = k * dt;
    s += std::to_string(t) + "," + std::to_string(std::sin(t)) + "," + std::to_string(0.9 * std::sin(t)) + ",0.5,0";
    if (header.find("r_mm") != std::string::npos || header.find("extra") != std::string::npos) s += ",1.5";
    s += "\n";
  }
  return s;
}

fs::path Write(const fs::path& dir, const std::string& name, const std::string& text) {
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

/// Replaces the line number `line` (1-based) of `text`.
std::string ReplaceLine(const std::string& text, int line, const std::string& with) {
  std::string out;
  std::size_t pos = 0;
  for (int l = 1; pos < text.size(); ++l) {
    const auto e = text.find('\n', pos);
    const std::string cur = text.substr(pos, e - pos);
    out += (l == line ? with : cur) + "\n";
    pos = e + 1;
  }
  return out;
}

/// Runs ReadRigRecord on `text` and returns the error's where() and problem().
std::pair<std::string, std::string> ErrorOf(const fs::path& dir, const std::string& text) {
  const auto p = Write(dir, "bad.csv", text);
  try {
    ReadRigRecord(p.string());
  } catch (const rths::Error& e) {
    return {e.where(), e.problem()};
  }
  return {"", "no error"};
}

bool Contains(const std::string& s, const std::string& part) {
  CAPTURE(s);
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("rig record: read, metadata, column order, optional r_mm, unknown columns; write round-trips") {
  const auto dir = rths_test::TempDir("rig_record_ok");
  const auto a = ReadRigRecord(Write(dir, "a.csv", Valid()).string());
  CHECK(a.size() == 5000);
  CHECK(a.dt_s == 0.0005);
  CHECK_FALSE(a.has_r());
  CHECK(a.Meta("lab") == "UIUC");
  CHECK(a.Meta("specimen") == "MR damper");
  CHECK(a.warnings.empty());
  CHECK(a.u_mm[100] == doctest::Approx(std::sin(0.05)).epsilon(1e-5));
  CHECK(a.y_mm[100] == doctest::Approx(0.9 * std::sin(0.05)).epsilon(1e-5));

  // Columns in another order, r_mm present, an unknown column.
  std::string text = Valid("t_s,u_mm,y_mm,f_kN,i_A,r_mm");
  const auto b = ReadRigRecord(Write(dir, "b.csv", text).string());
  CHECK(b.has_r());
  CHECK(b.r_mm[7] == 1.5);
  const auto c = ReadRigRecord(
      Write(dir, "c.csv", ReplaceLine(Valid("t_s,u_mm,y_mm,f_kN,i_A,extra"), 5, "t_s,y_mm,u_mm,f_kN,i_A,extra"))
          .string());
  CHECK(c.u_mm[100] == doctest::Approx(0.9 * std::sin(0.05)).epsilon(1e-5));  // the renamed column
  REQUIRE(c.warnings.size() == 1);
  CHECK(c.warnings[0].find("c.csv:5") != std::string::npos);
  CHECK(c.warnings[0].find("\"extra\"") != std::string::npos);

  // Write and read back.
  const auto p = dir / "round.csv";
  rths::io::WriteRigRecord(b, p.string());
  const auto d = ReadRigRecord(p.string());
  CHECK(d.size() == b.size());
  CHECK(d.dt_s == b.dt_s);
  CHECK(d.metadata == b.metadata);
  for (std::size_t k = 0; k < d.size(); k += 97) {
    CHECK(d.t_s[k] == doctest::Approx(b.t_s[k]).epsilon(1e-9));
    CHECK(d.u_mm[k] == doctest::Approx(b.u_mm[k]).epsilon(1e-9));
    CHECK(d.y_mm[k] == doctest::Approx(b.y_mm[k]).epsilon(1e-9));
    CHECK(d.f_kN[k] == b.f_kN[k]);
    CHECK(d.i_A[k] == b.i_A[k]);
    CHECK(d.r_mm[k] == b.r_mm[k]);
  }
}

TEST_CASE("rig record: every bad input is an error naming the file, the line and the problem") {
  const auto dir = rths_test::TempDir("rig_record_bad");
  const std::string bad = (dir / "bad.csv").string();
  const std::string ok = Valid();
  // Lines: 1 magic, 2 dt_s, 3-4 metadata, 5 header, 6.. data (row k on line 6 + k).
  {
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 5, "t_s,u_mm,f_kN,i_A"));
    CHECK(where == bad + ":5");
    CHECK(what.find("missing column \"y_mm\"") != std::string::npos);
  }
  {  // a missing data row: a gap
    std::string text = ok;
    const auto p = text.find("\n" + std::to_string(100 * 0.0005) + ",");
    text.erase(p + 1, text.find('\n', p + 1) - p);
    const auto [where, what] = ErrorOf(dir, text);
    CHECK(where == bad + ":106");
    CHECK(what.find("gap") != std::string::npos);
  }
  {  // a step that is off, but not a gap
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 206, "0.10010,0.1,0.09,0.5,0"));
    CHECK(where == bad + ":206");
    CHECK(what.find("non-uniform") != std::string::npos);
  }
  {  // time going backwards
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 206, "0.0,0.1,0.09,0.5,0"));
    CHECK(where == bad + ":206");
    CHECK(what.find("does not increase") != std::string::npos);
  }
  for (const std::string nan : {"nan", "NaN", "inf", "abc", ""}) {
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 300, "0.147," + nan + ",0.09,0.5,0"));
    CHECK(where == bad + ":300");
    CHECK(what.find("column u_mm") != std::string::npos);
    CHECK(what.find("not a finite number") != std::string::npos);
  }
  {  // fewer than 2 s: 1.5 s of rows
    const auto [where, what] = ErrorOf(dir, Valid("t_s,u_mm,y_mm,f_kN,i_A", 0.0005, 3000));
    CHECK(where == bad + ":3005");
    CHECK(what.find("at least 2 s") != std::string::npos);
  }
  {  // dt disagrees with the header
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 2, "# dt_s: 0.001"));
    CHECK(where == bad + ":2");
    CHECK(what.find("disagrees") != std::string::npos);
  }
  {  // no dt_s line
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 2, "# note: no step"));
    CHECK(where == bad + ":5");
    CHECK(what.find("dt_s") != std::string::npos);
  }
  {  // not a rig record
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 1, "t_s,u_mm"));
    CHECK(where == bad + ":1");
    CHECK(what.find("rths rig record v1") != std::string::npos);
  }
  {  // wrong number of fields
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 50, "0.022,0.1,0.09,0.5"));
    CHECK(where == bad + ":50");
    CHECK(what.find("4 fields, expected 5") != std::string::npos);
  }
  {  // duplicated column
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 5, "t_s,u_mm,y_mm,f_kN,u_mm"));
    CHECK(where == bad + ":5");
    CHECK(what.find("twice") != std::string::npos);
  }
  CHECK_THROWS_WITH_AS(ReadRigRecord((dir / "absent.csv").string()), doctest::Contains("cannot open"), rths::Error);
}

TEST_CASE("UTFSM chirp_0A: conversion, offsets from the idle stretch, trimmed at |u| > 0.4 mm") {
  const auto rec = rths::io::ReadUtfsmActuator(RTHS_SOURCE_DIR "/data/utfsm/actuator/chirp_0A.txt");
  CHECK(rec.dt_s == 0.001);
  CHECK(rec.size() > 50000);
  CHECK(rec.size() < 52000);
  CHECK(std::abs(rec.u_mm.front()) > 0.4);
  CHECK(std::abs(rec.u_mm.back()) > 0.4);
  double umax = 0.0, ymax = 0.0, fmax = 0.0;
  for (std::size_t k = 0; k < rec.size(); ++k) {
    umax = std::max(umax, std::abs(rec.u_mm[k]));
    ymax = std::max(ymax, std::abs(rec.y_mm[k]));
    fmax = std::max(fmax, std::abs(rec.f_kN[k]));
    REQUIRE(rec.i_A[k] == 0.0);
  }
  // data/README.md: about +/-2.4 mm and +/-0.7 kN after conversion; offsets about -0.21, -0.30 mm, -0.24 kN.
  CHECK(umax == doctest::Approx(2.1).epsilon(0.15));
  CHECK(ymax == doctest::Approx(2.1).epsilon(0.15));
  CHECK(fmax < 0.8);
  CHECK(fmax > 0.3);
  CHECK(rec.Meta("offsets_subtracted").find("u_mm -0.21") != std::string::npos);
  CHECK(rec.Meta("offsets_subtracted").find("y_mm -0.29") != std::string::npos);
  CHECK(rec.Meta("offsets_subtracted").find("f_kN -0.24") != std::string::npos);
  CHECK(rths::io::ReadUtfsm(RTHS_SOURCE_DIR "/data/utfsm/actuator/chirp_0A.txt").size() == rec.size());
  // Converted and read back as a CSV rig record.
  const auto dir = rths_test::TempDir("utfsm");
  rths::io::WriteRigRecord(rec, (dir / "chirp.csv").string());
  const auto back = ReadRigRecord((dir / "chirp.csv").string());
  CHECK(back.size() == rec.size());
  CHECK(back.Meta("current_A") == "0");
}

TEST_CASE("UTFSM damper files: u = y = x, F in kN, the current from the name, dt from t") {
  CHECK(rths::io::UtfsmCurrentFromName("a/25mm0x5Hz0x75A.txt") == 0.75);
  CHECK(rths::io::UtfsmCurrentFromName("10mm1Hz1A.txt") == 1.0);
  CHECK(rths::io::UtfsmCurrentFromName("2mm5Hz0A.txt") == 0.0);
  CHECK(rths::io::UtfsmCurrentFromName("25mm0x1Hz0x25A.txt") == 0.25);
  CHECK_THROWS_AS(rths::io::UtfsmCurrentFromName("chirp_0A.txt"), rths::Error);
  int files = 0;
  for (const auto& e : fs::directory_iterator(RTHS_SOURCE_DIR "/data/utfsm/mr_damper")) {
    const auto rec = rths::io::ReadUtfsm(e.path().string());
    const std::string name = e.path().filename().string();
    CAPTURE(name);
    ++files;
    const bool slow = name.rfind("25mm", 0) == 0 || name.rfind("2mm", 0) == 0;
    CHECK(rec.dt_s == (slow ? 0.005 : 0.001));
    CHECK(rec.DurationS() >= 2.0);
    CHECK(rec.u_mm == rec.y_mm);
    CHECK(rec.i_A.front() == rths::io::UtfsmCurrentFromName(name));
    double fmax = 0.0;
    for (double f : rec.f_kN) fmax = std::max(fmax, std::abs(f));
    CHECK(fmax > 0.1);
    CHECK(fmax < 2.0);
  }
  CHECK(files == 30);
}

TEST_CASE("an LCM run log of ours as a rig record: u = command, y = measured, i = current command, r = desired") {
  const auto dir = rths_test::TempDir("rig_record_log");
  const auto s = rths::scenario::LoadScenario(rths_test::WriteScenario(dir, R"(
[run]
duration_s = 2.5
[structure]
mode = "predefined"
[structure.desired]
kind = "blwn"
band_hz = 50.0
rms_mm = 0.254
seed = 4
[controller]
kind = "none"
[plant]
actuator = "0.0A"
specimen = "none"
[semiactive]
mode = "constant"
current_A = 2.5
)").string());
  REQUIRE(rths_test::RunMemq({s}, dir).code == 0);
  const auto path = (dir / "log.lcm").string();
  CHECK(rths::io::IsLcmLog(path));
  CHECK_FALSE(rths::io::IsLcmLog(RTHS_SOURCE_DIR "/data/utfsm/mr_damper/2mm5Hz0A.txt"));
  const auto log = rths::io::ReadRunLog(path);
  const auto rec = rths::io::ReadRecordAny(path);
  REQUIRE(rec.size() == static_cast<std::size_t>(s.steps()));
  CHECK(rec.dt_s == s.run.dt_s);
  CHECK(rec.has_r());
  const auto servo = rths::models::LinearServo::Make(s.plant.actuator, s.run.dt_s);
  rths::models::LinearServoState z;
  for (std::size_t k = 0; k < rec.size(); ++k) {
    REQUIRE(rec.u_mm[k] == log.command[k].u_mm);
    REQUIRE(rec.y_mm[k] == log.measured[k].y_mm);
    REQUIRE(rec.f_kN[k] == log.measured[k].f_kN);
    REQUIRE(rec.i_A[k] == log.current[k].i_cmd_A);
    REQUIRE(rec.r_mm[k] == log.desired[k].r_mm);
    REQUIRE(rec.u_mm[k] == rec.r_mm[k]);  // no controller
    REQUIRE(rec.i_A[k] == 2.5);
    // y_k is the ZOH servo's response to u_0 .. u_{k-1} (docs/lockstep.md).
    REQUIRE(rec.y_mm[k] == doctest::Approx(rths::models::Output(servo, z)).epsilon(1e-9));
    rths::models::Step(servo, &z, rec.u_mm[k]);
  }
  // A log too short for a record.
  RigRecord shortrec = rec;
  shortrec.t_s.resize(100), shortrec.u_mm.resize(100), shortrec.y_mm.resize(100), shortrec.f_kN.resize(100),
      shortrec.i_A.resize(100), shortrec.r_mm.resize(100);
  CHECK_THROWS_WITH_AS(rths::io::ValidateRigRecord(shortrec, "x"), doctest::Contains("at least 2 s"), rths::Error);
}

TEST_CASE("rig record: non-finite and absurd values are refused with file and line; bounds are inclusive") {
  const auto dir = rths_test::TempDir("rig_record_bounds");
  const std::string bad = (dir / "bad.csv").string();
  const std::string ok = Valid();
  // Row k is on line 6 + k; line 300 holds t = 0.147. Columns: t_s,u_mm,y_mm,f_kN,i_A.
  for (const std::string v : {"nan", "-nan", "inf", "-inf", "1e999", "-1e400", "infinity"}) {
    CAPTURE(v);
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 300, "0.147,0.1," + v + ",0.5,0"));
    CHECK(where == bad + ":300");
    CHECK(what == "column y_mm: \"" + v + "\" is not a finite number");
  }
  struct Case {
    std::string row, column, range;
  };
  for (const Case& c : std::vector<Case>{{"0.147,0.1,1e308,0.5,0", "y_mm: 1e+308", "[-10000, 10000] mm"},
                                         {"0.147,-10000.5,0.1,0.5,0", "u_mm: -10000.5", "[-10000, 10000] mm"},
                                         {"0.147,0.1,0.1,100001,0", "f_kN: 100001", "[-100000, 100000] kN"},
                                         {"0.147,0.1,0.1,0.5,-100.5", "i_A: -100.5", "[-100, 100] A"},
                                         {"2e10,0.1,0.1,0.5,0", "t_s: 20000000000", "[-1e+10, 1e+10] s"}}) {
    CAPTURE(c.row);
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 300, c.row));
    CHECK(where == bad + ":300");
    CHECK(what.find("column " + c.column + " is out of range " + c.range) != std::string::npos);
  }
  {  // r_mm has the displacement bound too
    const std::string text = ReplaceLine(Valid("t_s,u_mm,y_mm,f_kN,i_A,r_mm"), 300, "0.147,0.1,0.1,0.5,0,-2e4");
    const auto [where, what] = ErrorOf(dir, text);
    CHECK(where == bad + ":300");
    CHECK(what.find("column r_mm: -20000 is out of range [-10000, 10000] mm") != std::string::npos);
  }
  // The bounds themselves are allowed.
  const auto edge = rths::io::ParseRigRecord(ReplaceLine(ok, 300, "0.147,-10000,10000,-100000,100"), "edge.csv");
  CHECK(edge.u_mm[294] == -1e4);
  CHECK(edge.y_mm[294] == 1e4);
  CHECK(edge.f_kN[294] == -1e5);
  CHECK(edge.i_A[294] == 100.0);
  for (const std::string dt : {"0", "-0.0005", "1e-7", "2", "nan", "1e999"}) {
    CAPTURE(dt);
    const auto [where, what] = ErrorOf(dir, ReplaceLine(ok, 2, "# dt_s: " + dt));
    CHECK(where == bad + ":2");
    CHECK(what == "dt_s must be a number in [1e-06, 1] s (got \"" + dt + "\")");
  }
  // In-memory records get the same checks, named by sample.
  auto rec = rths::io::ParseRigRecord(ok, "mem.csv");
  rths::io::ValidateRigRecord(rec, "mem");
  rec.f_kN[17] = 1e308;
  CHECK_THROWS_WITH_AS(rths::io::ValidateRigRecord(rec, "mem"),
                       doctest::Contains("mem: sample 17: column f_kN: 1e+308 is out of range"), rths::Error);
  rec.f_kN[17] = 0.0;
  rec.dt_s = 1e-300;
  CHECK_THROWS_WITH_AS(rths::io::ValidateRigRecord(rec, "mem"), doctest::Contains("dt_s must be in [1e-06, 1] s"),
                       rths::Error);
}

TEST_CASE("rig record: ParseRigRecord on text is ReadRigRecord on the file") {
  const auto dir = rths_test::TempDir("rig_record_parse");
  const std::string text = Valid("t_s,u_mm,y_mm,f_kN,i_A,r_mm");
  const auto path = Write(dir, "p.csv", text).string();
  const auto a = ReadRigRecord(path);
  const auto b = rths::io::ParseRigRecord(text, path);
  CHECK(a.source == b.source);
  CHECK(a.t_s == b.t_s);
  CHECK(a.y_mm == b.y_mm);
  CHECK(a.r_mm == b.r_mm);
  CHECK(a.metadata == b.metadata);
  CHECK_THROWS_WITH_AS(rths::io::ParseRigRecord("", "empty.csv"),
                       doctest::Contains("empty.csv:1: not a rig record: the first line must be"), rths::Error);
}

TEST_CASE("UTFSM files: absurd values and headers are refused with file and line") {
  const auto dir = rths_test::TempDir("utfsm_bounds");
  std::string rows;
  for (int k = 0; k < 3000; ++k) rows += fmt::format("{:.7g} {:.7g} 0 {:.7g}\n", k * 0.001, std::sin(k * 0.01), 100.0);
  const auto damper = Write(dir, "25mm1Hz0x5A.txt", rows).string();
  CHECK(rths::io::ReadUtfsmDamper(damper).size() == 3000);
  auto error_of = [&](const std::string& name, const std::string& text) -> std::string {
    const auto p = Write(dir, name, text).string();
    try {
      rths::io::ReadUtfsm(p);
    } catch (const rths::Error& e) {
      return e.what();
    }
    FAIL_CHECK("expected an rths::Error for " << name);
    return "";
  };
  CHECK(Contains(error_of("25mm1Hz0x5A.txt", ReplaceLine(rows, 40, "0.039 1e308 0 100")),
                 "25mm1Hz0x5A.txt:40: x = 1e+308 is out of range [-10000, 10000] mm"));
  CHECK(Contains(error_of("25mm1Hz0x5A.txt", ReplaceLine(rows, 41, "0.04 0.1 0 1e300")),
                 "25mm1Hz0x5A.txt:41: F / 1000 = 1e+297 is out of range"));
  CHECK(Contains(error_of("25mm1Hz0x5A.txt", ReplaceLine(rows, 42, "0.041 0.1 0 1e999")),
                 "25mm1Hz0x5A.txt:42: expected four numbers"));
  CHECK(Contains(error_of("25mm1Hz500A.txt", rows), "cannot read the current '500' from the file name"));
  // The DAQ export: header size and sampling interval bounded, channels bounded after conversion.
  CHECK(Contains(error_of("daq.txt", "Header Size: 1e300\n"), "daq.txt:1: not a DAQ export"));
  CHECK(Contains(error_of("daq.txt", "Header Size: 3\nSampling Interval: 1e-300\nSample Number, Date/Time, CHANNEL0, "
                                     "CHANNEL1, CHANNEL2, Events\n"),
                 "daq.txt:2: bad Sampling Interval"));
  std::string daq = "Header Size: 3\nSampling Interval: 0.001\nSample Number, Date/Time, CHANNEL0, CHANNEL1, CHANNEL2, "
                    "Events\n";
  for (int k = 0; k < 10; ++k) daq += fmt::format("{},x,0,0,{}\n", k, k == 7 ? "1e306" : "0");
  CHECK(Contains(error_of("daq.txt", daq), "daq.txt:11: u_mm (10 CHANNEL2) = 1e+307 is out of range"));
}

namespace {
/// A record at 3004.8 Hz whose time column is written with `decimals` decimals, dt_s in the header
/// `header_dt` (3 s), optionally without row `skip`.
std::string AtRate(int decimals, double header_dt, std::size_t skip = 0) {
  const double dt = 1.0 / 3004.8;
  std::string s = fmt::format("# rths rig record v1\n# dt_s: {:.12g}\nt_s,u_mm,y_mm,f_kN,i_A\n", header_dt);
  for (std::size_t k = 0; k < 9015; ++k) {
    if (skip != 0 && k == skip) continue;
    const double t = k * dt;
    s += fmt::format("{:.{}f},{},{},{},0\n", t, decimals, std::sin(t), 0.9 * std::sin(t), 0.5);
  }
  return s;
}
std::string MessageOf(const std::string& text, rths::io::TimeAxis axis) {
  try {
    rths::io::ParseRigRecord(text, "r.csv", axis);
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("rig record: a rounded time column, a header dt slightly off, and dt from the header") {
  using rths::io::TimeAxis;
  const double dt = 1.0 / 3004.8;
  // Rounded to 0.1 ms: steps of 0.3 and 0.4 ms. Refused by default, with the way out named.
  const std::string rounded = AtRate(4, dt);
  const std::string m = MessageOf(rounded, TimeAxis::kColumn);
  CAPTURE(m);
  CHECK(m.find("non-uniform time") != std::string::npos);
  CHECK(m.find("--time-from-header") != std::string::npos);
  CHECK(m.find("gap") == std::string::npos);
  // From the header: read, the step is the header's, the deviation reported.
  const RigRecord r = rths::io::ParseRigRecord(rounded, "r.csv", TimeAxis::kHeader);
  CHECK(r.dt_s == doctest::Approx(dt).epsilon(1e-11));
  CHECK(r.t_s[9000] == doctest::Approx(9000 * dt).epsilon(1e-12));
  REQUIRE(!r.warnings.empty());
  CHECK(r.warnings.back().find("time taken from the header") != std::string::npos);
  // A precise column with a header 0.16 % off: refused on the dt_s line (line 2), the gap stated.
  const std::string off = MessageOf(AtRate(9, dt * 1.0016), TimeAxis::kColumn);
  CAPTURE(off);
  CHECK(off.find("r.csv:2") == 0);
  CHECK(off.find("disagrees with the time column's mean step") != std::string::npos);
  CHECK(off.find("-0.16 %") != std::string::npos);
  // ... and the same column and a correct header pass.
  CHECK(MessageOf(AtRate(9, dt), TimeAxis::kColumn).empty());
  // From the header, a missing row is still found (more than half a step off from there on).
  const std::string missing = MessageOf(AtRate(4, dt, 4000), TimeAxis::kHeader);
  CAPTURE(missing);
  CHECK(missing.find("more than half a step") != std::string::npos);
  CHECK(missing.find("r.csv:4004:") == 0);  // row k = 4000 (holding the t of k = 4001) is on line 4 + k
}
