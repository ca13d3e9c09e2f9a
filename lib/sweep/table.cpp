#include "sweep/table.h"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <fmt/core.h>

#include "core/error.h"
#include "io/plot.h"
#include "io/reserved_file.h"

namespace rths::sweep {

namespace fs = std::filesystem;

namespace {

/// A value as text: a string itself, a float the shortest text that reads back bit for bit, else
/// its JSON ("" for null).
std::string Text(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_number_float()) return fmt::format("{}", v.get<double>());
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::string Cell(const nlohmann::json& v) {
  std::string s = Text(v);
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

/// How a column is stored in HDF5.
enum class Kind { kInt, kFloat, kText };

Kind KindOf(const Table& t, std::size_t c) {
  bool any_null = false, all_int = true, all_num = true;
  for (const auto& row : t.rows) {
    const nlohmann::json& v = row[c];
    if (v.is_null()) {
      any_null = true;
      continue;
    }
    const bool num = v.is_number() || v.is_boolean();
    all_num = all_num && num;
    all_int = all_int && (v.is_number_integer() || v.is_boolean());
  }
  if (!all_num) return Kind::kText;
  return all_int && !any_null ? Kind::kInt : Kind::kFloat;
}

double AsDouble(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? 1.0 : 0.0;
  if (v.is_number()) return v.get<double>();
  return std::numeric_limits<double>::quiet_NaN();
}

/// Closes an HDF5 handle at scope exit.
struct H5Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  ~H5Handle() {
    if (id >= 0) close(id);
  }
};

void Check(bool ok, const fs::path& file, const std::string& what) {
  if (!ok) throw Error(file.string(), fmt::format("HDF5 could not {}", what));
}

/// A variable-length UTF-8 string type.
hid_t TextType() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

void WriteStrings(hid_t where, const std::string& name, const std::vector<std::string>& values, bool attribute,
                  const fs::path& file) {
  std::vector<const char*> ptrs;
  for (const std::string& s : values) ptrs.push_back(s.c_str());
  const hsize_t n = values.size();
  H5Handle space{H5Screate_simple(1, &n, nullptr), H5Sclose};
  H5Handle type{TextType(), H5Tclose};
  if (attribute) {
    H5Handle a{H5Acreate2(where, name.c_str(), type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
    Check(a.id >= 0 && H5Awrite(a.id, type.id, ptrs.data()) >= 0, file, "write attribute " + name);
    return;
  }
  H5Handle d{H5Dcreate2(where, name.c_str(), type.id, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose};
  Check(d.id >= 0 && H5Dwrite(d.id, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) >= 0, file,
        "write column " + name);
}

template <typename T>
void WriteNumbers(hid_t group, const std::string& name, const std::vector<T>& values, hid_t file_type, hid_t mem_type,
                  const fs::path& file) {
  const hsize_t n = values.size();
  H5Handle space{H5Screate_simple(1, &n, nullptr), H5Sclose};
  H5Handle d{H5Dcreate2(group, name.c_str(), file_type, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose};
  Check(d.id >= 0 && H5Dwrite(d.id, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0, file,
        "write column " + name);
}

/// The columns that hold a recorded field with at least one number (the summary's and plots' fields).
std::vector<std::size_t> NumericFields(const Spec& spec, const Table& t) {
  std::vector<std::size_t> out;
  const std::size_t first = t.columns.size() - spec.record.size();
  for (std::size_t c = first; c < t.columns.size(); ++c) {
    const bool any = std::any_of(t.rows.begin(), t.rows.end(), [&](const auto& r) { return r[c].is_number(); });
    if (any && KindOf(t, c) != Kind::kText) out.push_back(c);
  }
  return out;
}

bool Completed(const std::vector<nlohmann::json>& row) { return row[1] == "completed"; }

/// The first grid or drawn column: after index, status, scenario_sha256 and, with cases, case.
std::size_t FirstSetColumn(const Spec& spec) { return spec.cases.size() > 1 ? 4 : 3; }

/// Each case's name in the table: its file name, or, where two cases share a file name, its path
/// relative to the SPEC's folder.
std::vector<std::string> CaseNames(const Spec& spec) {
  std::vector<std::string> names;
  for (const std::string& c : spec.cases) names.push_back(fs::path(c).filename().string());
  std::vector<std::string> sorted = names;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) return names;
  names.clear();
  for (const std::string& c : spec.cases) {
    names.push_back(fs::path(c).lexically_relative(fs::path(spec.path).parent_path()).string());
  }
  return names;
}

}  // namespace

std::vector<std::string> TableColumns(const Spec& spec) {
  std::vector<std::string> c = {"index", "status", "scenario_sha256"};
  if (spec.cases.size() > 1) c.push_back("case");
  for (const Axis& a : spec.grid) c.push_back(a.key);
  for (const Draw& d : spec.draw) {
    for (const std::string& k : DrawColumns(d)) c.push_back(k);
  }
  for (const std::string& f : spec.record) {  // "status" is the sweep's: summary.json's becomes "summary.status"
    c.push_back(std::find(c.begin(), c.end(), f) == c.end() ? f : "summary." + f);
  }
  return c;
}

std::vector<std::string> AbsentFields(const Spec& spec, const Table& t) {
  std::vector<std::string> absent;
  const std::size_t first = t.columns.size() - spec.record.size();
  for (std::size_t f = 0; f < spec.record.size(); ++f) {
    bool any_completed = false, any_value = false;
    for (const auto& row : t.rows) {
      if (!Completed(row)) continue;
      any_completed = true;
      any_value = any_value || !row[first + f].is_null();
    }
    if (any_completed && !any_value) absent.push_back(spec.record[f]);
  }
  return absent;
}

fs::path RowFile(const fs::path& out, std::int64_t i) { return out / "rows" / fmt::format("{}.json", i); }

nlohmann::json ReadJsonFile(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nullptr;
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return nullptr;
  }
}

Table ReadTable(const Spec& spec, const fs::path& out) {
  const std::vector<std::string> cases = CaseNames(spec);
  Table t;
  t.columns = TableColumns(spec);
  const std::int64_t per_draw = std::max<std::int64_t>(spec.draws, 1);
  for (std::int64_t i = 0; i < spec.runs(); ++i) {
    const nlohmann::json row = ReadJsonFile(RowFile(out, i));
    if (!row.is_object()) continue;
    std::vector<nlohmann::json> cells = {row.value("index", i), row.value("status", std::string()),
                                         row.value("scenario_sha256", std::string())};
    if (spec.cases.size() > 1) cells.push_back(cases[static_cast<std::size_t>(PointOf(spec, i).case_index)]);
    const nlohmann::json set = row.value("set", nlohmann::json::object());
    const nlohmann::json record = row.value("record", nlohmann::json::object());
    for (const Axis& a : spec.grid) cells.push_back(set.value(a.key, nlohmann::json()));
    for (const Draw& d : spec.draw) {
      for (const std::string& k : DrawColumns(d)) cells.push_back(set.value(k, nlohmann::json()));
    }
    for (const std::string& f : spec.record) cells.push_back(record.value(f, nlohmann::json()));
    t.rows.push_back(std::move(cells));
    t.group.push_back(i / per_draw);
  }
  return t;
}

void WriteCsv(const Table& t, const fs::path& file) {
  std::ostringstream csv;
  for (std::size_t c = 0; c < t.columns.size(); ++c) csv << (c ? "," : "") << t.columns[c];
  csv << "\n";
  for (const auto& row : t.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) csv << (c ? "," : "") << Cell(row[c]);
    csv << "\n";
  }
  if (!io::OverwriteFile(file.string(), csv.str())) throw Error(file.string(), "cannot write the sweep's table");
}

void WriteHdf5(const Spec& spec, const Table& t, const fs::path& file) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become exceptions, not prints
  const fs::path tmp = file.string() + ".partial";
  {
    H5Handle f{H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
    Check(f.id >= 0, tmp, "create the file");
    WriteStrings(f.id, "sweep", {spec.name}, true, file);
    WriteStrings(f.id, "spec", {spec.path}, true, file);
    H5Handle g{H5Gcreate2(f.id, "runs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    Check(g.id >= 0, file, "create the group /runs");
    WriteStrings(g.id, "columns", t.columns, true, file);
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
      const Kind kind = KindOf(t, c);
      if (kind == Kind::kInt) {
        std::vector<std::int64_t> v;
        for (const auto& row : t.rows) v.push_back(row[c].is_boolean() ? row[c].get<bool>() : row[c].get<std::int64_t>());
        WriteNumbers(g.id, t.columns[c], v, H5T_STD_I64LE, H5T_NATIVE_INT64, file);
      } else if (kind == Kind::kFloat) {
        std::vector<double> v;
        for (const auto& row : t.rows) v.push_back(AsDouble(row[c]));
        WriteNumbers(g.id, t.columns[c], v, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, file);
      } else {
        std::vector<std::string> v;
        for (const auto& row : t.rows) v.push_back(row[c].is_string() ? row[c].get<std::string>() : Cell(row[c]));
        WriteStrings(g.id, t.columns[c], v, false, file);
      }
    }
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) throw Error(file.string(), "cannot write the sweep's HDF5 table: " + ec.message());
}

void WriteGroupSummary(const Spec& spec, const Table& t, const fs::path& file) {
  const std::vector<std::string> cases = CaseNames(spec);
  std::ostringstream csv;
  csv << "case";
  for (const Axis& a : spec.grid) csv << "," << a.key;
  csv << ",field,runs,failures,n,mean,std,min,max\n";
  const auto fields = NumericFields(spec, t);
  std::map<std::int64_t, std::vector<std::size_t>> groups;  // group -> rows
  for (std::size_t r = 0; r < t.rows.size(); ++r) groups[t.group[r]].push_back(r);
  for (const auto& [group, rows] : groups) {
    const auto& first = t.rows[rows.front()];
    const RunPoint p = PointOf(spec, first[0].get<std::int64_t>());
    std::string key = Cell(cases[static_cast<std::size_t>(p.case_index)]);
    for (std::size_t a = 0; a < spec.grid.size(); ++a) key += "," + Cell(first[FirstSetColumn(spec) + a]);
    std::int64_t failures = 0;
    for (const std::size_t r : rows) failures += !Completed(t.rows[r]);
    for (const std::size_t c : fields) {
      std::vector<double> v;
      for (const std::size_t r : rows) {
        const double x = AsDouble(t.rows[r][c]);
        if (Completed(t.rows[r]) && std::isfinite(x)) v.push_back(x);
      }
      // Not signal::SpreadOf: its mean, sum / n, can differ from this sum of x / n in the last
      // bit, and the summary prints the shortest exact form; the files keep their numbers.
      double mean = 0, var = 0;
      for (const double x : v) mean += x / static_cast<double>(v.size());
      for (const double x : v) var += (x - mean) * (x - mean);
      // The sample standard deviation (n - 1) of one run is undefined: an empty cell, not 0.
      const std::string sd = v.size() > 1 ? fmt::format("{}", std::sqrt(var / static_cast<double>(v.size() - 1))) : "";
      const auto [lo, hi] = v.empty() ? std::pair(0.0, 0.0) : std::pair(*std::min_element(v.begin(), v.end()),
                                                                         *std::max_element(v.begin(), v.end()));
      if (v.empty()) {
        csv << fmt::format("{},{},{},{},0,,,,\n", key, Cell(t.columns[c]), rows.size(), failures);
      } else {
        csv << fmt::format("{},{},{},{},{},{},{},{},{}\n", key, Cell(t.columns[c]), rows.size(),
                           failures, v.size(), mean, sd, lo, hi);
      }
    }
  }
  if (!io::OverwriteFile(file.string(), csv.str())) throw Error(file.string(), "cannot write the sweep's summary");
}

namespace {

/// A plot axis: its name and each row's value as text.
struct AxisColumn {
  std::string name;
  std::vector<std::string> labels;  ///< per row
  bool drawn = false;               ///< a [draw] key: a value per run, not levels shared by runs
};

/// The axes: the case (when there are several), each grid key, each drawn key (not seeds).
std::vector<AxisColumn> PlotAxes(const Spec& spec, const Table& t) {
  std::vector<AxisColumn> axes;
  if (spec.cases.size() > 1) {
    // The cases' file names without what they all end with ("case1_example.toml" ... -> "case1"),
    // so that the labels fit under their ticks.
    const std::vector<std::string> names = CaseNames(spec);
    auto back = [](const std::string& n, std::size_t k) { return k < n.size() ? n[n.size() - 1 - k] : '\0'; };
    std::size_t common = 0;  // the length of the names' common ending, leaving each one character
    while (std::all_of(names.begin(), names.end(), [&](const std::string& n) {
      return common + 1 < n.size() && back(n, common) == back(names[0], common);
    })) {
      ++common;
    }
    AxisColumn a{"case", {}};
    for (const auto& row : t.rows) {
      const std::string name = row[3].get<std::string>();
      a.labels.push_back(name.substr(0, name.size() - common));
    }
    axes.push_back(std::move(a));
  }
  std::size_t column = FirstSetColumn(spec);  // the grid's and the draws' columns
  for (const Axis& g : spec.grid) {
    AxisColumn a{g.key, {}};
    for (const auto& row : t.rows) a.labels.push_back(Text(row[column]));
    axes.push_back(std::move(a));
    ++column;
  }
  for (const Draw& d : spec.draw) {
    for (const std::string& key : DrawColumns(d)) {
      if (d.dist != "seed") {  // a seed is no axis
        AxisColumn a{key, {}, true};
        for (const auto& row : t.rows) a.labels.push_back(Text(row[column]));
        axes.push_back(std::move(a));
      }
      ++column;
    }
  }
  return axes;
}

/// The axis whose levels split the panel of axes[a] into curves: the first other axis that is the
/// case or a grid key (levels shared by many runs); nullptr if there is none.
const AxisColumn* SplitAxis(const std::vector<AxisColumn>& axes, std::size_t a) {
  for (std::size_t b = 0; b < axes.size(); ++b) {
    if (b != a && !axes[b].drawn) return &axes[b];
  }
  return nullptr;
}

/// Each row's x on axis `a`: numeric values at their value; text values (a case, a controller)
/// at 0, 1, 2, ... in order of first appearance, labelled on the panel's x tics.
std::vector<double> XPositions(const AxisColumn& a, io::Panel* p) {
  bool numeric = true;
  for (const std::string& l : a.labels) {
    char* end = nullptr;
    std::strtod(l.c_str(), &end);
    numeric = numeric && !l.empty() && end && *end == '\0';
  }
  std::vector<double> x;
  std::map<std::string, double> category;
  for (const std::string& l : a.labels) {
    if (numeric) {
      x.push_back(std::strtod(l.c_str(), nullptr));
      continue;
    }
    auto [it, fresh] = category.emplace(l, static_cast<double>(category.size()));
    if (fresh) p->x_tics.emplace_back(it->second, l);
    x.push_back(it->second);
  }
  if (!numeric) p->x_range = std::pair(-0.5, static_cast<double>(category.size()) - 0.5);
  return x;
}

/// Keeps the x tick labels of a panel `width_chars` characters wide (its plot area, about) from
/// running into each other: category names are slanted when they do not fit side by side; numeric
/// ticks are thinned to as many labels as fit (NiceTicStep's steps, each label's length measured
/// as gnuplot writes it).
void FitXTicks(io::Panel* p, const std::vector<double>& x, int width_chars) {
  if (!p->x_tics.empty()) {
    std::size_t chars = 0;
    for (const auto& [at, label] : p->x_tics) chars += label.size() + 2;
    p->rotate_x_tics = static_cast<int>(chars) > width_chars;
    return;
  }
  double lo = INFINITY, hi = -INFINITY;
  for (const double v : x) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  for (int n = 8; n >= 2; --n) {
    const double step = io::NiceTicStep(lo, hi, n);
    if (step <= 0) return;
    std::size_t longest = 1;
    for (double t = std::ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) {
      longest = std::max(longest, fmt::format("{:.6g}", std::abs(t) < step * 1e-9 ? 0.0 : t).size());
    }
    if (static_cast<int>((n + 1) * (longest + 2)) <= width_chars || n == 2) {
      p->max_x_tics = n;
      return;
    }
  }
}

/// Column c of the completed rows against axis axes[a], a curve per level of the other factor
/// (SplitAxis; one curve without one), with space between the points and the frame. Against a
/// case or grid key, each curve is a line through the mean of its runs at each x, its runs as
/// small open points where an x has several (draws); against a drawn key, points only.
io::Panel PlotPanel(const Table& t, std::size_t c, const std::vector<AxisColumn>& axes, std::size_t a) {
  const AxisColumn& axis = axes[a];
  io::Panel p = io::MakePanel("", axis.name, t.columns[c]);
  p.margin_fraction = 0.05;
  const std::vector<double> x = XPositions(axis, &p);
  const AxisColumn* split = SplitAxis(axes, a);
  std::vector<std::string> levels;  // of `split`, in order of first appearance among completed rows
  std::vector<std::size_t> level_of(t.rows.size(), 0);
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (!Completed(t.rows[r]) || split == nullptr) continue;
    const auto it = std::find(levels.begin(), levels.end(), split->labels[r]);
    level_of[r] = static_cast<std::size_t>(it - levels.begin());
    if (it == levels.end()) levels.push_back(split->labels[r]);
  }
  // Levels with no completed run, said in the title: of `split` (no curve), or, with no split, of
  // this axis itself (an empty tick).
  const AxisColumn* of = split != nullptr ? split : (axis.drawn ? nullptr : &axis);
  std::vector<std::string> lost, done;
  for (std::size_t r = 0; of != nullptr && r < t.rows.size(); ++r)
    if (Completed(t.rows[r])) done.push_back(of->labels[r]);
  for (std::size_t r = 0; of != nullptr && r < t.rows.size(); ++r) {
    const std::string& l = of->labels[r];
    if (std::find(done.begin(), done.end(), l) == done.end() && std::find(lost.begin(), lost.end(), l) == lost.end())
      lost.push_back(l);
  }
  if (levels.empty()) levels.push_back("");
  if (split != nullptr) p.title = (axis.drawn ? "coloured by " : "a curve per ") + split->name;
  for (std::size_t i = 0; i < lost.size(); ++i) p.title += (i ? ", " : (p.title.empty() ? "no completed run: " : "; no completed run: ")) + lost[i];
  p.key = split != nullptr ? "outside right top" : "off";  // short entries (the levels): a narrow column
  const auto& palette = io::ReadableColors();
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const std::string color = palette[l % palette.size()];
    io::Series runs = io::MakeSeries("", color);
    std::map<double, std::vector<double>> at_x;  // finite values per x, for the means
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
      if (!Completed(t.rows[r]) || level_of[r] != l) continue;
      const double y = AsDouble(t.rows[r][c]);
      runs.x.push_back(x[r]);
      runs.y.push_back(y);
      if (std::isfinite(y)) at_x[x[r]].push_back(y);
    }
    if (axis.drawn) {  // a value per run: a scatter, coloured by the level
      runs.title = levels[l];
      runs.with = "points pt 7 ps 0.8";
      p.series.push_back(std::move(runs));
      continue;
    }
    io::Series mean = io::MakeSeries(levels[l], color);
    mean.with = "linespoints pt 7 ps 1.2";
    bool repeated = false;
    for (const auto& [xv, ys] : at_x) {
      double sum = 0;
      for (const double y : ys) sum += y;
      mean.x.push_back(xv);
      mean.y.push_back(sum / static_cast<double>(ys.size()));
      repeated = repeated || ys.size() > 1;
    }
    if (repeated) {
      runs.with = "points pt 6 ps 0.7";
      p.series.push_back(std::move(runs));
    }
    p.series.push_back(std::move(mean));
  }
  if (split != nullptr) p.right_margin_chars = io::KeyMarginChars({&p});
  // The panel's plot area in characters: its share of the figure (io::Figure's 1000 px, about 7.5 px
  // a character at its font, measured on its PNGs: 7.2) less the y axis's labels and the key's column.
  const int panel_chars = static_cast<int>((io::Figure{}.width_px / (axes.size() > 1 ? 2 : 1)) / 7.5);
  FitXTicks(&p, x, panel_chars - 10 - std::max(p.right_margin_chars, 2));
  return p;
}

}  // namespace

std::vector<fs::path> WritePlots(const Spec& spec, const Table& t, const fs::path& dir) {
  std::vector<fs::path> pngs;
  if (!io::GnuplotAvailable("gnuplot")) return pngs;
  const std::vector<AxisColumn> axes = PlotAxes(spec, t);
  for (const std::size_t c : NumericFields(spec, t)) {
    io::Figure fig;
    fig.name = t.columns[c];
    for (char& ch : fig.name) {
      if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_' && ch != '.') ch = '_';
    }
    // Lines only against a case or grid axis; against a drawn key the runs are points.
    const bool lines = std::any_of(axes.begin(), axes.end(), [](const AxisColumn& a) { return !a.drawn; });
    fig.title = fmt::format("{}: {} against each axis (completed runs{})", spec.name, t.columns[c],
                            lines ? "; lines through the mean of a point's runs" : "");
    fig.columns = axes.size() > 1 ? 2 : 1;
    for (std::size_t a = 0; a < axes.size(); ++a) fig.panels.push_back(PlotPanel(t, c, axes, a));
    const bool drawable = std::all_of(fig.panels.begin(), fig.panels.end(), [](const io::Panel& p) {
      return std::any_of(p.series.begin(), p.series.end(), [](const io::Series& s) {
        return std::any_of(s.y.begin(), s.y.end(), [](double y) { return std::isfinite(y); });
      });
    });
    if (fig.panels.empty() || !drawable) continue;
    pngs.push_back(io::Plot(fig, dir).png);
  }
  return pngs;
}

}  // namespace rths::sweep
