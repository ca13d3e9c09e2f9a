// Rig records in the formats labs have (io/column_record.h): a CSV with named columns and a
// MATLAB .mat file through a column map, checked against the shipped UTFSM data read directly.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <matio.h>
#include <sys/wait.h>

#include "core/error.h"
#include "io/column_record.h"
#include "io/utfsm.h"
#include "test_support.h"

namespace {

const std::string kDamper = RTHS_SOURCE_DIR "/data/utfsm/mr_damper/25mm0x5Hz1A.txt";

/// The message of the rths::Error `f` throws ("" if none).
template <class F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}

/// A shipped damper test written as a lab's DAQ export might be: quoted names, cm and N, the
/// current in mA, a column with empty fields, a trailing comma on every line, the time column
/// rounded to 0.1 ms (exact here: 5 ms steps).
void WriteLabCsv(const rths::io::RigRecord& r, const std::string& path) {
  std::ofstream f(path);
  f << "\"time\",\"accel\",\"disp\",\"I\",\"fs\",\"force\",\n";
  for (std::size_t k = 0; k < r.size(); ++k)
    f << fmt::format("{:.4f},0.0,{:.9g},{:.9g},{},{:.9g},\n", r.t_s[k], r.y_mm[k] / 10.0, r.i_A[k] * 1000.0,
                     k == 0 ? "200" : "", r.f_kN[k] * 1000.0);
}

/// A matio variable: a real double column vector or matrix (rows x cols, column-major).
matvar_t* Doubles(const char* name, const std::vector<double>& v, std::size_t rows, std::size_t cols) {
  std::size_t dims[2] = {rows, cols};
  return Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(v.data()), 0);
}

void CheckSameRecord(const rths::io::RigRecord& a, const rths::io::RigRecord& b, double rel) {
  REQUIRE(a.size() == b.size());
  CHECK(a.dt_s == doctest::Approx(b.dt_s).epsilon(1e-9));
  for (std::size_t k = 0; k < a.size(); k += 37) {
    CHECK(a.y_mm[k] == doctest::Approx(b.y_mm[k]).epsilon(rel).scale(1.0));
    CHECK(a.f_kN[k] == doctest::Approx(b.f_kN[k]).epsilon(rel).scale(1.0));
    CHECK(a.u_mm[k] == a.y_mm[k]);
    CHECK(a.i_A[k] == doctest::Approx(b.i_A[k]).epsilon(rel));
  }
}

}  // namespace

TEST_CASE("column map: parsed with units and scales; every mistake names the entry and what is allowed") {
  const auto m = rths::io::ParseColumnMap("t=time:ms, y=CH0*10:mm,f=\"Force\":N,v=Y:mV");
  REQUIRE(m.columns.size() == 4);
  CHECK(m.Find('t')->to_record == doctest::Approx(1e-3));
  CHECK(m.Find('y')->to_record == doctest::Approx(10.0));
  CHECK(m.Find('f')->source == "Force");
  CHECK(m.Find('f')->to_record == doctest::Approx(1e-3));
  CHECK(m.Find('v')->to_record == doctest::Approx(1e-3));
  CHECK(m.Find('u') == nullptr);
  CHECK(rths::io::ParseColumnMap("dt=0.001,y=x,f=F:kip").Find('f')->to_record == doctest::Approx(4.4482216152605));
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y=D:furlong,f=F"); }).find("mm, cm, m, in") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,q=D,f=F"); }).find("unknown role \"q\"") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y=D,y=E,f=F"); }).find("twice") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,f=F"); }).find("no y") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("y=D,f=F"); }).find("exactly one of t") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,dt=0.001,y=D,f=F"); }).find("exactly one of t") !=
        std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y=D*0,f=F"); }).find("non-zero") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y,f=F"); }).find("ROLE=SOURCE") != std::string::npos);
}

