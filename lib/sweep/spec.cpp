#include "sweep/spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include <fmt/core.h>
#include <toml++/toml.h>

#include "core/error.h"
#include "models/benchmark_plant.h"
#include "sweep/element_keys.h"

namespace rths::sweep {

namespace fs = std::filesystem;

std::string FloatLiteral(double x) {
  std::string out = fmt::format("{}", x);
  if (out.find_first_of(".eEn") == std::string::npos) out += ".0";
  return out;
}

namespace {

/// A TOML literal of a scalar value, as `--set KEY=VALUE` takes it; "" for an unsupported type.
std::string ScalarLiteral(const toml::node& v) {
  if (const auto* s = v.as_string()) {
    std::string out = "\"";
    for (const char c : s->get()) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    return out + "\"";
  }
  if (const auto* i = v.as_integer()) return std::to_string(i->get());
  if (const auto* b = v.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* d = v.as_floating_point()) return std::isfinite(d->get()) ? FloatLiteral(d->get()) : "";
  return "";
}

/// A TOML literal of a [set] value or a grid level, as `--set KEY=VALUE` takes it: a scalar, or a
/// non-empty array of numbers ("[2, 95]", the level's text in the table); "" for anything else.
std::string Literal(const toml::node& v) {
  const auto* a = v.as_array();
  if (a == nullptr) return ScalarLiteral(v);
  std::string out = "[";
  for (const toml::node& e : *a) {
    if (!e.is_integer() && !e.is_floating_point()) return "";
    const std::string x = ScalarLiteral(e);
    if (x.empty()) return "";
    out += (out.size() > 1 ? ", " : "") + x;
  }
  return a->empty() ? "" : out + "]";
}

/// Refuses KEY[i] outside [draw]: [set] and [grid] give whole arrays.
void WholeKey(const std::string& key, const std::string& where) {
  if (SplitElementKey(key, where)) {
    throw Error(where, "one element of an array (KEY[i]) may be drawn in [draw]; here give the whole array, "
                       "e.g. \"controller.lti.feedback.num\" = [[2.0, 95.0], [3.0, 120.0]] in [grid]");
  }
}

/// FNV-1a of a key: its stream differs from every other key's.
std::uint64_t KeyHash(const std::string& key) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : key) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// A uniform double in (0, 1) from 53 random bits.
double Unit(std::uint64_t* state) {
  return (static_cast<double>(SplitMix64(state) >> 11) + 0.5) * 0x1.0p-53;
}

/// One standard normal deviate (Box-Muller, the cosine branch).
double StandardNormal(std::uint64_t* state) {
  const double u1 = Unit(state), u2 = Unit(state);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

std::string Value(const Draw& d, std::uint64_t* state) {
  if (d.dist == "normal") return FloatLiteral(d.a + d.b * StandardNormal(state));
  if (d.dist == "lognormal") return FloatLiteral(std::exp(d.a + d.b * StandardNormal(state)));
  if (d.dist == "uniform") return FloatLiteral(d.a + (d.b - d.a) * Unit(state));
  return std::to_string(1 + SplitMix64(state) % 2147483646ULL);  // "seed": [1, 2^31 - 2]
}

double Number(const toml::table& t, const std::string& where, const char* name) {
  const auto v = t[name].value<double>();
  if (!v || !std::isfinite(*v)) throw Error(where, fmt::format("needs a finite number `{}`", name));
  return *v;
}

Draw ParseDraw(const std::string& key, const toml::node& node, const std::string& where) {
  const auto* t = node.as_table();
  if (!t) throw Error(where, "must be a table such as { dist = \"normal\", mean = 0.02, std = 0.002 }");
  Draw d;
  d.key = key;
  d.dist = (*t)["dist"].value_or(std::string());
  if (d.dist == "normal") {
    d.a = Number(*t, where, "mean");
    d.b = Number(*t, where, "std");
    if (d.b < 0) throw Error(where + ".std", fmt::format("{} is out of range [0, inf)", d.b));
  } else if (d.dist == "lognormal") {
    d.a = Number(*t, where, "mu");
    d.b = Number(*t, where, "sigma");
    if (d.b < 0) throw Error(where + ".sigma", fmt::format("{} is out of range [0, inf)", d.b));
  } else if (d.dist == "uniform") {
    d.a = Number(*t, where, "lo");
    d.b = Number(*t, where, "hi");
    if (!(d.a < d.b)) throw Error(where, fmt::format("needs lo < hi (lo = {}, hi = {})", d.a, d.b));
  } else if (d.dist == "benchmark_plant") {
    if (key != "plant.benchmark") throw Error(where, "dist = \"benchmark_plant\" is drawn for the key \"plant.benchmark\"");
  } else if (d.dist != "seed") {
    throw Error(where + ".dist", fmt::format("\"{}\": allowed \"normal\", \"uniform\", \"lognormal\", \"seed\", "
                                             "\"benchmark_plant\"",
                                             d.dist));
  }
  return d;
}

std::string Resolve(const std::string& spec_path, const std::string& file) {
  const fs::path p(file);
  return (p.is_absolute() ? p : fs::path(spec_path).parent_path() / p).lexically_normal().string();
}

void ParseSweepTable(const toml::table& root, const std::string& path, Spec* spec) {
  const auto* sweep = root["sweep"].as_table();
  if (!sweep) throw Error(path, "needs a [sweep] table (base, seed, record; see lib/sweep/spec.h)");
  for (const auto& [k, v] : *sweep) {
    const std::string key(k.str());
    if (key != "name" && key != "base" && key != "seed" && key != "draws" && key != "record") {
      throw Error(path + ": sweep." + key, "unknown key; allowed: name, base, seed, draws, record");
    }
  }
  spec->name = (*sweep)["name"].value_or(spec->name);
  const auto seed = (*sweep)["seed"].value<std::int64_t>();
  if (seed && *seed < 0) throw Error(path + ": sweep.seed", fmt::format("{} is out of range [0, 2^63)", *seed));
  spec->seed = static_cast<std::uint64_t>(seed.value_or(1));
  spec->draws = (*sweep)["draws"].value_or(std::int64_t{0});
  if (spec->draws < 0 || spec->draws > kMaxRuns) {
    throw Error(path + ": sweep.draws", fmt::format("{} is out of range [0, {}]", spec->draws, kMaxRuns));
  }
  if (const auto* record = (*sweep)["record"].as_array()) {
    for (const auto& f : *record) {
      const auto name = f.value<std::string>();
      if (!name || name->empty()) throw Error(path + ": sweep.record", "must list summary.json field names");
      spec->record.push_back(*name);
    }
  }
  if (const auto base = (*sweep)["base"].value<std::string>()) spec->cases.push_back(Resolve(path, *base));
}

void ParseSlurmTable(const toml::table& slurm, const std::string& path, SlurmSettings* out) {
  for (const auto& [k, v] : slurm) {
    const std::string key(k.str());
    const std::string where = path + ": slurm." + key;
    if (key == "partition" || key == "time" || key == "account") {
      const auto s = v.value<std::string>();
      if (!s) throw Error(where, "must be a string");
      (key == "partition" ? out->partition : key == "time" ? out->time : out->account) = *s;
    } else if (key == "runs_per_task" || key == "cpus_per_task" || key == "retries") {
      const auto n = v.value<std::int64_t>();
      const std::int64_t hi = key == "runs_per_task" ? kMaxRuns : key == "cpus_per_task" ? 4096 : 100;
      const std::int64_t lo = key == "retries" ? 0 : 1;
      if (!n || *n < lo || *n > hi) throw Error(where, fmt::format("must be an integer in [{}, {}]", lo, hi));
      if (key == "runs_per_task") out->runs_per_task = *n;
      if (key == "cpus_per_task") out->cpus_per_task = static_cast<int>(*n);
      if (key == "retries") out->retries = static_cast<int>(*n);
    } else if (key == "sbatch_args") {
      const auto* a = v.as_array();
      if (!a) throw Error(where, "must be an array of sbatch options, e.g. [\"--qos=short\"]");
      for (const auto& x : *a) {
        const auto s = x.value<std::string>();
        if (!s || s->rfind("-", 0) != 0) throw Error(where, "each entry must be one sbatch option starting with '-'");
        out->sbatch_args.push_back(*s);
      }
    } else if (key == "setup") {
      const auto* a = v.as_array();
      if (!a) throw Error(where, "must be an array of shell lines (strings), e.g. [\"module load gcc/12\"]");
      for (std::size_t i = 0; i < a->size(); ++i) {
        const auto s = (*a)[i].value<std::string>();
        if (!s) throw Error(fmt::format("{}[{}]", where, i), "must be a string: one shell line");
        if (const std::string problem = SetupLineProblem(*s); !problem.empty()) {
          throw Error(fmt::format("{}[{}]", where, i), problem);
        }
        out->setup.push_back(*s);
      }
    } else {
      throw Error(where, "unknown key; allowed: partition, time, account, runs_per_task, cpus_per_task, retries, "
                         "sbatch_args, setup");
    }
  }
}

}  // namespace

std::uint64_t SplitMix64(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::string SetupLineProblem(const std::string& line) {
  if (line.find_first_not_of(" \t") == std::string::npos) return "is empty: give a shell line, e.g. \"module load gcc/12\"";
  for (const unsigned char c : line) {
    if (c < 0x20 && c != '\t') return "holds a newline or another control character: one entry is one line";
    if (c == 0x7f) return "holds a control character (DEL)";
  }
  if (line.size() > 4096) return fmt::format("is {} bytes long: at most 4096", line.size());
  return "";
}

std::int64_t Spec::combinations() const {
  std::int64_t n = 1;
  for (const Axis& a : grid) n *= static_cast<std::int64_t>(a.values.size());
  return n;
}

std::int64_t Spec::runs() const {
  return static_cast<std::int64_t>(cases.size()) * combinations() * std::max<std::int64_t>(draws, 1);
}

namespace {

/// [cases], [grid], [set] and [draw] into `spec`.
void ParseAxes(const toml::table& root, const std::string& path, Spec* spec_ptr) {
  Spec& spec = *spec_ptr;
  if (const auto* cases = root["cases"].as_table()) {
    if (!spec.cases.empty()) throw Error(path + ": cases", "give either sweep.base or [cases] files, not both");
    const auto* files = (*cases)["files"].as_array();
    if (!files || files->empty()) throw Error(path + ": cases.files", "must list at least one scenario file");
    for (const auto& f : *files) {
      const auto file = f.value<std::string>();
      if (!file) throw Error(path + ": cases.files", "must list scenario file paths (strings)");
      spec.cases.push_back(Resolve(path, *file));
    }
  }
  if (spec.cases.empty()) throw Error(path + ": sweep.base", "missing: the scenario every run starts from");
  if (const auto* grid = root["grid"].as_table()) {
    for (const auto& [k, v] : *grid) {
      const std::string where = fmt::format("{}: grid.\"{}\"", path, k.str());
      WholeKey(std::string(k.str()), where);
      const auto* values = v.as_array();
      if (!values || values->empty()) throw Error(where, "must be a non-empty array of values");
      Axis axis{std::string(k.str()), {}};
      for (const auto& value : *values) {
        const std::string literal = Literal(value);
        if (literal.empty()) {
          throw Error(where, "values must be strings, integers, finite floats, booleans or non-empty arrays of "
                             "numbers (levels of an array-valued key: [[2.0, 95.0], [3.0, 120.0]])");
        }
        axis.values.push_back(literal);
      }
      spec.grid.push_back(std::move(axis));
    }
  }
  if (const auto* set = root["set"].as_table()) {
    for (const auto& [k, v] : *set) {
      const std::string where = fmt::format("{}: set.\"{}\"", path, k.str());
      WholeKey(std::string(k.str()), where);
      const std::string literal = Literal(v);
      if (literal.empty()) {
        throw Error(where, "must be a string, an integer, a finite float, a boolean or a non-empty array of numbers");
      }
      spec.fixed.emplace_back(std::string(k.str()), literal);
    }
  }
  if (const auto* draw = root["draw"].as_table()) {
    for (const auto& [k, v] : *draw) {
      const std::string where = fmt::format("{}: draw.\"{}\"", path, k.str());
      std::string key(k.str());
      if (const auto element = SplitElementKey(key, where)) {  // "num[00]" is "num[0]": one stream, one column
        key = fmt::format("{}[{}]", element->array_key, element->index);
      }
      spec.draw.push_back(ParseDraw(key, v, where));
    }
  }
}

/// Sorts the axes by key; refuses a key given twice and a sweep of more than kMaxRuns runs.
void SortAndCheck(const std::string& path, Spec* spec_ptr) {
  Spec& spec = *spec_ptr;
  auto key_order = [](const auto& x, const auto& y) { return x.key < y.key; };
  std::sort(spec.grid.begin(), spec.grid.end(), key_order);
  std::sort(spec.draw.begin(), spec.draw.end(), key_order);
  std::sort(spec.fixed.begin(), spec.fixed.end());
  // A key varied in one place only.
  std::vector<std::string> keys;
  for (const auto& [k, v] : spec.fixed) keys.push_back(k);
  for (const Axis& a : spec.grid) keys.push_back(a.key);
  for (const Draw& d : spec.draw) {
    for (const std::string& k : DrawColumns(d)) keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  if (const auto dup = std::adjacent_find(keys.begin(), keys.end()); dup != keys.end()) {
    throw Error(path + ": " + *dup, "is given in more than one of [set], [grid] and [draw]");
  }
  // The run count, without overflow.
  double runs = static_cast<double>(spec.cases.size()) * static_cast<double>(std::max<std::int64_t>(spec.draws, 1));
  for (const Axis& a : spec.grid) runs *= static_cast<double>(a.values.size());
  if (runs > static_cast<double>(kMaxRuns)) {
    throw Error(path, fmt::format("{:.0f} runs: more than the {} a sweep may hold; split it", runs, kMaxRuns));
  }
}

}  // namespace

Spec ParseSpec(const std::string& text, const std::string& path) {
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw Error(path, fmt::format("line {}: {}", e.source().begin.line, e.description()));
  }
  for (const auto& [k, v] : root) {
    const std::string key(k.str());
    if (key != "sweep" && key != "cases" && key != "set" && key != "grid" && key != "draw" && key != "slurm") {
      throw Error(path + ": " + key, "unknown table; allowed: [sweep], [cases], [set], [grid], [draw], [slurm]");
    }
  }
  Spec spec;
  spec.path = path;
  ParseSweepTable(root, path, &spec);
  ParseAxes(root, path, &spec);
  if (const auto* slurm = root["slurm"].as_table()) ParseSlurmTable(*slurm, path, &spec.slurm);
  if (!spec.draw.empty() && spec.draws == 0) {
    throw Error(path + ": sweep.draws", "[draw] needs sweep.draws >= 1 (the runs per grid point)");
  }
  if (spec.draw.empty() && spec.draws > 0) throw Error(path + ": sweep.draws", "needs a [draw] table to draw from");
  SortAndCheck(path, &spec);
  return spec;
}

Spec LoadSpec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot read the sweep SPEC");
  std::stringstream text;
  text << in.rdbuf();
  Spec spec = ParseSpec(text.str(), fs::absolute(path).lexically_normal().string());
  CheckElementKeys(spec);
  return spec;
}

std::vector<std::string> DrawColumns(const Draw& d) {
  if (d.dist == "benchmark_plant") {
    return {d.key + ".b1", d.key + ".b2", d.key + ".a3", d.key + ".k_e_N_per_m"};
  }
  return {d.key};
}

RunPoint PointOf(const Spec& spec, std::int64_t index) {
  if (index < 0 || index >= spec.runs()) {
    throw Error(spec.path, fmt::format("run {} is out of range [0, {})", index, spec.runs()));
  }
  const std::int64_t per_draw = std::max<std::int64_t>(spec.draws, 1);
  const std::int64_t per_case = spec.combinations() * per_draw;
  RunPoint p;
  p.index = index;
  p.case_index = index / per_case;
  p.combination = (index % per_case) / per_draw;
  p.draw = index % per_draw;
  p.scenario = spec.cases[static_cast<std::size_t>(p.case_index)];
  // The grid's combination: the last key varies fastest.
  std::vector<std::size_t> pick(spec.grid.size());
  std::int64_t rest = p.combination;
  for (std::size_t a = spec.grid.size(); a-- > 0;) {
    const auto n = static_cast<std::int64_t>(spec.grid[a].values.size());
    pick[a] = static_cast<std::size_t>(rest % n);
    rest /= n;
  }
  for (const auto& [key, value] : spec.fixed) p.sets.push_back(key + "=" + value);
  for (std::size_t a = 0; a < spec.grid.size(); ++a) {
    p.sets.push_back(spec.grid[a].key + "=" + spec.grid[a].values[pick[a]]);
  }
  for (const Draw& d : spec.draw) {
    std::uint64_t state = spec.seed;
    state = SplitMix64(&state) ^ static_cast<std::uint64_t>(index);
    state = SplitMix64(&state) ^ KeyHash(d.key);
    if (d.dist != "benchmark_plant") {
      p.sets.push_back(d.key + "=" + Value(d, &state));
      continue;
    }
    // The benchmark's Gaussian uncertainty of b1, b2, a3 and k_e about its nominal plant
    // (models::PerturbedBenchmarkParams), seeded from this run's stream; the numerical
    // substructure follows the perturbed specimen (structure.subtract_specimen).
    const std::uint64_t seed = 1 + SplitMix64(&state) % 2147483646ULL;
    const models::BenchmarkPlantParams b = models::PerturbedBenchmarkParams(models::BenchmarkPlantParams{}, seed);
    const std::vector<std::string> keys = DrawColumns(d);
    const double values[] = {b.b1, b.b2, b.a3, b.k_e_N_per_m};
    for (std::size_t k = 0; k < keys.size(); ++k) p.sets.push_back(keys[k] + "=" + FloatLiteral(values[k]));
    p.sets.push_back("structure.subtract_specimen=true");
  }
  return p;
}

}  // namespace rths::sweep
