// The bundle for hosts that are not Debian 12 (issue 45; scripts/bundle.sh, docs/cluster.md): made
// from this build tree, it holds every rths-* program, its libraries down to glibc and its loader,
// and every library any ELF of it needs is inside it. In a chroot that holds only the bundle and
// busybox-static (tests/bundle/chroot.sh; root), `rths run --transport memq`, `rths sweep` and the
// two array tasks of the Slurm job script (`rths-sweep --task`) succeed, with the bundle's own path in
// the job script and the table of the tasks equal, byte for byte, to the local sweep's and to the
// table of the checkout's own rths-sweep outside the chroot.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/command.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

const fs::path kBuild = fs::path(RTHS_BIN_DIR).parent_path();

/// The lines of a text file.
std::vector<std::string> Lines(const fs::path& file) {
  std::vector<std::string> lines;
  std::istringstream in(rths_test::Slurp(file));
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// scripts/bundle.sh run once for the whole binary (it takes seconds): the tarball's path.
const fs::path& Bundle() {
  static const fs::path tarball = [] {
    const fs::path out = rths_test::TempDir("bundle");
    const auto r = rths::io::RunCommand({"/bin/bash", std::string(RTHS_SOURCE_DIR) + "/scripts/bundle.sh", "--build",
                                         kBuild.string(), "--out", out.string(), "--no-build"});
    INFO(r.output);
    REQUIRE(r.status == 0);
    fs::path made;
    for (const auto& f : fs::directory_iterator(out)) {
      if (f.path().string().ends_with(".tar.gz")) made = f.path();
    }
    REQUIRE_MESSAGE(!made.empty(), "no .tar.gz in " << out.string());
    CHECK(r.output.ends_with(made.string() + "\n"));  // its path is the output's last line
    return made;
  }();
  return tarball;
}

/// The bundle untarred into a fresh folder: the folder rths-<version>-linux-x86_64.
fs::path Untarred(const std::string& name) {
  const fs::path dir = rths_test::TempDir(name);
  const auto r = rths::io::RunCommand({"/bin/tar", "xzf", Bundle().string(), "-C", dir.string()});
  REQUIRE_MESSAGE(r.status == 0, r.output);
  return dir / Bundle().stem().stem();
}

/// The NEEDED entries of an ELF file (readelf -d).
std::vector<std::string> Needed(const fs::path& elf) {
  const auto r = rths::io::RunCommand({"/usr/bin/readelf", "-d", elf.string()});
  REQUIRE_MESSAGE(r.status == 0, elf.string() << ": " << r.output);
  std::vector<std::string> needed;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    const auto open = line.find("(NEEDED)");
    if (open == std::string::npos) continue;
    const auto a = line.find('[', open), b = line.find(']', open);
    needed.push_back(line.substr(a + 1, b - a - 1));
  }
  return needed;
}

}  // namespace

TEST_CASE("the bundle holds every rths-* program, started through its own loader, and every library they need") {
  const auto programs = Lines(kBuild / "rths_programs.txt");
  REQUIRE(programs.size() >= 10);
  for (const auto& p : programs) rths_test::RequireBuilt(fs::path(p).filename().string());
  const fs::path b = Untarred("bundle_content");
  CHECK(Bundle().filename().string().rfind("rths-", 0) == 0);
  CHECK(Bundle().filename().string().find("-linux-x86_64.tar.gz") != std::string::npos);
  CHECK(fs::exists(b / "rths"));
  CHECK(fs::exists(b / "scenarios/default.toml"));
  CHECK(fs::exists(b / "build/bin/ld-linux-x86-64.so.2"));
  CHECK(fs::exists(b / "build/lib/libc.so.6"));
  for (const auto& p : programs) {
    const std::string name = fs::path(p).filename().string();
    CAPTURE(name);
    CHECK(rths_test::Slurp(b / "build/bin" / name).rfind("#!/bin/sh\n", 0) == 0);
    CHECK(rths_test::Slurp(b / "build/libexec" / name).rfind("\x7f" "ELF", 0) == 0);
  }
  // No ELF of the bundle needs a library from outside it.
  std::set<std::string> checked;
  for (const char* sub : {"build/libexec", "build/lib"}) {
    for (const auto& f : fs::directory_iterator(b / sub)) {
      for (const auto& lib : Needed(f.path())) {
        CAPTURE(f.path().string());
        CHECK_MESSAGE((fs::exists(b / "build/lib" / lib) || lib == "ld-linux-x86-64.so.2"), lib);
        checked.insert(lib);
      }
    }
  }
  CHECK(checked.count("libc.so.6") == 1);
  CHECK(checked.count("liblcm.so.1") == 1);
  // The host needs only a kernel: BUNDLE.txt says which.
  CHECK(rths_test::Slurp(b / "BUNDLE.txt").find("kernel >= 3.2") != std::string::npos);
}

TEST_CASE("the bundle runs in a chroot of busybox alone: rths run, rths sweep, the Slurm tasks" *
          doctest::skip(!rths_test::IsRoot())) {
  REQUIRE_MESSAGE(fs::exists("/bin/busybox"), "/bin/busybox is not installed: apt-get install busybox-static "
                                              "(scripts/bootstrap.sh installs it)");
  const fs::path root = rths_test::TempDir("bundle_chroot");
  const auto r = rths::io::RunCommand(
      {"/bin/bash", std::string(RTHS_SOURCE_DIR) + "/tests/bundle/chroot.sh", Bundle().string(), root.string()});
  INFO(r.output);
  REQUIRE(r.status == 0);
  const fs::path work = root / "work";

  // Outside the bundle's loader, its programs cannot start: nothing of this host is in the chroot.
  CHECK(rths_test::Slurp(work / "isolated.out").find("not found") != std::string::npos);

  // rths run --transport memq: 0.5 s at dt 0.5 ms.
  const auto summary = nlohmann::json::parse(rths_test::Slurp(work / "run/summary.json"));
  CHECK(summary["status"] == "completed");
  CHECK(summary["steps"] == 1000);

  // rths sweep: 4 completed rows; no gnuplot there, and it says so.
  const auto table = Lines(work / "sweep/table.csv");
  REQUIRE(table.size() == 5);
  for (std::size_t i = 1; i < table.size(); ++i) CHECK(table[i].find(",completed,") != std::string::npos);
  CHECK(rths_test::Slurp(work / "sweep.out").find("gnuplot") != std::string::npos);

  // The job script runs the bundle's rths-sweep (not its loader); its two tasks made the same table.
  const std::string bundle = "/opt/rths bundle/" + Bundle().stem().stem().string();
  CHECK(rths_test::Slurp(work / "tasks/slurm/task.sh").find("exec '" + bundle + "/build/bin/rths-sweep' ") !=
        std::string::npos);
  for (const char* task : {"task0.out", "task1.out"}) CHECK(rths_test::Slurp(work / task).find("ran 2") != std::string::npos);
  CHECK(rths_test::Slurp(work / "resume.out").find("ran 0") != std::string::npos);
  CHECK(rths_test::Slurp(work / "tasks/table.csv") == rths_test::Slurp(work / "sweep/table.csv"));

  // The checkout's own rths-sweep, on this Debian, makes the same table as the bundle in the chroot.
  const auto native = rths::io::RunCommand({std::string(RTHS_BIN_DIR) + "/rths-sweep", (work / "spec.toml").string(),
                                            "--out", (root / "native").string(), "--jobs", "2"});
  INFO(native.output);
  REQUIRE(native.status == 0);
  CHECK(rths_test::Slurp(root / "native/table.csv") == rths_test::Slurp(work / "sweep/table.csv"));
}
