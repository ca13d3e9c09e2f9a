#include "studies/batch.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "participants/factory.h"
#include "supervisor/run_summary.h"
#include "supervisor/run.h"
#include "supervisor/scenario_file.h"
#include "supervisor/summary_builder.h"

namespace rths::studies {

namespace fs = std::filesystem;

std::string Slug(const std::string& label) {
  std::string out;
  bool dash = false;
  for (char c : label) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_';
    if (c >= 'A' && c <= 'Z') {
      c = static_cast<char>(c - 'A' + 'a');
    } else if (!keep) {
      dash = !out.empty();
      continue;
    }
    if (dash) out += '-';
    dash = false;
    out += c;
  }
  return out.empty() ? "run" : out;
}

namespace {

/// The first line of a study's scenario.toml.
std::string ScenarioHeader(const RunSpec& spec, const std::string& origin = "rths reproduce") {
  return spec.label + " (written by " + origin + "; every key is written out)";
}

}  // namespace

scenario::Scenario WriteScenarioFile(const RunSpec& spec) {
  fs::create_directories(spec.dir);
  return supervisor::WriteScenarioFile(spec.dir / "scenario.toml", ScenarioHeader(spec), spec.scenario);
}

void Preflight(const std::vector<RunSpec>& specs) {
  std::vector<std::string> problems;
  for (const auto& spec : specs) {
    try {
      scenario::ValidateScenario(spec.scenario);
      participants::CheckBuildable(spec.scenario);
    } catch (const std::exception& e) {
      problems.push_back(fmt::format("  {}: {}", spec.label, e.what()));
    }
  }
  if (problems.empty()) return;
  std::string msg = fmt::format("{} of {} runs cannot be built with this build of rths:", problems.size(), specs.size());
  for (const auto& p : problems) msg += "\n" + p;
  throw Error("reproduce", msg);
}

void Preflight(std::vector<RunSpec>* specs, const std::vector<std::string>& overrides,
               const std::function<void(std::string_view)>& log) {
  if (!overrides.empty()) {
    for (auto& spec : *specs) {
      try {
        spec.scenario = scenario::WithOverrides(spec.scenario, overrides);
      } catch (const Error& e) {  // a scenario built in code has no file: name the run instead
        std::string where = e.where();
        if (const std::string text = "<scenario text>"; where.rfind(text, 0) == 0) where.erase(0, text.size());
        if (where.rfind(": ", 0) == 0) where.erase(0, 2);
        throw Error(spec.label, where.empty() ? e.problem() : where + ": " + e.problem());
      }
    }
  }
  Preflight(*specs);
  if (!log) return;
  participants::OutputBytes sum;
  for (const auto& spec : *specs) {
    const auto b = participants::EstimateOutputBytes(spec.scenario);
    sum.log += b.log;
    sum.csv += b.csv;
  }
  // log.lcm's size is exact, the CSV's a bound (a row's length depends on its numbers).
  if (sum.csv > 0) {
    log(fmt::format("{} runs will write at most {:.0f} MB: log.lcm {:.0f} MB, signals.csv up to {:.0f} MB (--compact: "
                    "none)",
                    specs->size(), sum.total() / 1e6, sum.log / 1e6, sum.csv / 1e6));
  } else {
    log(fmt::format("{} runs will write {:.0f} MB: log.lcm, no signals.csv", specs->size(), sum.log / 1e6));
  }
}

