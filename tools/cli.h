#pragma once
/// @file The command-line convention every `rths <sub>` tool follows (README "Commands"):
///   - usage lines and errors name the command as the user typed it ("rths run"), not the binary;
///   - `--help` exits 0; a usage error (unknown option, missing argument, value out of range)
///     prints CLI11's message and the usage hint on stderr and exits 2, like every other bad input;
///   - messages on stderr start with "rths <sub>: ".
/// Header-only; the tools include it, the libraries never do.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/exit_code.h"

#include "core/progress.h"

namespace rths::tools {


/// Names `app` "rths <sub>" for its usage line and help, and prefixes its usage errors with
/// "rths <sub>: " like every other message of the command. Call before adding subcommands (they
/// inherit the prefix).
inline void NameCommand(CLI::App& app, const std::string& sub) {
  app.name("rths " + sub);
  app.failure_message([](const CLI::App* a, const CLI::Error& e) {
    return a->get_name() + ": " + e.what() + "\nRun with --help for more information.\n";
  });
}

/// Parses the command line. Returns -1 to go on, or the code to exit with: 0 after --help,
/// rths::kExitUsage after a usage error (message already printed). A non-empty RTHS_NO_PROGRESS in the
/// environment turns the progress lines off (core/progress.h).
inline int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  if (const char* off = std::getenv("RTHS_NO_PROGRESS"); off != nullptr && *off != '\0') ProgressLine::TurnOff();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : rths::kExitUsage;
  }
  return -1;
}

/// `name` as found on the user's PATH (the first executable regular file), or `name` itself if it
/// holds a '/' or is not found (the library then looks in the system's folders, io/plot.h).
inline std::string ProgramOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (name.find('/') != std::string::npos || path == nullptr) return name;
  std::string dirs = path;
  for (std::size_t start = 0; start <= dirs.size();) {
    std::size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
    const std::string candidate = dir + "/" + name;
    std::error_code ec;
    if (::access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate, ec)) return candidate;
    start = end + 1;
  }
  return name;
}

/// Adds the repeatable `--set KEY=VALUE` option (scenario overrides, scenario::ApplyOverrides).
inline CLI::Option* AddSetOption(CLI::App& app, std::vector<std::string>* sets) {
  return app
      .add_option("--set", *sets,
                  "KEY=VALUE: override a scenario key (dotted, e.g. run.duration_s=5, controller.kind=ff_lqg, "
                  "plant.damper.c0_a=21); repeatable; checked like the file (docs/scenarios.md)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
}

/// Adds `--columns MAP`: how to read a CSV with named columns or a .mat file as a rig record
/// (io::ParseColumnMap, docs/rig_record.md "Other formats"); the text is parsed by the tool.
inline CLI::Option* AddColumnsOption(CLI::App& app, std::string* columns) {
  return app
      .add_option("--columns", *columns,
                  "read the records (a CSV with named columns or a .mat file) through this map: "
                  "ROLE=SOURCE[*SCALE][:UNIT],... with roles t u y f i v r (or dt=STEP_S), e.g. t=t,y=D:cm,f=F:N,v=Y:V "
                  "(docs/rig_record.md \"Other formats\")")
      ->type_name("MAP");
}

}  // namespace rths::tools