TEST_CASE("a CSV with named columns: the shipped damper test in a lab's export reads back as the UTFSM reader reads it") {
  const auto utfsm = rths::io::ReadUtfsmDamper(kDamper);
  const auto dir = rths_test::TempDir("formats_csv");
  const auto csv = (dir / "lab.csv").string();
  WriteLabCsv(utfsm, csv);
  const auto map = rths::io::ParseColumnMap("t=time,y=disp:cm,f=force:N,i=I:mA");
  const auto rec = rths::io::ReadAnyRecord(csv, &map);
  CheckSameRecord(rec, utfsm, 1e-8);
  CHECK(rec.Meta("columns") == "t=time,y=disp:cm,f=force:N,i=I:mA");
  REQUIRE(!rec.warnings.empty());
  CHECK(rec.warnings[0].find("no command column") != std::string::npos);
  // Without a map the file is refused with the option to use and its columns.
  const auto e = ErrorOf([&] { rths::io::ReadAnyRecord(csv, nullptr); });
  CHECK(e.find("--columns") != std::string::npos);
  CHECK(e.find("time, accel, disp, I, fs, force") != std::string::npos);
  // A mapped column that is missing names the file's columns; a bad field names its line.
  const auto bad_map = rths::io::ParseColumnMap("t=time,y=Disp:cm,f=force:N");
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(csv, &bad_map); }).find("no column \"Disp\"") != std::string::npos);
  {
    std::ofstream f(csv, std::ios::app);
    f << "99.0,0,abc,0,,1,\n";
  }
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(csv, &map); }).find(fmt::format("lab.csv:{}", utfsm.size() + 2)) !=
        std::string::npos);
}

TEST_CASE("a time column rounded coarser than its step is taken on its mean grid, with a warning") {
  // 3004.8 Hz written to 0.1 ms (the public prototype damper's record): steps of 0.3 and 0.4 ms.
  const auto dir = rths_test::TempDir("formats_rounded");
  const auto csv = (dir / "rounded.csv").string();
  const double dt = 1.0 / 3004.8;
  const std::size_t n = 9000;
  {
    std::ofstream f(csv);
    f << "t;D;F;Y\n";
    for (std::size_t k = 0; k < n; ++k)
      f << fmt::format("{:.4f};{:.6f};{:.6f};{:.3f}\n", k * dt, std::sin(k * dt * 6.0), std::cos(k * dt * 6.0),
                       k % 3000 < 1500 ? 2.25 : 0.0);
  }
  const auto map = rths::io::ParseColumnMap("t=t,y=D:cm,f=F:N,v=Y");
  const auto rec = rths::io::ReadAnyRecord(csv, &map);
  CHECK(rec.dt_s == doctest::Approx(dt).epsilon(1e-4));
  CHECK(rec.has_v());
  CHECK(rec.i_A.empty());
  bool warned = false;
  for (const auto& w : rec.warnings) warned = warned || w.find("rounded?") != std::string::npos;
  CHECK(warned);
  // A missing row is still a gap.
  std::ofstream(csv, std::ios::app) << fmt::format("{:.4f};0;0;0\n", (n + 3) * dt);
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(csv, &map); }).find("gap") != std::string::npos);
}