namespace {

/// A number of summary.json: NaN for null (nlohmann writes NaN as null), `fallback` if absent.
double NumberOf(const nlohmann::json& j, const char* key, double fallback = 0.0) {
  if (!j.contains(key)) return fallback;
  return j[key].is_number() ? j[key].get<double>() : std::numeric_limits<double>::quiet_NaN();
}

/// summary.json of a run folder (null if it is missing or unreadable).
nlohmann::json ReadSummary(const fs::path& dir) {
  try {
    std::ifstream in(dir / "summary.json");
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return nullptr;
  }
}

/// A run's result as its summary.json gives it (ResultOfRunFolder).
RunResult ResultOfSummary(const nlohmann::json& j, const fs::path& dir, const std::string& label) {
  RunResult res;
  res.label = label;
  res.dir = dir;
  if (!j.is_object()) {
    res.error = Error((dir / "summary.json").string(), "missing or unreadable: the run did not end").what();
    return res;
  }
  res.error = j.value("status", std::string()) == "completed" ? "" : j.value("stopped", std::string("no status"));
  res.ok = res.error.empty();
  res.wall_s = NumberOf(j, "wall_s");
  res.steps = j.value("steps", std::int64_t{0});
  res.tracking_pct = NumberOf(j, "tracking_nrmse_pct");
  res.peak_force_kN = NumberOf(j, "peak_force_kN");
  if (j.contains("benchmark_criteria")) {
    const nlohmann::json& b = j["benchmark_criteria"];
    signal::BenchmarkCriteria c;
    double* const js[] = {&c.J1_ms, &c.J2_pct, &c.J3_pct, &c.J4_pct, &c.J5_pct, &c.J6_pct, &c.J7_pct, &c.J8_pct, &c.J9_pct};
    const char* const names[] = {"J1_ms", "J2_pct", "J3_pct", "J4_pct", "J5_pct", "J6_pct", "J7_pct", "J8_pct", "J9_pct"};
    for (int i = 0; i < 9; ++i) *js[i] = NumberOf(b, names[i]);
    c.lag_samples = b.value("lag_samples", 0);
    for (const auto& f : b.value("floors", nlohmann::json::array())) {
      c.floors.push_back({f.value("floor", 0), NumberOf(f, "std_pct"), NumberOf(f, "max_pct")});
    }
    res.benchmark = c;
  }
  res.benchmark_error = j.value("benchmark_criteria_error", std::string());
  return res;
}

/// One run of the batch through the supervisor (memq, in this thread); its summary.json says how
/// it went, also when it could not run.
RunResult RunOne(const RunSpec& spec, const std::string& origin, const BatchControl& control, bool* reused) {
  RunResult res;
  res.label = spec.label;
  res.dir = spec.dir;
  if (control.resume && fs::exists(spec.dir)) {
    // A run that ended stands; one that was interrupted, or never wrote its summary, is made again.
    const nlohmann::json j = ReadSummary(spec.dir);
    const std::string status = j.is_object() ? j.value("status", std::string()) : std::string();
    if (!status.empty() && status != "interrupted") {
      *reused = true;
      return ResultOfSummary(j, spec.dir, spec.label);
    }
    fs::remove_all(spec.dir);
  }
  if (fs::exists(spec.dir / "log.lcm")) {  // the folder's run and its summary stay as they are
    res.error = Error(spec.dir.string(), "holds a run already; refusing to overwrite it").what();
    return res;
  }
  supervisor::RunRequest request;
  request.scenario = spec.scenario;
  request.scenario_header = ScenarioHeader(spec, origin);
  request.transport = "memq";
  request.out = spec.dir;
  request.check_before_start = false;  // Preflight did
  request.keep_folder = true;
  request.batch_summary = true;
  request.label = spec.label;
  request.interrupted = control.interrupted;
  supervisor::RunSummary sum;
  try {
    sum = supervisor::Run(request).summary;
  } catch (const supervisor::RunError& e) {
    sum = e.summary();
    if (fs::exists(spec.dir / "log.lcm")) supervisor::ReadLog((spec.dir / "log.lcm").string(), &sum);
    supervisor::MarkStudyFailure(e.what(), &sum);
    try {
      fs::create_directories(spec.dir);
      std::ofstream(spec.dir / "summary.json") << sum.ToJson().dump(2) << "\n";
    } catch (const std::exception&) {
    }
  }
  res.error = sum.status == "completed" ? "" : sum.stopped;
  res.ok = res.error.empty();
  res.wall_s = sum.wall_s;
  res.steps = sum.steps;
  if (sum.metrics) {
    res.tracking_pct = sum.metrics->tracking_nrmse_pct;
    res.peak_force_kN = sum.metrics->peak_force_kN;
  }
  res.benchmark = sum.benchmark_criteria;
  res.benchmark_error = sum.benchmark_error;
  return res;
}

/// Resuming: every run folder already there must hold the very scenario this batch would write
/// (the same study, options and overrides), else the tables would mix two studies. Throws
/// rths::Error naming the folders that differ.
void CheckResumable(const std::vector<RunSpec>& specs, const std::string& origin) {
  std::vector<std::string> differ;
  for (const auto& spec : specs) {
    const fs::path file = spec.dir / "scenario.toml";
    if (!fs::exists(file)) continue;
    std::ifstream in(file, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text != "# " + ScenarioHeader(spec, origin) + "\n" + scenario::ToToml(spec.scenario)) {
      differ.push_back(spec.dir.string());
    }
  }
  if (differ.empty()) return;
  throw Error("--resume", fmt::format("{} run folder(s) hold another scenario than this study makes (e.g. {}): resume "
                                      "with the options the interrupted study had (--quick, --plant, --set, ...)",
                                      differ.size(), differ.front()));
}

}  // namespace

