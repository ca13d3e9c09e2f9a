#include "io/rig_record.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "core/error.h"
#include "core/text.h"

namespace rths::io {

namespace {

constexpr const char* kMagic = "# rths rig record v1";

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    const std::size_t n = comma == std::string::npos ? std::string::npos : comma - start;
    out.emplace_back(Trim(std::string_view(line).substr(start, n), kLineWhitespace));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

/// Parses a finite double from the whole of `s`; false otherwise (text, NaN, inf, empty).
bool ParseFinite(const std::string& s, double* v) {
  if (s.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(*v);
}

/// Every optional-length column is empty or as long as t_s.
bool SizesOk(const RigRecord& rec) {
  const std::size_t n = rec.size();
  for (const auto* v : {&rec.i_A, &rec.r_mm, &rec.v_V})
    if (!v->empty() && v->size() != n) return false;
  return true;
}

std::string Where(const std::string& path, std::size_t line) { return fmt::format("{}:{}", path, line); }

/// The bound on |value| of a column and its unit (0 if the column is not one of ours).
std::pair<double, const char*> BoundOf(std::string_view column) {
  if (column == "t_s") return {kMaxAbsTimeS, "s"};
  if (column == "u_mm" || column == "y_mm" || column == "r_mm") return {kMaxAbsDisplacementMm, "mm"};
  if (column == "f_kN") return {kMaxAbsForceKN, "kN"};
  if (column == "i_A") return {kMaxAbsCurrentA, "A"};
  if (column == "v_V") return {kMaxAbsVoltageV, "V"};
  return {0.0, ""};
}

/// "" if |v| is within the column's bound, else the problem.
std::string OutOfBounds(std::string_view column, double v) {
  const auto [bound, unit] = BoundOf(column);
  if (std::abs(v) <= bound) return "";
  return fmt::format("column {}: {} is out of range [-{:g}, {:g}] {} (a rig record's bound: an absurd value, or a "
                     "unit mix-up?)",
                     column, v, bound, bound, unit);
}

bool DtInRange(double dt) { return dt >= kMinDtS && dt <= kMaxDtS; }

/// The upper median: one of the record's own steps (not signal::Median, which averages the two
/// middle values of an even count, and would move a record's step).
double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// Largest |t_k - (t_0 + k dt)| [s].
double GridDeviation(const std::vector<double>& t, double dt) {
  double dev = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) dev = std::max(dev, std::abs(t[k] - (t[0] + static_cast<double>(k) * dt)));
  return dev;
}

/// Time-axis checks shared by the CSV reader and ValidateRigRecord (TimeAxis::kColumn). `line_of(k)`
/// names sample k.
template <class LineOf>
void CheckTime(const std::vector<double>& t, double dt_header, const std::string& dt_where, LineOf line_of) {
  if (t.size() < 2) return;  // too short: reported by the duration check
  std::vector<double> steps(t.size() - 1);
  for (std::size_t k = 1; k < t.size(); ++k) steps[k - 1] = t[k] - t[k - 1];
  const double med = Median(steps);
  const double n1 = static_cast<double>(t.size() - 1);
  for (std::size_t k = 1; k < t.size(); ++k) {
    const double d = steps[k - 1];
    if (!(d > 0.0)) {
      throw Error(line_of(k), fmt::format("time t_s = {} does not increase (previous {})", t[k], t[k - 1]));
    }
    if (med > 0.0 && std::abs(d - med) > 0.01 * med) {
      // A column rounded to a coarse resolution (steps of 0.3 and 0.4 ms for 0.3328 ms) is
      // uniform on the header's grid: say so instead of calling it non-uniform or a gap.
      const bool on_header_grid = GridDeviation(t, dt_header) <= 0.5 * dt_header;
      const std::string rounded_hint =
          on_header_grid ? fmt::format("; every t_s is within half a step of t_0 + k dt_s ({} s): if the column is "
                                       "rounded, take dt from the header (--time-from-header)",
                                       dt_header)
                         : "";
      if (d > 1.5 * med && !on_header_grid) {
        throw Error(line_of(k), fmt::format("gap in time: t_s jumps from {} to {} ({:.6g} s, {:.3g} steps of {:.6g} s; "
                                            "missing rows?)",
                                            t[k - 1], t[k], d, d / med, med));
      }
      throw Error(line_of(k), fmt::format("non-uniform time: step {:.6g} s from t_s = {} differs from the record's "
                                          "step {:.6g} s by more than 1 %{}",
                                          d, t[k - 1], med, rounded_hint));
    }
  }
  // The mean step over the whole record (rounding averages out) against the header, within
  // kDtAgreement: a header 0.16 % off would misplace the last sample of 20 s by 32 ms.
  const double mean = (t.back() - t.front()) / n1;
  if (std::abs(mean - dt_header) > kDtAgreement * dt_header) {
    throw Error(dt_where, fmt::format("dt_s = {} disagrees with the time column's mean step {:.9g} s ({:+.3g} %, "
                                      "allowed {:g} %; {:.6g} Hz vs {:.6g} Hz)",
                                      dt_header, mean, 100.0 * (mean - dt_header) / dt_header, 100.0 * kDtAgreement,
                                      1.0 / dt_header, 1.0 / mean));
  }
}

/// TimeAxis::kHeader: dt is the header's; t must increase and every t_k lie within half a step of
/// t_0 + k dt (no row missing or extra); the largest deviation is a warning; t_s becomes t_0 + k dt.
template <class LineOf>
void TimeFromHeader(RigRecord* rec, LineOf line_of) {
  auto& t = rec->t_s;
  if (t.size() < 2) return;
  const double dt = rec->dt_s;
  double dev = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (k > 0 && !(t[k] > t[k - 1])) {
      throw Error(line_of(k), fmt::format("time t_s = {} does not increase (previous {})", t[k], t[k - 1]));
    }
    const double place = t[0] + static_cast<double>(k) * dt;
    const double d = std::abs(t[k] - place);
    if (d > 0.5 * dt) {  // the first sample off its place: where a row went missing or extra
      throw Error(line_of(k), fmt::format("t_s = {} is {:.6g} s from its place t_0 + k dt_s = {} (k = {}): more "
                                          "than half a step (dt_s = {} s from the header); a row missing or extra?",
                                          t[k], t[k] - place, place, k, dt));
    }
    dev = std::max(dev, d);
  }
  rec->warnings.push_back(fmt::format("{}: time taken from the header (dt_s = {} s); the time column deviates from "
                                      "t_0 + k dt_s by at most {:.3g} s ({:.3g} steps, allowed 0.5)",
                                      rec->source, dt, dev, dev / dt));
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = t[0] + static_cast<double>(k) * dt;
}

void CheckDuration(std::size_t n, double dt, const std::string& where) {
  const double dur = static_cast<double>(n) * dt;
  if (dur < kMinRecordS - 1e-9) {
    throw Error(where, fmt::format("only {:.4g} s of data ({} rows at dt_s = {}); a record needs at least {} s", dur,
                                   n, dt, kMinRecordS));
  }
}

}  // namespace

