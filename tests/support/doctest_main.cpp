// The main of every doctest binary: doctest's, then the test folders of this process
// (/tmp/rths_test_<pid>, test_support.h's TempDir) removed when every test passed, so that a suite
// does not leave its runs' logs behind (about 1.2 GB a full ctest run). A failing binary keeps
// them for a look; RTHS_KEEP_TEST_DIRS=1 keeps them always.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
  doctest::Context context(argc, argv);
  const int rc = context.run();
  if (context.shouldExit()) return rc;  // --help, --list-test-cases, ...
  if (rc == 0 && std::getenv("RTHS_KEEP_TEST_DIRS") == nullptr) {
    std::error_code ec;
    std::filesystem::remove_all(std::filesystem::temp_directory_path(ec) / ("rths_test_" + std::to_string(::getpid())),
                                ec);
  }
  return rc;
}
