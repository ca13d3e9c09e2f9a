#include "studies/marths_lockstep.h"

#include <chrono>
#include <cmath>
#include <filesystem>

#include <unistd.h>

#include <fmt/format.h>

#include "core/error.h"
#include "ident/design_model.h"
#include "io/run_log.h"
#include "io/source_tree.h"
#include "participants/group.h"
#include "participants/marths_run.h"
#include "scenario/scenario.h"

namespace rths::studies {

std::vector<MarthsLockstepRow> RunMarthsScenarios(const ReproduceOptions& opts, const std::vector<MarthsRow>& rows,
                                                  std::size_t samples, double dt_s) {
  namespace fs = std::filesystem;
  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_marths_lockstep_{}", ::getpid());
  std::vector<MarthsLockstepRow> out;
  for (const char* name : {"none", "rodeac", "ff", "ff_lqg"}) {
    MarthsLockstepRow row;
    row.compensator = name;
    const std::string file = io::FindSourceFile(fmt::format("scenarios/marths/elcentro_{}.toml", name),
                                                opts.source_dir).string();
    const std::string duration = fmt::format("run.duration_s={}", static_cast<double>(samples) * dt_s);
    scenario::Scenario s = scenario::LoadScenario(file, {duration});
    if (s.steps() != static_cast<std::int64_t>(samples)) {
      throw Error(file, fmt::format("{} steps where the study's record has {}", s.steps(), samples));
    }
    ident::ResolveDesignModel(&s);
    const fs::path dir = tmp / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto t0 = std::chrono::steady_clock::now();
    const auto outcomes = participants::RunGroupInProcess({s}, 47, dir.string());
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (const participants::Outcome* failed = participants::RootCause(outcomes)) {
      throw Error(file, fmt::format("the lockstep run failed: {}: {}", failed->role, failed->message));
    }
    const participants::MarthsRunScore score =
        participants::MarthsScoreOfRun(io::ReadRunLog((dir / "log.lcm").string()), s);
    fs::remove_all(dir);
    row.steps = score.steps;
    row.lockstep = score.j;
    row.max_volts[0] = score.max_volts[0];
    row.max_volts[1] = score.max_volts[1];
    row.realizable = score.realizable;
    for (const MarthsRow& r : rows) {
      if (r.compensator == name && r.run == "nominal") row.loop = r.j;
    }
    const auto a = row.lockstep.Items(), b = row.loop.Items();
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double rel = std::abs(a[i].second - b[i].second) / std::max(std::abs(b[i].second), 1e-300);
      row.max_rel_diff = std::max(row.max_rel_diff, rel);
    }
    out.push_back(row);
  }
  fs::remove_all(tmp);
  return out;
}

}  // namespace rths::studies
