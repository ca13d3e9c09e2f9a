#include "io/column_record.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "core/text.h"
#include "io/utfsm.h"

namespace rths::io {

namespace {

/// A role: its letter, what it is, its record unit and the units it may be given in.
struct Role {
  char letter;
  const char* what;
  const char* unit;
  std::vector<std::pair<const char*, double>> units;  // name, factor to the record's unit
};

const std::array<Role, 7>& Roles() {
  static const std::array<Role, 7> roles = {{
      {'t', "time", "s", {{"s", 1.0}, {"ms", 1e-3}}},
      {'u', "command", "mm", {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}}},
      {'y', "measured displacement", "mm", {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}}},
      {'f', "force", "kN", {{"kN", 1.0}, {"N", 1e-3}, {"MN", 1e3}, {"lbf", 4.4482216152605e-3}, {"kip", 4.4482216152605}}},
      {'i', "damper current", "A", {{"A", 1.0}, {"mA", 1e-3}}},
      {'v', "damper voltage", "V", {{"V", 1.0}, {"mV", 1e-3}}},
      {'r', "desired displacement", "mm", {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}}},
  }};
  return roles;
}

const Role* RoleOf(std::string_view name) {
  for (const auto& r : Roles())
    if (name.size() == 1 && name[0] == r.letter) return &r;
  return nullptr;
}

std::string RoleList() {
  std::string o;
  for (const auto& r : Roles()) o += fmt::format("{}{} ({})", o.empty() ? "" : ", ", r.letter, r.what);
  return o + ", dt (the step [s] of a file without a time column)";
}

std::string UnitList(const Role& r) {
  std::string o;
  for (const auto& [name, f] : r.units) o += fmt::format("{}{}", o.empty() ? "" : ", ", name);
  return o;
}

bool ParseNumber(std::string_view s, double* v) {
  const std::string text(Trim(s, kLineWhitespace));
  if (text.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(*v);
}

/// A CSV field without its surrounding whitespace and double quotes.
std::string Unquote(std::string_view s) {
  s = Trim(s, kLineWhitespace);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return std::string(s);
}

std::vector<std::string> Split(const std::string& line, char sep) {
  std::vector<std::string> out;
  if (sep == ' ') {  // whitespace-separated
    std::size_t k = 0;
    while (true) {
      k = line.find_first_not_of(" \t\r\n", k);
      if (k == std::string::npos) break;
      const auto e = line.find_first_of(" \t\r\n", k);
      out.push_back(line.substr(k, e == std::string::npos ? std::string::npos : e - k));
      if (e == std::string::npos) break;
      k = e;
    }
    return out;
  }
  std::size_t start = 0;
  while (true) {
    const auto at = line.find(sep, start);
    out.push_back(line.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) break;
    start = at + 1;
  }
  return out;
}

/// The separator a header line uses: ',', ';', a tab, else whitespace (' ').
char SeparatorOf(const std::string& header) {
  for (char c : {',', ';', '\t'})
    if (header.find(c) != std::string::npos) return c;
  return ' ';
}

/// The header line of a CSV: the first line that is not empty or a '#' comment; its 1-based number.
bool FindHeader(std::istream& in, std::string* header, std::size_t* line) {
  for (std::string l; std::getline(in, l);) {
    ++*line;
    const auto t = Trim(l, kLineWhitespace);
    if (t.empty() || t.front() == '#') continue;
    *header = l;
    return true;
  }
  return false;
}

}  // namespace

std::string JoinNames(const std::vector<std::string>& names) {
  std::string o;
  for (const auto& n : names)
    if (!n.empty()) o += fmt::format("{}{}", o.empty() ? "" : ", ", n);
  return o.empty() ? "(none)" : o;
}

const ColumnSource* ColumnMap::Find(char role) const {
  for (const auto& c : columns)
    if (c.role == role) return &c;
  return nullptr;
}

std::string ColumnMap::Describe() const {
  std::string o = dt_s ? fmt::format("dt={}", *dt_s) : "";
  for (const auto& c : columns) {
    o += fmt::format("{}{}={}", o.empty() ? "" : ",", c.role, c.source);
    if (c.scale != 1.0) o += fmt::format("*{}", c.scale);
    if (!c.unit.empty()) o += ":" + c.unit;
  }
  if (current_A) o += fmt::format("{}i={}", o.empty() ? "" : ",", *current_A);
  if (voltage_V) o += fmt::format("{}v={}", o.empty() ? "" : ",", *voltage_V);
  return o;
}