RunResult ResultOfRunFolder(const fs::path& dir, const std::string& label) {
  return ResultOfSummary(ReadSummary(dir), dir, label);
}

std::string BatchInterrupted::Describe(std::size_t ended, std::size_t cut, std::size_t not_started) {
  return fmt::format("interrupted: {} run(s) ended and stand, {} stopped mid-run (their summary.json says "
                     "\"interrupted\", their log ends on their last complete step), {} not started",
                     ended, cut, not_started);
}

std::vector<RunResult> RunBatch(const std::vector<RunSpec>& specs, int jobs, ProgressLine* line,
                                const Progress& progress, const std::string& origin, const BatchControl& control) {
  if (jobs < 1) throw Error("reproduce", "--jobs must be >= 1");
  if (control.resume) CheckResumable(specs, origin);
  std::vector<RunResult> results(specs.size());
  std::vector<char> started(specs.size(), 0), cut(specs.size(), 0);
  auto stopping = [&] { return control.interrupted != nullptr && *control.interrupted != 0; };
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  // Progress by simulated steps of the finished runs (runs differ in length).
  double total_steps = 0.0, done_steps = 0.0;
  for (const auto& spec : specs) total_steps += static_cast<double>(spec.scenario.steps());
  std::mutex m;
  auto worker = [&] {
    for (;;) {
      if (stopping()) return;
      const std::size_t i = next.fetch_add(1);
      if (i >= specs.size()) return;
      started[i] = 1;
      bool reused = false;
      RunResult r = RunOne(specs[i], origin, control, &reused);
      std::lock_guard<std::mutex> lock(m);
      // A run the interrupt cut short is no result: it is made again on --resume.
      if (!reused && stopping() && !r.ok) cut[i] = 1;
      results[i] = r;
      ++done;
      done_steps += static_cast<double>(specs[i].scenario.steps());
      if (progress) progress(done, specs.size(), results[i]);
      if (line) line->Update(done_steps, total_steps, fmt::format("{} of {} runs", done, specs.size()));
    }
  };
  const int n = std::min<int>(jobs, static_cast<int>(std::max<std::size_t>(specs.size(), 1)));
  std::vector<std::thread> threads;
  for (int t = 0; t < n; ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (stopping()) {
    std::size_t n_started = 0, n_cut = 0;
    for (std::size_t i = 0; i < specs.size(); ++i) {
      n_started += started[i];
      n_cut += cut[i];
    }
    throw BatchInterrupted(n_started - n_cut, n_cut, specs.size() - n_started);
  }
  return results;
}

}  // namespace rths::studies