std::string RigRecord::Meta(const std::string& key) const {
  for (const auto& [k, v] : metadata)
    if (k == key) return v;
  return "";
}

RigRecord ReadRigRecord(const std::string& path, TimeAxis time) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(path, "cannot open the rig record");
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw Error(path, "cannot read the rig record");
  return ParseRigRecord(text, path, time);
}

namespace {

/// Where the header block of a rig record ended: its column names and the lines of note.
struct RigHeader {
  std::vector<std::string> cols;
  std::size_t header_line = 0;  ///< the column line
  std::size_t dt_line = 0;      ///< the '# dt_s:' line
};

/// Reads the magic line and the '# key: value' lines up to the column line into rec (dt_s,
/// metadata). *ln: lines read.
RigHeader ReadRigHeader(std::istream& in, const std::string& path, RigRecord* rec, std::size_t* ln) {
  std::string line;
  if (!std::getline(in, line) || Trim(line, kLineWhitespace) != kMagic) {
    throw Error(Where(path, 1), fmt::format("not a rig record: the first line must be \"{}\"", kMagic));
  }
  *ln = 1;
  RigHeader h;
  while (std::getline(in, line)) {
    ++*ln;
    const std::string s(Trim(line, kLineWhitespace));
    if (s.empty()) continue;
    if (s[0] == '#') {
      const auto colon = s.find(':');
      if (colon == std::string::npos) continue;  // a plain comment
      const std::string key(Trim(s.substr(1, colon - 1), kLineWhitespace));
      const std::string value(Trim(s.substr(colon + 1), kLineWhitespace));
      if (key == "dt_s") {
        if (!ParseFinite(value, &rec->dt_s) || !DtInRange(rec->dt_s))
          throw Error(Where(path, *ln), fmt::format("dt_s must be a number in [{:g}, {:g}] s (got \"{}\")", kMinDtS,
                                                   kMaxDtS, value));
        h.dt_line = *ln;
      } else {
        rec->metadata.emplace_back(key, value);
      }
      continue;
    }
    h.cols = SplitCsv(s);
    h.header_line = *ln;
    break;
  }
  if (h.header_line == 0) throw Error(Where(path, *ln), "no column header line (t_s,u_mm,y_mm,f_kN,i_A)");
  if (h.dt_line == 0) throw Error(Where(path, h.header_line), "missing the '# dt_s: <step in s>' line before the columns");
  return h;
}

/// Which vector of rec each known column fills (column index); unknown columns are warned about
/// in rec->warnings; a missing required column throws.
std::vector<std::pair<std::vector<double>*, std::size_t>> ColumnTargets(const RigHeader& h, const std::string& path,
                                                                        RigRecord* rec) {
  static constexpr const char* kColumns = "required: t_s,u_mm,y_mm,f_kN and i_A or v_V (or both); optional r_mm";
  static const std::vector<std::string> kRequired{"t_s", "u_mm", "y_mm", "f_kN"};
  const auto& cols = h.cols;
  std::map<std::string, std::size_t> index;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    if (index.count(cols[c]))
      throw Error(Where(path, h.header_line), fmt::format("column \"{}\" appears twice", cols[c]));
    index[cols[c]] = c;
    const bool known = cols[c] == "r_mm" || cols[c] == "i_A" || cols[c] == "v_V" || std::find(kRequired.begin(), kRequired.end(), cols[c]) != kRequired.end();
    if (!known)
      rec->warnings.push_back(fmt::format("{}: unknown column \"{}\" ignored", Where(path, h.header_line), cols[c]));
  }
  for (const auto& name : kRequired) {
    if (!index.count(name)) {
      throw Error(Where(path, h.header_line),
                  fmt::format("missing column \"{}\" ({})", name, kColumns));
    }
  }
  if (!index.count("i_A") && !index.count("v_V"))
    throw Error(Where(path, h.header_line),
                fmt::format("missing the damper command: a column \"i_A\" (current) or \"v_V\" (voltage) ({})", kColumns));
  std::vector<std::pair<std::vector<double>*, std::size_t>> targets{
      {&rec->t_s, index["t_s"]}, {&rec->u_mm, index["u_mm"]}, {&rec->y_mm, index["y_mm"]},
      {&rec->f_kN, index["f_kN"]}};
  if (index.count("i_A")) targets.emplace_back(&rec->i_A, index["i_A"]);
  if (index.count("r_mm")) targets.emplace_back(&rec->r_mm, index["r_mm"]);
  if (index.count("v_V")) targets.emplace_back(&rec->v_V, index["v_V"]);
  return targets;
}

}  // namespace

