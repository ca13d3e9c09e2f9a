#pragma once
/// @file The command-line convention every `rths <sub>` tool follows (README "Commands"):
///   - usage lines and errors name the command as the user typed it ("rths run"), not the binary;
///   - `--help` exits 0; a usage error (unknown option, missing argument, value out of range)
///     prints CLI11's message and the usage hint on stderr and exits 2, like every other bad input;
///   - messages on stderr start with "rths <sub>: ".
/// Header-only; the tools include it, the libraries never do.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lockstep/exit_code.h"

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
/// lockstep::kExitUsage after a usage error (message already printed).
inline int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : lockstep::kExitUsage;
  }
  return -1;
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

}  // namespace rths::tools
