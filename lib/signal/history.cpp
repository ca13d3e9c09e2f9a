#include "signal/history.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <fstream>
#include <string_view>

#include <fmt/format.h>

#include "core/error.h"
#include "core/text.h"
#include "signal/blwn.h"

namespace rths::signal {
namespace {

struct Row {
  double t = 0.0;      // time [s] (two-column files) or 0
  double value = 0.0;  // value in the file's unit
  int line = 0;        // 1-based line number, for messages
};

std::string Where(const std::string& path, int line) { return fmt::format("{}:{}", path, line); }

double ParseNumber(std::string_view field, const std::string& where) {
  std::string_view digits = field;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() ||
      !std::isfinite(value)) {
    throw Error(where, fmt::format("'{}' is not a finite number", field));
  }
  return value;
}

// Splits one data line into fields: commas separate fields (an empty field between two commas
// or at either end is an error), and so do runs of whitespace.
void SplitFields(std::string_view line, const std::string& where, std::vector<std::string_view>* out) {
  out->clear();
  const bool has_comma = line.find(',') != std::string_view::npos;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = has_comma ? line.find(',', start) : std::string_view::npos;
    const std::string_view piece =
        Trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (has_comma && piece.empty()) {
      throw Error(where, "empty field (two separators in a row, or a separator at an end of the row)");
    }
    std::size_t p = 0;
    while (p < piece.size()) {
      const std::size_t q = piece.find_first_of(" \t\r\v\f", p);
      const std::size_t e = q == std::string_view::npos ? piece.size() : q;
      out->push_back(piece.substr(p, e - p));
      p = piece.find_first_not_of(" \t\r\v\f", e);
      if (p == std::string_view::npos) break;
    }
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

std::vector<Row> ReadRows(const std::string& path, bool has_time) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open the file for reading");
  std::vector<Row> rows;
  std::vector<std::string_view> fields;
  std::string text;
  int line_no = 0;
  const std::size_t columns = has_time ? 2 : 1;
  while (std::getline(in, text)) {
    ++line_no;
    std::string_view line = text;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    if (Trim(line).empty()) continue;
    const std::string where = Where(path, line_no);
    SplitFields(line, where, &fields);
    if (fields.size() != columns) {
      throw Error(where, fmt::format("{} fields; expected {} ({})", fields.size(), columns,
                                     has_time ? "t [s], value: file_dt_s = 0"
                                              : "one value per row: file_dt_s > 0"));
    }
    Row row;
    row.line = line_no;
    if (has_time) {
      row.t = ParseNumber(fields[0], where);
      row.value = ParseNumber(fields[1], where);
    } else {
      row.value = ParseNumber(fields[0], where);
    }
    rows.push_back(row);
  }
  if (in.bad()) throw Error(path, "read error");
  if (rows.empty()) throw Error(path, "no data rows (the file is empty or only has comments)");
  return rows;
}

void CheckTimes(const std::string& path, const std::vector<Row>& rows) {
  if (rows.front().t < 0.0) {
    throw Error(Where(path, rows.front().line),
                fmt::format("time {} s: the time column must start at >= 0", rows.front().t));
  }
  std::vector<double> steps;
  steps.reserve(rows.size());
  for (std::size_t j = 1; j < rows.size(); ++j) {
    if (!(rows[j].t > rows[j - 1].t)) {
      throw Error(Where(path, rows[j].line),
                  fmt::format("time {} s does not increase (previous row: {} s)", rows[j].t, rows[j - 1].t));
    }
    steps.push_back(rows[j].t - rows[j - 1].t);
  }
  if (steps.empty()) return;
  std::vector<double> sorted = steps;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const double median = *mid;
  for (std::size_t j = 0; j < steps.size(); ++j) {
    if (steps[j] > 1.5 * median) {
      throw Error(Where(path, rows[j + 1].line),
                  fmt::format("gap: step of {} s from t = {} s, more than 1.5 x the median step {} s "
                              "(missing rows?)",
                              steps[j], rows[j].t, median));
    }
  }
}

}  // namespace

std::vector<double> LoadHistory(const std::string& path, double file_dt_s, double scale, double dt_s,
                                std::size_t n, double start_s) {
  if (!(file_dt_s >= 0.0) || !std::isfinite(file_dt_s)) {
    throw Error(path, fmt::format("file_dt_s = {}: allowed > 0, or 0 for a file with a time column",
                                  file_dt_s));
  }
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw Error(path, fmt::format("dt_s = {}: allowed > 0", dt_s));
  }
  if (!std::isfinite(scale)) throw Error(path, fmt::format("scale = {}: must be finite", scale));
  if (!(start_s >= 0.0) || !std::isfinite(start_s)) {
    throw Error(path, fmt::format("start_s = {}: allowed >= 0", start_s));
  }
  return ResampleHistory(ReadHistoryFile(path, file_dt_s), file_dt_s, scale, dt_s, n, start_s);
}