TEST_CASE("a .mat file: vectors, a struct's fields, a matrix's columns; the rig record's own names need no map") {
  const auto utfsm = rths::io::ReadUtfsmDamper(kDamper);
  const std::size_t n = utfsm.size();
  const auto dir = rths_test::TempDir("formats_mat");
  std::vector<double> t = utfsm.t_s, disp_cm(n), force_N(n), current(n, 1.0), matrix(3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    disp_cm[k] = utfsm.y_mm[k] / 10.0;
    force_N[k] = utfsm.f_kN[k] * 1000.0;
    matrix[k] = t[k];
    matrix[n + k] = disp_cm[k];
    matrix[2 * n + k] = force_N[k];
  }
  const auto path = (dir / "lab.mat").string();
  {
    mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
    REQUIRE(mat != nullptr);
    for (matvar_t* v : {Doubles("time", t, n, 1), Doubles("disp", disp_cm, 1, n), Doubles("I", current, n, 1),
                        Doubles("data", matrix, n, 3)}) {
      Mat_VarWrite(mat, v, MAT_COMPRESSION_NONE);
      Mat_VarFree(v);
    }
    const char* fields[2] = {"force", "disp"};
    std::size_t one[2] = {1, 1};
    matvar_t* s = Mat_VarCreateStruct("test", 2, one, fields, 2);
    Mat_VarSetStructFieldByName(s, "force", 0, Doubles(nullptr, force_N, n, 1));
    Mat_VarSetStructFieldByName(s, "disp", 0, Doubles(nullptr, disp_cm, n, 1));
    Mat_VarWrite(mat, s, MAT_COMPRESSION_NONE);
    Mat_VarFree(s);
    Mat_Close(mat);
  }
  CHECK(rths::io::IsMatFile(path));
  const auto a = rths::io::ParseColumnMap("t=time,y=disp:cm,f=test.force:N,i=I");
  CheckSameRecord(rths::io::ReadAnyRecord(path, &a), utfsm, 1e-12);
  const auto b = rths::io::ParseColumnMap("t=data(:,1),y=data(:,2):cm,f=data(:,3)*1e-3,i=I");
  CheckSameRecord(rths::io::ReadAnyRecord(path, &b), utfsm, 1e-12);
  // Mistakes name the variable and list what the file has.
  const auto c = rths::io::ParseColumnMap("t=time,y=data,f=test.forc:N");
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(path, &c); }).find("name one column, data(:,K)") != std::string::npos);
  const auto d = rths::io::ParseColumnMap("t=time,y=dsp,f=test.force:N");
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(path, &d); }).find("time, disp, I, data, test") != std::string::npos);
  CHECK(ErrorOf([&] { rths::io::ReadAnyRecord(path, nullptr); }).find("--columns") != std::string::npos);
  // The rig record's own names (t_s or dt_s, u_mm, y_mm, f_kN, i_A) need no map.
  const auto own = (dir / "own.mat").string();
  {
    mat_t* mat = Mat_CreateVer(own.c_str(), nullptr, MAT_FT_MAT5);
    REQUIRE(mat != nullptr);
    const std::vector<double> dt{utfsm.dt_s};
    for (matvar_t* v : {Doubles("dt_s", dt, 1, 1), Doubles("y_mm", utfsm.y_mm, n, 1), Doubles("u_mm", utfsm.u_mm, n, 1),
                        Doubles("f_kN", utfsm.f_kN, n, 1), Doubles("i_A", utfsm.i_A, n, 1)}) {
      Mat_VarWrite(mat, v, MAT_COMPRESSION_NONE);
      Mat_VarFree(v);
    }
    Mat_Close(mat);
  }
  CheckSameRecord(rths::io::ReadAnyRecord(own, nullptr), utfsm, 1e-12);
}

TEST_CASE("a map serves a mix of a lab's files and ours: a CSV rig record is read as it is") {
  const auto utfsm = rths::io::ReadUtfsmDamper(kDamper);
  const auto dir = rths_test::TempDir("formats_mix");
  const auto ours = (dir / "ours.csv").string();
  rths::io::WriteRigRecord(utfsm, ours);
  const auto map = rths::io::ParseColumnMap("t=time,y=disp:cm,f=force:N,i=I:mA");
  const auto rec = rths::io::ReadAnyRecord(ours, &map);
  CHECK(rec.Meta("columns").empty());
  CheckSameRecord(rec, utfsm, 1e-8);
}

TEST_CASE("ReadAnyRecord without a map reads the shipped UTFSM files as before") {
  const auto damper = rths::io::ReadAnyRecord(kDamper, nullptr);
  CHECK(damper.size() == rths::io::ReadUtfsmDamper(kDamper).size());
  const auto chirp = rths::io::ReadAnyRecord(RTHS_SOURCE_DIR "/data/utfsm/actuator/chirp_0A.txt", nullptr);
  CHECK(chirp.dt_s == doctest::Approx(0.001));
}

