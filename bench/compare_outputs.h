#pragma once
// bench-compare --outputs: every output file of the same commands in two checkouts, compared byte
// for byte (see the top of compare.cpp). Included by compare.cpp only (bench/*.cpp are globbed as
// one program each, so this mode is a header).
#include <fmt/core.h>
#include <fmt/format.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>
#include <stdexcept>

#include "studies/study_table.h"

namespace outputs {

namespace fs = std::filesystem;

/// One command, run in each checkout with the working folder its side's output folder. `line` is a
/// shell line with {rths} (the checkout's ./rths), {root} (the checkout), {out} (the side's output
/// folder, absolute) and {set} (--other-set arguments on the other side, "" on this one) filled in.
struct Command {
  std::string name;  ///< also the stem of its NAME.stdout, NAME.stderr and NAME.rc files
  std::string line;
};

/// The commands: every reproduction of studies::Studies(), `design` on every shipped scenario, the real-data study and
/// a rig-mode run diagnosed (train: the shipped seeds; test: desired seed 4, noise seed 8).
inline std::vector<Command> Commands(const fs::path& root, bool full, const std::string& only) {
  const std::string quick = full ? "" : " --quick";
  std::vector<Command> c;
  const auto want = [&](const std::string& group) { return only.empty() || only.find(group) != std::string::npos; };
  if (want("reproduce")) {
    for (const auto& study : rths::studies::Studies()) {  // the one list of studies (studies/study_table.h)
      const std::string& n = study.name;
      c.push_back({fmt::format("reproduce_{}", n),
                   fmt::format("{{rths}} reproduce {}{} {{set}} --out {{out}}/reproduce_{}", n, quick, n)});
    }
    c.push_back({"reproduce_table2_extended",
                 "{rths} reproduce table2 --extended" + quick + " {set} --out {out}/reproduce_table2_extended"});
  }
  if (want("design")) {
    std::vector<fs::path> scenarios;
    for (const auto& e : fs::recursive_directory_iterator(root / "scenarios")) {
      if (e.path().extension() == ".toml") scenarios.push_back(fs::relative(e.path(), root));
    }
    std::sort(scenarios.begin(), scenarios.end());
    for (const fs::path& s : scenarios) {
      std::string stem = s.string();
      std::replace(stem.begin(), stem.end(), '/', '_');
      stem = "design_" + stem.substr(0, stem.size() - 5);
      c.push_back({stem, fmt::format("{{rths}} design {{root}}/{} {{set}} --out {}.json", s.string(), stem)});
    }
  }
  if (want("real_data")) c.push_back({"real_data", "RTHS={rths} {root}/scripts/real_data_study.sh real_data"});
  if (want("rig")) {
    const std::string run = "{rths} run {root}/scenarios/rig_mode_example.toml --transport memq --quiet {set}";
    c.push_back({"rig_run_a", run + " --run-id 1 --out rig_a"});
    c.push_back({"rig_run_b", run + " --run-id 2 --set structure.desired.seed=4 --set plant.noise_seed=8 --out rig_b"});
    c.push_back({"rig_record_a", "{rths} record rig_a --out rig_a.csv"});
    c.push_back({"rig_record_b", "{rths} record rig_b --out rig_b.csv"});
    c.push_back({"rig_diagnose", "{rths} diagnose --train rig_a.csv --test rig_b.csv --out rig_diagnosis"});
  }
  return c;
}

inline std::string Fill(std::string s, const std::map<std::string, std::string>& with) {
  for (const auto& [key, value] : with) {
    for (std::size_t p; (p = s.find(key)) != std::string::npos;) s.replace(p, key.size(), value);
  }
  return s;
}

inline std::string Quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `cmd` in `root`'s side folder `out`: NAME.stdout, NAME.stderr, NAME.rc; its wall time [s].
inline double RunOne(const Command& cmd, const fs::path& root, const fs::path& out, const std::string& set) {
  const std::string line = Fill(cmd.line, {{"{rths}", Quoted((root / "rths").string())},
                                           {"{root}", Quoted(root.string())},
                                           {"{out}", Quoted(out.string())},
                                           {"{set}", set}});
  const std::string sh =
      fmt::format("cd {} && env -u RTHS_BIN_DIR bash -c {} > {}.stdout 2> {}.stderr; echo $? > {}.rc",
                  Quoted(out.string()), Quoted(line), cmd.name, cmd.name, cmd.name);
  const auto t0 = std::chrono::steady_clock::now();
  (void)std::system(sh.c_str());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A named replacement that hides what differs between two runs of the same commit.
struct Mask {
  std::string name;
  std::regex pattern;
  std::string with;
};

/// JSON keys whose values differ between two runs of the same commit (found by running every
/// command twice in one checkout: --this D --other D): the run id, wall times and rates, the step
/// latencies (the clock measures them on every run, paced or not), the diagnosis' runtime and
/// "link", the udpm transport's counters of re-requested, repaired and duplicate messages (they
/// follow the host's timing; the payloads do not: log.lcm is compared by payload), and the clock's
/// "peers" (each participant's pid and those counters as the clock saw them).
inline const std::vector<std::string>& VolatileKeys() {
  static const std::vector<std::string> keys = {"run_id",
                                                "wall_s",
                                                "stepping_s",
                                                "steps_per_s",
                                                "link",
                                                "peers",
                                                "latency_histogram_us",
                                                "latency_max_us",
                                                "latency_p50_us",
                                                "latency_p99_us",
                                                "latency_p999_us",
                                                "max_release_late_us",
                                                "runtime_s"};
  return keys;
}

/// Text masks: the two sides' folders (checkout, output folder), then dates and wall times.
inline std::vector<Mask> TextMasks(const std::vector<std::pair<std::string, std::string>>& folders) {
  std::vector<Mask> m;
  for (const auto& [path, as] : folders) {
    m.push_back(
        {"folder " + as, std::regex(std::regex_replace(path, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)")), as});
  }
  m.push_back({"'Made by ... on <date>'", std::regex(R"( on \d{4}-\d\d-\d\d \d\d:\d\d UTC)"), " on <date>"});
  m.push_back({"'in N s wall time'", std::regex(R"(in \d+(\.\d+)? s wall time)"), "in <wall> s wall time"});
  m.push_back({"study's 'runs in N s' and 'time: N s'", std::regex(R"((runs in|time:) \d+(\.\d+)? s)"), "$1 <wall> s"});
  m.push_back({"diagnosis 'runtime N s'", std::regex(R"(runtime:? \d+(\.\d+)? s)"), "runtime <wall> s"});
  m.push_back({"progress line '[i/N] ... (N.N s)'", std::regex(R"(\(\d+(\.\d+)? s\))"), "(<wall> s)"});
  return m;
}

inline std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> v;
  std::stringstream ss(text);
  for (std::string line; std::getline(ss, line);) v.push_back(line);
  return v;
}

/// JSON without the volatile keys (and `extra` keys), one key per line.
inline std::string MaskedJson(const std::string& text, const std::vector<std::string>& extra, bool* masked) {
  auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded()) return text;
  std::vector<std::string> keys = VolatileKeys();
  keys.insert(keys.end(), extra.begin(), extra.end());
  const std::function<void(nlohmann::json&)> drop = [&](nlohmann::json& v) {
    if (v.is_object()) {
      for (const std::string& k : keys) {
        if (v.contains(k)) v[k] = "<masked>", *masked = true;
      }
      for (auto& [k, x] : v.items()) drop(x);
    } else if (v.is_array()) {
      for (auto& x : v) drop(x);
    }
  };
  drop(j);
  return j.dump(1);
}

/// The outcome for one file present on both sides.
struct Verdict {
  enum Kind { kIdentical, kMasked, kDifferent } kind = kIdentical;
  std::string detail;           ///< the first difference (kDifferent)
  std::set<std::string> masks;  ///< masks that made the file identical
};

inline std::string Clip(const std::string& s) { return s.size() > 110 ? s.substr(0, 110) + "..." : s; }

/// A study's progress line "[ i/N] label ... (t s)": parallel runs finish in any order.
inline bool IsProgress(const std::string& line) {
  static const std::regex progress(R"(^\s*\[\s*\d+/\d+\] )");
  return std::regex_search(line, progress);
}

/// The progress lines of `lines` moved to its end, counter cut, sorted (completion order aside).
inline std::vector<std::string> ProgressLast(const std::vector<std::string>& lines, bool* moved) {
  std::vector<std::string> rest, progress;
  for (const std::string& l : lines) {
    if (IsProgress(l))
      progress.push_back(l.substr(l.find(']') + 1));
    else
      rest.push_back(l);
  }
  std::sort(progress.begin(), progress.end());
  *moved = *moved || !progress.empty();
  rest.insert(rest.end(), progress.begin(), progress.end());
  return rest;
}

/// `extra_json_keys`: keys masked in this JSON file beside VolatileKeys().
inline Verdict CompareText(std::string a, std::string b, bool json, bool console, const std::vector<Mask>& masks,
                           const std::vector<std::string>& extra_json_keys = {}) {
  Verdict v;
  if (json) {
    bool ma = false, mb = false;
    a = MaskedJson(a, extra_json_keys, &ma), b = MaskedJson(b, extra_json_keys, &mb);
    if (a == b) {
      v.kind = Verdict::kMasked;
      v.masks.insert("JSON keys " + fmt::format("{}", fmt::join(VolatileKeys(), ", ")));
      if (!extra_json_keys.empty())
        v.masks.insert(fmt::format("JSON keys {} (beside a scenario.toml the same after masking)",
                                   fmt::join(extra_json_keys, ", ")));
      return v;
    }
  }
  auto la = Lines(a), lb = Lines(b);
  if (console) {
    bool moved = false;
    const auto pa = ProgressLast(la, &moved), pb = ProgressLast(lb, &moved);
    if (moved && la != lb) v.masks.insert("order of progress lines (parallel runs)");
    la = pa, lb = pb;
  }
  for (std::size_t i = 0; i < std::max(la.size(), lb.size()); ++i) {
    if (i >= la.size() || i >= lb.size()) {
      v.kind = Verdict::kDifferent;
      v.detail = fmt::format("{} lines against {}", la.size(), lb.size());
      return v;
    }
    if (la[i] == lb[i]) continue;
    std::string x = la[i], y = lb[i];
    for (const Mask& m : masks) {
      const std::string x2 = std::regex_replace(x, m.pattern, m.with), y2 = std::regex_replace(y, m.pattern, m.with);
      if (x2 != x || y2 != y) v.masks.insert(m.name);
      x = x2, y = y2;
    }
    if (x != y) {
      v.kind = Verdict::kDifferent;
      v.detail = fmt::format("line {}: '{}' against '{}'", i + 1, Clip(la[i]), Clip(lb[i]));
      return v;
    }
  }
  v.kind = v.masks.empty() ? Verdict::kIdentical : Verdict::kMasked;
  return v;
}

inline bool IsText(const std::string& ext) {
  static const std::set<std::string> text = {".csv", ".md",  ".txt", ".toml", ".html", ".json", ".stdout", ".stderr",
                                             ".rc",  ".log", ".svg", ".m",    ".dat",  ".tex",  ""};
  return text.count(ext) > 0;
}

/// Compares one file of the two sides: bytes, then by kind (log.lcm: `rths log compare`).
inline Verdict CompareFile(const fs::path& a, const fs::path& b, const fs::path& rths, const std::vector<Mask>& masks) {
  const std::string ta = Slurp(a), tb = Slurp(b);
  if (ta == tb) return {};
  const std::string ext = a.extension().string();
  if (ext == ".lcm") {
    const std::string cmd = fmt::format("{} log compare {} {} > /dev/null 2>&1", Quoted(rths.string()),
                                        Quoted(a.string()), Quoted(b.string()));
    const int rc = std::system(cmd.c_str());
    if (WIFEXITED(rc) && WEXITSTATUS(rc) == 0)
      return {Verdict::kMasked, "", {"log: payload per (channel, k), run_id aside"}};
    return {Verdict::kDifferent, "rths log compare: the logs differ", {}};
  }
  if (!IsText(ext))
    return {Verdict::kDifferent, fmt::format("bytes differ ({} against {} bytes)", ta.size(), tb.size()), {}};
  // A run folder's scenario_sha256 is the hash of its scenario.toml, whose first comment names the
  // file it came from (a path in the checkout): when the two scenario.toml are the same after
  // masking, so is what the hash stands for.
  std::vector<std::string> extra;
  const fs::path sa = a.parent_path() / "scenario.toml", sb = b.parent_path() / "scenario.toml";
  if (ext == ".json" && fs::exists(sa) && fs::exists(sb) &&
      CompareText(Slurp(sa), Slurp(sb), false, false, masks).kind != Verdict::kDifferent) {
    extra.push_back("scenario_sha256");
  }
  return CompareText(ta, tb, ext == ".json", ext == ".stdout" || ext == ".stderr", masks, extra);
}

inline std::set<std::string> Files(const fs::path& dir) {
  std::set<std::string> f;
  if (!fs::exists(dir)) return f;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) f.insert(fs::relative(e.path(), dir).string());
  }
  return f;
}

/// The class of a file, for the summary: its extension (log.lcm apart).
inline std::string ClassOf(const std::string& rel) {
  const std::string ext = fs::path(rel).extension().string();
  return ext.empty() ? "(none)" : ext;
}

struct Tally {
  int n = 0, identical = 0, masked = 0, different = 0, one_side = 0;
};

/// Compares every file under `a` and `b`; prints one line per class and the verdict; 0 if
/// nothing differs.
inline int CompareTrees(const fs::path& a, const fs::path& b, const fs::path& rths, const std::vector<Mask>& masks) {
  const auto fa = Files(a), fb = Files(b);
  std::set<std::string> all(fa.begin(), fa.end());
  all.insert(fb.begin(), fb.end());
  std::map<std::string, Tally> by_class;
  Tally total;
  std::set<std::string> masks_used;
  std::vector<std::string> different, one_side;
  for (const std::string& rel : all) {
    Tally& t = by_class[ClassOf(rel)];
    ++t.n, ++total.n;
    if (!fa.count(rel) || !fb.count(rel)) {
      ++t.one_side, ++total.one_side;
      one_side.push_back(rel + (fa.count(rel) ? " (this only)" : " (other only)"));
      continue;
    }
    const Verdict v = CompareFile(a / rel, b / rel, rths, masks);
    if (v.kind == Verdict::kIdentical) ++t.identical, ++total.identical;
    if (v.kind == Verdict::kMasked) ++t.masked, ++total.masked, masks_used.insert(v.masks.begin(), v.masks.end());
    if (v.kind == Verdict::kDifferent) ++t.different, ++total.different, different.push_back(rel + ": " + v.detail);
  }
  std::printf("\n%-10s %6s %10s %14s %10s %10s\n", "class", "files", "identical", "after masking", "different",
              "one side");
  for (const auto& [cls, t] : by_class) {
    std::printf("%-10s %6d %10d %14d %10d %10d\n", cls.c_str(), t.n, t.identical, t.masked, t.different, t.one_side);
  }
  std::printf("\nverdict: %d files: %d identical, %d identical after masking, %d different, %d on one side only\n",
              total.n, total.identical, total.masked, total.different, total.one_side);
  for (const std::string& m : masks_used) std::printf("  mask used: %s\n", m.c_str());
  for (const std::string& d : different) std::printf("  DIFFERENT %s\n", d.c_str());
  for (const std::string& o : one_side) std::printf("  ONE SIDE  %s\n", o.c_str());
  return total.different == 0 && total.one_side == 0 ? 0 : 1;
}

/// Options of the outputs mode.
struct Options {
  fs::path mine, other, out;
  bool full = false;      ///< reproductions without --quick
  bool run = true;        ///< false: compare OUT/this and OUT/other as they are
  std::string only;       ///< groups to run (reproduce,design,real_data,rig; "" for all)
  std::string other_set;  ///< --set arguments for the other side only (to show a difference is caught)
  std::string side = "both";  ///< "this" or "other": run that side only (the other kept as it is)
};

/// Runs every command in both checkouts into OUT/this and OUT/other, then compares every file.
inline int Run(const Options& o) {
  const fs::path a = o.out / "this", b = o.out / "other";
  if (o.side != "both" && o.side != "this" && o.side != "other")
    throw std::runtime_error("--side: '" + o.side + "' is not one of both, this, other");
  const bool run_a = o.run && o.side != "other", run_b = o.run && o.side != "this";
  if (run_a) fs::remove_all(a), fs::create_directories(a);
  if (run_b) fs::remove_all(b), fs::create_directories(b);
  if (o.run) {
    const auto commands = Commands(o.mine, o.full, o.only);
    std::printf("bench-compare --outputs: %zu commands in %s (this) and %s (other), into %s\n", commands.size(),
                o.mine.c_str(), o.other.c_str(), o.out.c_str());
    for (const Command& c : commands) {
      const double x = run_a ? RunOne(c, o.mine, a, "") : 0.0;
      const double y = run_b ? RunOne(c, o.other, b, o.other_set) : 0.0;
      const std::string rc_a = Slurp(a / (c.name + ".rc")), rc_b = Slurp(b / (c.name + ".rc"));
      std::printf("  %-44s %7.1f s %7.1f s  exit %s / %s\n", c.name.c_str(), x, y,
                  rc_a.substr(0, rc_a.find('\n')).c_str(), rc_b.substr(0, rc_b.find('\n')).c_str());
      std::fflush(stdout);
    }
  }
  const auto masks = TextMasks({{fs::absolute(a).string(), "<OUT>"},
                                {fs::absolute(b).string(), "<OUT>"},
                                {o.mine.string(), "<ROOT>"},
                                {o.other.string(), "<ROOT>"}});
  return CompareTrees(a, b, o.mine / "rths", masks);
}

}  // namespace outputs