namespace {

/// The entries of a column map: split at the commas outside parentheses (NAME(:,K) has one).
std::vector<std::string> MapEntries(std::string_view text) {
  std::vector<std::string> out(1);
  int depth = 0;
  for (char c : text) {
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth <= 0) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

}  // namespace

ColumnMap ParseColumnMap(std::string_view text, const std::string& where) {
  ColumnMap map;
  for (const std::string& raw : MapEntries(text)) {
    const std::string entry(Trim(raw, kLineWhitespace));
    if (entry.empty()) continue;
    const auto eq = entry.find('=');
    if (eq == std::string::npos)
      throw Error(where, fmt::format("\"{}\": expected ROLE=SOURCE[*SCALE][:UNIT], e.g. y=D:cm (roles: {})", entry,
                                     RoleList()));
    const std::string role_name(Trim(std::string_view(entry).substr(0, eq), kLineWhitespace));
    std::string rest(Trim(std::string_view(entry).substr(eq + 1), kLineWhitespace));
    if (role_name == "dt") {
      double dt = 0.0;
      if (map.dt_s || !ParseNumber(rest, &dt) || !(dt >= kMinDtS && dt <= kMaxDtS))
        throw Error(where, fmt::format("\"{}\": dt=STEP_S once, a step in [{:g}, {:g}] s", entry, kMinDtS, kMaxDtS));
      map.dt_s = dt;
      continue;
    }
    const Role* role = RoleOf(role_name);
    if (role == nullptr) throw Error(where, fmt::format("\"{}\": unknown role \"{}\" (roles: {})", entry, role_name, RoleList()));
    const bool constant_given = (role->letter == 'i' && map.current_A) || (role->letter == 'v' && map.voltage_V);
    if (map.Find(role->letter) != nullptr || constant_given)
      throw Error(where, fmt::format("\"{}\": role {} given twice", entry, role_name));
    ColumnSource c;
    c.role = role->letter;
    const auto close = rest.rfind(')');  // a ':' or '*' inside NAME(:,K) is not a unit or scale
    if (const auto colon = rest.rfind(':'); colon != std::string::npos && (close == std::string::npos || colon > close)) {
      c.unit = std::string(Trim(std::string_view(rest).substr(colon + 1), kLineWhitespace));
      rest = std::string(Trim(std::string_view(rest).substr(0, colon), kLineWhitespace));
    }
    if (const auto star = rest.rfind('*'); star != std::string::npos && (close == std::string::npos || star > close)) {
      if (!ParseNumber(std::string_view(rest).substr(star + 1), &c.scale) || c.scale == 0.0)
        throw Error(where, fmt::format("\"{}\": SCALE after '*' must be a non-zero number", entry));
      rest = std::string(Trim(std::string_view(rest).substr(0, star), kLineWhitespace));
    }
    c.source = Unquote(rest);
    if (c.source.empty()) throw Error(where, fmt::format("\"{}\": no column or variable name", entry));
    double factor = 1.0;
    if (!c.unit.empty()) {
      const auto u = std::find_if(role->units.begin(), role->units.end(),
                                  [&](const auto& p) { return c.unit == p.first; });
      if (u == role->units.end())
        throw Error(where, fmt::format("\"{}\": unit \"{}\" is not one of {} ({}: {})", entry, c.unit, role->what,
                                       role->letter, UnitList(*role)));
      factor = u->second;
    }
    c.to_record = c.scale * factor;
    // i=VALUE, v=VALUE: a constant damper command (a number where a name would be).
    if (double value = 0.0; (c.role == 'i' || c.role == 'v') && ParseNumber(c.source, &value)) {
      value *= c.to_record;
      const double max = c.role == 'i' ? kMaxAbsCurrentA : kMaxAbsVoltageV;
      if (!(value >= 0.0 && value <= max))
        throw Error(where, fmt::format("\"{}\": a constant damper command must be in [0, {:g}] {}", entry, max,
                                       c.role == 'i' ? "A" : "V"));
      (c.role == 'i' ? map.current_A : map.voltage_V) = value;
      continue;
    }
    map.columns.push_back(std::move(c));
  }
  for (char need : {'y', 'f'})
    if (map.Find(need) == nullptr)
      throw Error(where, fmt::format("no {} (the {}): a record needs y and f, and t or dt",
                                     need, need == 'y' ? "measured displacement" : "force"));
  if ((map.Find('t') != nullptr) == map.dt_s.has_value())
    throw Error(where, "give exactly one of t (a time column) and dt=STEP_S (a file without one)");
  return map;
}

RigRecord RecordFromColumns(const ColumnMap& map, const std::string& path, std::vector<std::vector<double>> values) {
  if (values.size() != map.columns.size()) throw Error(path, "internal: one value vector per mapped column");
  const std::size_t n = values.empty() ? 0 : values[0].size();
  RigRecord rec;
  rec.source = path;
  for (std::size_t j = 0; j < values.size(); ++j) {
    const auto& c = map.columns[j];
    if (values[j].size() != n)
      throw Error(path, fmt::format("{} ({}) has {} values, {} ({}) has {}", c.source, c.role, values[j].size(),
                                    map.columns[0].source, map.columns[0].role, n));
    for (double& x : values[j]) x *= c.to_record;
    std::vector<double>* target = nullptr;
    switch (c.role) {
      case 't': target = &rec.t_s; break;
      case 'u': target = &rec.u_mm; break;
      case 'y': target = &rec.y_mm; break;
      case 'f': target = &rec.f_kN; break;
      case 'i': target = &rec.i_A; break;
      case 'v': target = &rec.v_V; break;
      default: target = &rec.r_mm; break;
    }
    *target = std::move(values[j]);
  }
  if (map.dt_s) {
    rec.dt_s = *map.dt_s;
    rec.t_s.resize(n);
    for (std::size_t k = 0; k < n; ++k) rec.t_s[k] = static_cast<double>(k) * rec.dt_s;
  } else if (n >= 2) {
    // dt is the column's mean step; a column rounded coarser than its step (3004.8 Hz written to
    // 0.1 ms) still lies within half a step of t_0 + k dt when no row is missing: take that grid.
    const double t0 = rec.t_s.front();
    rec.dt_s = (rec.t_s.back() - t0) / static_cast<double>(n - 1);
    double dev = 0.0;
    for (std::size_t k = 0; k < n; ++k) dev = std::max(dev, std::abs(rec.t_s[k] - (t0 + static_cast<double>(k) * rec.dt_s)));
    if (dev > 0.5 * rec.dt_s) {  // a row missing: a step of 1.5 mean steps or more
      for (std::size_t k = 1; k < n; ++k)
        if (rec.t_s[k] - rec.t_s[k - 1] > 1.5 * rec.dt_s)
          throw Error(fmt::format("{}: sample {}", path, k),
                      fmt::format("gap in time: t jumps from {} to {} s ({:.3g} mean steps of {:.6g} s; missing rows?)",
                                  rec.t_s[k - 1], rec.t_s[k], (rec.t_s[k] - rec.t_s[k - 1]) / rec.dt_s, rec.dt_s));
    } else if (std::is_sorted(rec.t_s.begin(), rec.t_s.end())) {
      if (dev > 0.01 * rec.dt_s)
        rec.warnings.push_back(fmt::format("{}: the time column deviates from t_0 + k dt (dt = its mean step, {:.9g} s, "
                                           "{:.6g} Hz) by up to {:.3g} s ({:.2f} steps; rounded?): time taken as "
                                           "t_0 + k dt",
                                           path, rec.dt_s, 1.0 / rec.dt_s, dev, dev / rec.dt_s));
      for (std::size_t k = 0; k < n; ++k) rec.t_s[k] = t0 + static_cast<double>(k) * rec.dt_s;
    }
  }
  if (rec.u_mm.empty()) {
    rec.u_mm = rec.y_mm;
    rec.warnings.push_back(fmt::format("{}: no command column (u): u = y, as for a damper test", path));
  }
  if (map.current_A) rec.i_A.assign(n, *map.current_A);
  if (map.voltage_V) rec.v_V.assign(n, *map.voltage_V);
  if (rec.i_A.empty() && rec.v_V.empty()) {
    rec.i_A.assign(n, 0.0);
    rec.warnings.push_back(fmt::format("{}: no damper command (i or v): i = 0 A (a constant one: i=VALUE in the map, "
                                       "or --current)", path));
  }
  rec.metadata.emplace_back("source", path);
  rec.metadata.emplace_back("columns", map.Describe());
  ValidateRigRecord(rec, path);
  return rec;
}

std::vector<std::string> CsvColumnNames(const std::string& path) {
  std::ifstream in(path);
  std::string header;
  std::size_t line = 0;
  if (!in || !FindHeader(in, &header, &line)) return {};
  std::vector<std::string> names;
  for (const auto& f : Split(header, SeparatorOf(header))) names.push_back(Unquote(f));
  return names;
}

RigRecord ReadColumnsCsv(const std::string& path, const ColumnMap& map) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open");
  std::string header;
  std::size_t line = 0;
  if (!FindHeader(in, &header, &line)) throw Error(path, "no header line of column names");
  const char sep = SeparatorOf(header);
  std::vector<std::string> names;
  for (const auto& f : Split(header, sep)) names.push_back(Unquote(f));
  std::vector<std::size_t> index;  // per mapped column, its field
  for (const auto& c : map.columns) {
    const auto it = std::find(names.begin(), names.end(), c.source);
    if (it == names.end())
      throw Error(fmt::format("{}:{}", path, line),
                  fmt::format("no column \"{}\" (for {}); the file's columns: {}", c.source, c.role, JoinNames(names)));
    index.push_back(static_cast<std::size_t>(it - names.begin()));
  }
  const std::size_t need = index.empty() ? 0 : *std::max_element(index.begin(), index.end()) + 1;
  std::vector<std::vector<double>> values(map.columns.size());
  for (std::string l; std::getline(in, l);) {
    ++line;
    const auto t = Trim(l, kLineWhitespace);
    if (t.empty() || t.front() == '#') continue;
    const auto fields = Split(l, sep);
    if (fields.size() < need)
      throw Error(fmt::format("{}:{}", path, line),
                  fmt::format("{} fields, the mapped columns need {} (up to \"{}\")", fields.size(), need, names[need - 1]));
    for (std::size_t j = 0; j < index.size(); ++j) {
      double v = 0.0;
      if (!ParseNumber(Unquote(fields[index[j]]), &v))
        throw Error(fmt::format("{}:{}", path, line),
                    fmt::format("column \"{}\": \"{}\" is not a finite number", map.columns[j].source,
                                Unquote(fields[index[j]])));
      values[j].push_back(v);
    }
  }
  return RecordFromColumns(map, path, std::move(values));
}