TEST_CASE("rths identify and rths diagnose take --columns") {
  const auto utfsm = rths::io::ReadUtfsmDamper(kDamper);
  const auto dir = rths_test::TempDir("formats_cli");
  const auto csv = (dir / "lab.csv").string(), log = (dir / "out.txt").string();
  WriteLabCsv(utfsm, csv);
  const int fit = std::system(fmt::format("{}/rths-identify --damper {} --current 1 --columns "
                                          "t=time,y=disp:cm,f=force:N,i=I:mA > {} 2>&1",
                                          RTHS_BIN_DIR, csv, log)
                                  .c_str());
  CHECK(WEXITSTATUS(fit) == 0);
  CHECK(rths_test::Slurp(log).find("Spencer MR damper model at 1 A") != std::string::npos);
  const int refused = std::system(fmt::format("{}/rths-diagnose --train {} --test {} > {} 2>&1", RTHS_BIN_DIR, csv,
                                              csv, log)
                                      .c_str());
  CHECK(WEXITSTATUS(refused) == 2);
  CHECK(rths_test::Slurp(log).find("--columns ROLE=COLUMN") != std::string::npos);
  const int bad = std::system(fmt::format("{}/rths-diagnose --train {} --test {} --columns t=time,y=disp:parsec,f=force "
                                          "> {} 2>&1",
                                          RTHS_BIN_DIR, csv, csv, log)
                                  .c_str());
  CHECK(WEXITSTATUS(bad) == 2);
  CHECK(rths_test::Slurp(log).find("unit \"parsec\"") != std::string::npos);
}

TEST_CASE("a file without a current column: i=VALUE in the map, or --current, gives its constant current") {
  const auto utfsm = rths::io::ReadUtfsmDamper(kDamper);  // a test at 1 A
  const auto dir = rths_test::TempDir("formats_const_current");
  const auto csv = (dir / "lab.csv").string(), log = (dir / "out.txt").string();
  WriteLabCsv(utfsm, csv);
  const auto map = rths::io::ParseColumnMap("t=time,y=disp:cm,f=force:N,i=1000:mA");
  REQUIRE(map.current_A.has_value());
  CHECK(*map.current_A == doctest::Approx(1.0));
  const auto rec = rths::io::ReadAnyRecord(csv, &map);
  CHECK(rec.i_A.size() == rec.size());
  CHECK(std::all_of(rec.i_A.begin(), rec.i_A.end(), [](double i) { return i == 1.0; }));
  for (const auto& w : rec.warnings) CHECK(w.find("no damper command") == std::string::npos);
  CHECK(rec.Meta("columns").find("i=1") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y=D,f=F,i=I,i=2"); }).find("twice") != std::string::npos);
  CHECK(ErrorOf([] { rths::io::ParseColumnMap("t=t,y=D,f=F,i=-1"); }).find("[0, 100] A") != std::string::npos);
  // rths identify --damper --current 1 on a map without i: the file's current is 1 A (it refused it at 0 A).
  const int fit = std::system(fmt::format("{}/rths-identify --damper {} --current 1 --columns t=time,y=disp:cm,f=force:N "
                                          "> {} 2>&1",
                                          RTHS_BIN_DIR, csv, log)
                                  .c_str());
  CHECK(WEXITSTATUS(fit) == 0);
  CHECK(rths_test::Slurp(log).find("Spencer MR damper model at 1 A") != std::string::npos);
  // rths diagnose --current: only with --columns and a map without the command.
  const int no_map = std::system(fmt::format("{}/rths-diagnose --train {} --test {} --current 1 > {} 2>&1",
                                             RTHS_BIN_DIR, kDamper, kDamper, log)
                                     .c_str());
  CHECK(WEXITSTATUS(no_map) == 2);
  CHECK(rths_test::Slurp(log).find("only with --columns") != std::string::npos);
}
