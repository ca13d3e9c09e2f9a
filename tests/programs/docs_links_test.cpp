// Every document the repository cites is in it (a user's clone has nothing else): each Markdown
// file named in the README, the docs, the code, the tests, the benches, the examples and the scripts
// resolves to a file of the repository (as written, under docs/, or beside the citing file), except
// the Markdown files the studies write into their output folders.
#include <doctest/doctest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "test_support.h"

namespace fs = std::filesystem;

TEST_CASE("every cited .md file is in the repository") {
  const fs::path root = RTHS_SOURCE_DIR;
  // What `rths reproduce` and the studies write into their output folders: outputs, not documents.
  const std::set<std::string> outputs = {"fig5.md", "fig6.md", "fig7.md", "fig8.md", "fig9.md", "fig11.md",
                                         "table2.md", "table2_extended.md", "benchmark.md", "critical_delay.md",
                                         "marths_decisions.md", "marths_records.md", "marths_lockstep.md"};
  std::vector<fs::path> files = {root / "README.md", root / "rths"};
  for (const char* dir : {"docs", "lib", "tools", "tests", "bench", "examples", "scripts"}) {
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      const auto ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".md" || ext == ".h" || ext == ".cpp" || ext == ".sh" || ext == ".m" ||
                                  ext == ".py" || ext == ".java" || ext == ".toml")) {
        files.push_back(e.path());
      }
    }
  }
  const std::regex cite(R"((?:^|[^A-Za-z0-9_/.-])((?:\.\./)?(?:[A-Za-z0-9_.-]+/)*[A-Za-z0-9_-]+\.md)\b)");
  int checked = 0;
  for (const auto& f : files) {
    const std::string text = rths_test::Slurp(f);
    for (std::sregex_iterator m(text.begin(), text.end(), cite), end; m != end; ++m) {
      const std::string ref = (*m)[1];
      if (outputs.count(ref) != 0) continue;
      ++checked;
      const bool found = fs::exists(root / ref) || fs::exists(root / "docs" / ref) || fs::exists(f.parent_path() / ref);
      CHECK_MESSAGE(found, fs::relative(f, root).string() << " cites " << ref << ", which is not in the repository");
    }
  }
  CHECK(checked > 100);
}
