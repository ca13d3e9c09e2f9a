#include "sweep/run_sweep.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "ident/design_model.h"
#include "io/reserved_file.h"
#include "scenario/scenario.h"
#include "studies/batch.h"
#include "sweep/element_keys.h"
#include "sweep/table.h"

namespace rths::sweep {

namespace fs = std::filesystem;

namespace {

/// The value of a dotted field of summary.json ("benchmark_criteria.J1_ms"); null if absent.
nlohmann::json Field(const nlohmann::json& summary, const std::string& dotted) {
  const nlohmann::json* j = &summary;
  std::stringstream ss(dotted);
  for (std::string part; std::getline(ss, part, '.');) {
    if (!j->is_object() || !j->contains(part)) return nullptr;
    j = &(*j)[part];
  }
  return *j;
}

/// A --set value (a TOML literal) as JSON: a string without its quotes, a boolean, a number, or
/// an array of numbers as its text ("[2, 95]": the grid level's name in the table).
nlohmann::json ValueOf(const std::string& literal) {
  if (!literal.empty() && literal.front() == '[') return literal;
  if (literal.size() >= 2 && literal.front() == '"') {
    std::string out;
    for (std::size_t i = 1; i + 1 < literal.size(); ++i) {
      if (literal[i] == '\\' && i + 2 < literal.size()) ++i;
      out += literal[i];
    }
    return out;
  }
  if (literal == "true" || literal == "false") return literal == "true";
  if (literal.find_first_of(".eEn") == std::string::npos) return std::stoll(literal);
  return std::stod(literal);  // the shortest text of a double reads back as that double
}

/// Run i's row: its index, status, scenario hash, the values it was given and the recorded fields.
nlohmann::json Row(const Spec& spec, const RunPoint& p, const std::string& status, const nlohmann::json& summary) {
  nlohmann::json row = {{"index", p.index}, {"status", status}};
  row["scenario_sha256"] = summary.is_object() ? summary.value("scenario_sha256", std::string()) : "";
  for (const std::string& set : p.sets) {
    const std::size_t eq = set.find('=');
    row["set"][set.substr(0, eq)] = ValueOf(set.substr(eq + 1));
  }
  for (const std::string& f : spec.record) row["record"][f] = summary.is_object() ? Field(summary, f) : nullptr;
  return row;
}

}  // namespace

WrittenTable WriteTable(const Spec& spec, const fs::path& out) {
  const Table t = ReadTable(spec, out);
  WriteCsv(t, out / "table.csv");
  WriteHdf5(spec, t, out / "table.h5");
  WriteGroupSummary(spec, t, out / "summary.csv");
  try {
    WritePlots(spec, t, out / "plots");
  } catch (const std::exception& e) {  // the table is the result; a figure that fails is not
    fs::create_directories(out / "plots");
    io::OverwriteFile((out / "plots" / "FAILED.txt").string(), std::string(e.what()) + "\n");
  }
  WrittenTable w{out / "table.csv", static_cast<std::int64_t>(t.rows.size()), 0, AbsentFields(spec, t)};
  for (const auto& row : t.rows) w.not_completed += row[1] != "completed";
  return w;
}

namespace {

/// The indices this call makes: `only`, or the chunk's, less the rows already there with resume.
std::vector<std::int64_t> Todo(const Spec& spec, const SweepOptions& o, SweepOutcome* outcome) {
  std::vector<std::int64_t> todo;
  const std::int64_t first = o.only.value_or(0), last = o.only ? *o.only + 1 : spec.runs();
  if (o.chunks < 1 || o.chunk < 0 || o.chunk >= o.chunks) {
    throw Error("--chunk", fmt::format("{} of {}: needs 0 <= chunk < chunks", o.chunk, o.chunks));
  }
  if (o.only) PointOf(spec, *o.only);  // throws for an index out of range
  for (std::int64_t i = first; i < last; ++i) {
    if (i % o.chunks != o.chunk) continue;
    if (o.resume && fs::exists(RowFile(o.out, i))) {
      ++outcome->skipped;
      outcome->kept.push_back(i);
      continue;
    }
    todo.push_back(i);
  }
  return todo;
}

/// Makes runs `ids` (`total` in this call, for the progress line), each row written as its run ends.
void RunBlock(const Spec& spec, const SweepOptions& o, const std::vector<std::int64_t>& ids, std::size_t total,
              SweepOutcome* outcome) {
  std::vector<studies::RunSpec> specs;
  std::vector<RunPoint> points;
  for (const std::int64_t i : ids) {
    const RunPoint p = PointOf(spec, i);
    const fs::path dir = o.out / "runs" / std::to_string(p.index);
    fs::remove_all(dir);  // what an interrupted attempt left
    try {
      scenario::Scenario s = scenario::LoadScenario(p.scenario, ScenarioSets(p));
      // A model-based controller designs on the plant the run drives, as in `rths run`.
      const std::string note = ident::ResolveDesignModel(&s);
      auto& notes = outcome->design_notes;
      if (!note.empty() && std::find(notes.begin(), notes.end(), note) == notes.end()) notes.push_back(note);
      specs.push_back({fmt::format("run {} of sweep {}", p.index, spec.name), std::move(s), dir});
      points.push_back(p);
    } catch (const std::exception& e) {  // e.g. a drawn value out of the key's range: a row, not a crash
      io::OverwriteFile(RowFile(o.out, p.index).string(),
                        Row(spec, p, fmt::format("invalid: {}", e.what()), nullptr).dump(2) + "\n");
      ++outcome->ran;
      ++outcome->failed;
    }
  }
  std::size_t next = 0;  // RunBatch reports runs in the order they end: find each by its folder
  auto on_run = [&](std::size_t, std::size_t, const studies::RunResult& result) {
    std::size_t r = next;
    while (specs[r].dir != result.dir) r = (r + 1) % specs.size();
    next = (r + 1) % specs.size();
    const nlohmann::json summary = ReadJsonFile(result.dir / "summary.json");
    const std::string status =
        result.ok ? "completed" : fmt::format("failed: {}", result.error.empty() ? "no summary" : result.error);
    if (!o.keep_logs) {
      std::error_code ec;
      fs::remove(result.dir / "log.lcm", ec);
      fs::remove(result.dir / "signals.csv", ec);
    }
    io::OverwriteFile(RowFile(o.out, points[r].index).string(), Row(spec, points[r], status, summary).dump(2) + "\n");
    ++outcome->ran;
    if (!result.ok) ++outcome->failed;
    if (o.progress) {
      o.progress->Update(static_cast<double>(outcome->ran), static_cast<double>(total),
                         fmt::format("{} of {} runs", outcome->ran, total));
    }
  };
  studies::RunBatch(specs, std::max(1, o.jobs), nullptr, on_run, "rths sweep");
}

}  // namespace

SweepOutcome RunSweep(const Spec& spec, const SweepOptions& o) {
  fs::create_directories(o.out / "rows");
  fs::create_directories(o.out / "runs");
  SweepOutcome outcome;
  const std::vector<std::int64_t> todo = Todo(spec, o, &outcome);
  // Blocks of runs, so that a sweep of 16 000 runs does not hold 16 000 scenarios at once.
  const std::size_t block = std::max<std::size_t>(64, 16 * static_cast<std::size_t>(std::max(1, o.jobs)));
  for (std::size_t from = 0; from < todo.size(); from += block) {
    const std::vector<std::int64_t> ids(todo.begin() + static_cast<std::ptrdiff_t>(from),
                                        todo.begin() + static_cast<std::ptrdiff_t>(std::min(todo.size(), from + block)));
    RunBlock(spec, o, ids, todo.size(), &outcome);
  }
  if (o.write_table) {
    WrittenTable w = WriteTable(spec, o.out);
    outcome.table = w.csv;
    outcome.rows = w.rows;
    outcome.not_completed = w.not_completed;
    outcome.absent_fields = std::move(w.absent_fields);
  }
  return outcome;
}

}  // namespace rths::sweep