RigRecord ParseRigRecord(std::string_view text, const std::string& path, TimeAxis time) {
  std::istringstream in{std::string(text)};
  RigRecord rec;
  rec.source = path;
  std::size_t ln = 0;
  const RigHeader h = ReadRigHeader(in, path, &rec, &ln);
  const auto targets = ColumnTargets(h, path, &rec);

  std::vector<std::size_t> row_line;
  for (std::string line; std::getline(in, line);) {
    ++ln;
    const std::string s(Trim(line, kLineWhitespace));
    if (s.empty() || s[0] == '#') continue;
    const auto f = SplitCsv(s);
    if (f.size() != h.cols.size()) {
      throw Error(Where(path, ln), fmt::format("{} fields, expected {} (one per column of line {})", f.size(),
                                               h.cols.size(), h.header_line));
    }
    for (auto& [vec, c] : targets) {
      double v = 0.0;
      if (!ParseFinite(f[c], &v)) {
        throw Error(Where(path, ln), fmt::format("column {}: \"{}\" is not a finite number", h.cols[c], f[c]));
      }
      if (const auto problem = OutOfBounds(h.cols[c], v); !problem.empty()) throw Error(Where(path, ln), problem);
      vec->push_back(v);
    }
    row_line.push_back(ln);
  }
  const auto line_of = [&](std::size_t k) { return Where(path, row_line[k]); };
  if (time == TimeAxis::kHeader) {
    TimeFromHeader(&rec, line_of);
  } else {
    CheckTime(rec.t_s, rec.dt_s, Where(path, h.dt_line), line_of);
  }
  CheckDuration(rec.size(), rec.dt_s, Where(path, row_line.empty() ? ln : row_line.back()));
  return rec;
}