RigRecord ReadAnyRecord(const std::string& path, const ColumnMap* map, TimeAxis time) {
  if (IsMatFile(path)) return ReadMatRecord(path, map);
  // Our own formats are read as they are, map or not (a map names the columns of the other files).
  if (IsLcmLog(path)) return ReadRecordAny(path, time);
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open");
  std::string first;
  std::getline(in, first);
  const auto t = Trim(first, kLineWhitespace);
  if (t.rfind("# rths rig record", 0) == 0 || t.rfind("Header Size", 0) == 0) return ReadRecordOrUtfsm(path, time);
  // A UTFSM damper file starts with a row of numbers: it has no header for a map to name, and is
  // read by its own format, map or not (a map given for a lab's .mat beside it does not apply).
  const auto fields = Split(first, SeparatorOf(first));
  const bool numeric = !fields.empty() && std::all_of(fields.begin(), fields.end(), [](const std::string& f) {
    double v = 0.0;
    return Unquote(f).empty() || ParseNumber(Unquote(f), &v);
  });
  if (numeric) return ReadRecordOrUtfsm(path, time);
  if (map != nullptr) return ReadColumnsCsv(path, *map);
  throw Error(path, fmt::format("not a rig record of ours (its first line is not \"# rths rig record v1\"): for a CSV "
                                "with named columns give --columns ROLE=COLUMN[*SCALE][:UNIT],... (roles t, u, y, f, "
                                "i, v, r; e.g. --columns t=t,y=D:cm,f=F:N,v=Y:V); this file's columns: {} "
                                "(docs/rig_record.md \"Other formats\")",
                                JoinNames(CsvColumnNames(path))));
}

}  // namespace rths::io
