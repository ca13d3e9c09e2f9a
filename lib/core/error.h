#pragma once
/// @file One error type for the whole project (docs/units.md; README "What happens when things go wrong").
/// It carries where the problem is (file, key or line) and what was expected, so that a
/// tool can print it and exit with a documented code. Library code throws; only main() exits.
#include <stdexcept>
#include <string>

namespace rths {

class Error : public std::runtime_error {
 public:
  /// @param where  "file.toml: key" or "file.csv:123" or a component name.
  /// @param what   the problem and, where there is one, the allowed range.
  Error(std::string where, std::string what)
      : std::runtime_error(where.empty() ? what : where + ": " + what),
        where_(std::move(where)), problem_(std::move(what)) {}
  const std::string& where() const { return where_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string where_;
  std::string problem_;
};

/// The work was interrupted (Ctrl-C or a termination signal, at any stage: a run, a child such as
/// gnuplot killed by the same signal): not bad input. Tools exit 130 on it and say how to resume.
class Interrupted : public Error {
 public:
  using Error::Error;
};

}  // namespace rths