HistoryRecord ReadHistoryFile(const std::string& path, double file_dt_s) {
  if (!(file_dt_s >= 0.0) || !std::isfinite(file_dt_s)) {
    throw Error(path, fmt::format("file_dt_s = {}: allowed > 0, or 0 for a file with a time column",
                                  file_dt_s));
  }
  const bool has_time = file_dt_s == 0.0;
  std::vector<Row> rows = ReadRows(path, has_time);
  if (has_time) {
    CheckTimes(path, rows);
  } else {
    for (std::size_t j = 0; j < rows.size(); ++j) rows[j].t = static_cast<double>(j) * file_dt_s;
  }
  HistoryRecord record;
  record.t.reserve(rows.size());
  record.value.reserve(rows.size());
  for (const Row& r : rows) {
    record.t.push_back(r.t);
    record.value.push_back(r.value);
  }
  return record;
}

std::vector<double> ResampleHistory(const HistoryRecord& record, double file_dt_s, double scale, double dt_s,
                                    std::size_t n, double start_s) {
  if (record.t.empty() || record.t.size() != record.value.size()) {
    throw Error("history", "no data rows (the record was not read: ReadHistoryFile)");
  }
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("history", fmt::format("dt_s = {}: allowed > 0", dt_s));
  if (!std::isfinite(scale)) throw Error("history", fmt::format("scale = {}: must be finite", scale));
  if (!(start_s >= 0.0) || !std::isfinite(start_s)) {
    throw Error("history", fmt::format("start_s = {}: allowed >= 0", start_s));
  }
  std::vector<Row> rows(record.t.size());
  for (std::size_t j = 0; j < rows.size(); ++j) rows[j] = Row{record.t[j], record.value[j], 0};
  if (start_s > 0.0) {  // zeros at the file's own step before and after, then the delay
    const double first_step = rows.size() > 1 ? rows[1].t - rows[0].t : file_dt_s;
    const double last_step = rows.size() > 1 ? rows.back().t - rows[rows.size() - 2].t : file_dt_s;
    for (Row& r : rows) r.t += start_s;
    if (first_step > 0.0 && rows.front().t - first_step >= 0.0) rows.insert(rows.begin(), Row{rows.front().t - first_step, 0.0, 0});
    if (last_step > 0.0) rows.push_back(Row{rows.back().t + last_step, 0.0, 0});
  }

  // Linear interpolation on the rows' time axis; zero outside [t_first, t_last]. A tolerance of
  // 1e-9 dt absorbs the rounding of k * dt_s at the record's ends.
  std::vector<double> x(n, 0.0);
  const double tol = 1e-9 * dt_s;
  const double t_first = rows.front().t;
  const double t_last = rows.back().t;
  std::size_t j = 0;  // rows[j].t <= t < rows[j + 1].t
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt_s;
    if (t < t_first - tol) continue;
    if (t > t_last + tol) break;
    if (t >= t_last) {
      x[k] = scale * rows.back().value;
      continue;
    }
    if (t <= t_first) {
      x[k] = scale * rows.front().value;
      continue;
    }
    while (j + 1 < rows.size() && rows[j + 1].t <= t) ++j;
    const Row& a = rows[j];
    const Row& b = rows[j + 1];
    const double w = (t - a.t) / (b.t - a.t);
    x[k] = scale * (a.value + w * (b.value - a.value));
  }
  return x;
}

std::vector<double> MakeSignal(const signal::SignalSpec& spec, double dt_s, std::size_t n) {
  std::vector<double> x;
  switch (spec.kind) {
    case SignalKind::kBlwn:
      x = Blwn(spec.band_hz, spec.rms, dt_s, n, spec.seed, spec.discard_s);
      break;
    case SignalKind::kFile:
      if (spec.record.t.empty()) {
        throw Error(spec.file.empty() ? "signal.file" : spec.file,
                    "not read: a kind = \"file\" signal needs the file's rows (scenario::LoadScenario reads them)");
      }
      x = ResampleHistory(spec.record, spec.file_dt_s, spec.scale, dt_s, n, spec.start_s);
      break;
    case SignalKind::kZero:
      x.assign(n, 0.0);
      break;
  }
  ApplyTaper(spec.taper_s, dt_s, &x);
  return x;
}

void ApplyTaper(double taper_s, double dt_s, std::vector<double>* x) {
  const auto m = static_cast<std::size_t>(std::llround(taper_s / dt_s));
  for (std::size_t i = 0; i < m && i < x->size(); ++i) {
    const double w = 0.5 * (1.0 - std::cos(std::numbers::pi * static_cast<double>(i) / static_cast<double>(m)));
    (*x)[i] *= w;
  }
}

}  // namespace rths::signal