void ValidateRigRecord(const RigRecord& rec, const std::string& where) {
  const std::size_t n = rec.t_s.size();
  if (rec.u_mm.size() != n || rec.y_mm.size() != n || rec.f_kN.size() != n || !SizesOk(rec))
    throw Error(where, "the record's columns differ in length");
  if (rec.i_A.empty() && rec.v_V.empty()) throw Error(where, "the record has no damper command (i_A or v_V)");
  if (!DtInRange(rec.dt_s))
    throw Error(where, fmt::format("dt_s must be in [{:g}, {:g}] s (got {})", kMinDtS, kMaxDtS, rec.dt_s));
  const std::vector<std::pair<const char*, const std::vector<double>*>> cols{
      {"t_s", &rec.t_s}, {"u_mm", &rec.u_mm}, {"y_mm", &rec.y_mm}, {"f_kN", &rec.f_kN}, {"i_A", &rec.i_A},
      {"r_mm", &rec.r_mm}, {"v_V", &rec.v_V}};
  for (const auto& [name, v] : cols)
    for (std::size_t k = 0; k < v->size(); ++k)
      if (!std::isfinite((*v)[k])) {
        throw Error(fmt::format("{}: sample {}", where, k), fmt::format("{} is not finite", name));
      } else if (const auto problem = OutOfBounds(name, (*v)[k]); !problem.empty()) {
        throw Error(fmt::format("{}: sample {}", where, k), problem);
      }
  CheckTime(rec.t_s, rec.dt_s, where, [&](std::size_t k) { return fmt::format("{}: sample {}", where, k); });
  CheckDuration(n, rec.dt_s, where);
}

void WriteRigRecord(const RigRecord& rec, const std::string& path) {
  const std::size_t n = rec.size();
  if (rec.u_mm.size() != n || rec.y_mm.size() != n || rec.f_kN.size() != n || !SizesOk(rec) ||
      (rec.i_A.empty() && rec.v_V.empty()))
    throw Error(path, "the record's columns differ in length or it has no damper command (i_A or v_V)");
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw Error(path, "cannot write the rig record");
  std::string out = fmt::format("{}\n# dt_s: {}\n", kMagic, rec.dt_s);
  for (const auto& [k, v] : rec.metadata) out += fmt::format("# {}: {}\n", k, v);
  const bool has_i = !rec.i_A.empty();
  out += "t_s,u_mm,y_mm,f_kN";
  out += has_i ? ",i_A" : "";
  out += rec.has_r() ? ",r_mm" : "";
  out += rec.has_v() ? ",v_V\n" : "\n";
  for (std::size_t k = 0; k < n; ++k) {
    out += fmt::format("{:.10g},{:.10g},{:.10g},{:.10g}", rec.t_s[k], rec.u_mm[k], rec.y_mm[k], rec.f_kN[k]);
    if (has_i) out += fmt::format(",{:.10g}", rec.i_A[k]);
    if (rec.has_r()) out += fmt::format(",{:.10g}", rec.r_mm[k]);
    if (rec.has_v()) out += fmt::format(",{:.10g}", rec.v_V[k]);
    out += '\n';
  }
  const bool ok = std::fwrite(out.data(), 1, out.size(), f) == out.size();
  if (std::fclose(f) != 0 || !ok) throw Error(path, "cannot write the rig record");
}

RigRecord RigRecordFromRunLog(const RunLog& log, const std::string& source) {
  RigRecord rec;
  rec.source = source;
  for (const auto& h : log.handshakes)
    if (h.dt_s > 0.0) rec.dt_s = h.dt_s;
  if (!(rec.dt_s > 0.0)) throw Error(source, "the run log has no handshake with the step dt_s");
  const auto n = static_cast<std::size_t>(log.CompleteSteps());
  rec.metadata = {{"source", source + " (LCM run log)"}, {"run_id", std::to_string(log.run_id)}};
  if (!log.Complete()) {
    rec.warnings.push_back(fmt::format("{}: the log is {}: the record holds its {} complete steps", source,
                                       log.TruncationReason(), n));
  }
  for (std::size_t k = 0; k < n; ++k) {
    rec.t_s.push_back(static_cast<double>(k) * rec.dt_s);
    rec.u_mm.push_back(log.command[k].u_mm);
    rec.y_mm.push_back(log.measured[k].y_mm);
    rec.f_kN.push_back(log.measured[k].f_kN);
    rec.i_A.push_back(log.current[k].i_cmd_A);
    rec.r_mm.push_back(log.desired[k].r_mm);
  }
  ValidateRigRecord(rec, source);
  return rec;
}

bool IsLcmLog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[4] = {0, 0, 0, 0};
  if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
  return b[0] == 0xED && b[1] == 0xA1 && b[2] == 0xDA && b[3] == 0x01;
}

RigRecord ReadRecordAny(const std::string& path, TimeAxis time) {
  if (IsLcmLog(path)) return RigRecordFromRunLog(ReadRunLog(path), path);
  return ReadRigRecord(path, time);
}

}  // namespace rths::io
