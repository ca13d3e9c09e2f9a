#include "io/utfsm.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "core/text.h"

namespace rths::io {

namespace {

bool ParseFinite(const std::string& s, double* v) {
  const std::string t(Trim(s, kLineWhitespace));
  if (t.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size() && std::isfinite(*v);
}

std::string Where(const std::string& path, std::size_t line) { return fmt::format("{}:{}", path, line); }

/// Throws "path:line: <what> = v is out of range [-bound, bound] unit" if |v| > bound (the rig
/// record's bounds, io/rig_record.h), so an absurd sample is named by its line, not its index.
void CheckBound(const std::string& path, std::size_t line, const char* what, double v, double bound, const char* unit) {
  if (std::abs(v) <= bound) return;
  throw Error(Where(path, line), fmt::format("{} = {} is out of range [-{:g}, {:g}] {} (a rig record's bound: an "
                                             "absurd value?)",
                                             what, v, bound, bound, unit));
}

double Mean(const std::vector<double>& v, std::size_t a, std::size_t b) {
  double s = 0.0;
  for (std::size_t k = a; k < b; ++k) s += v[k];
  return s / static_cast<double>(b - a);
}

/// The DAQ export's header: "Header Size: H" first, H lines in all, the last naming the columns.
/// Returns the sampling interval [s]; *ln is the number of lines read.
double ReadUtfsmHeader(std::istream& in, const std::string& path, std::size_t* ln) {
  std::string line;
  if (!std::getline(in, line)) throw Error(Where(path, 1), "empty file");
  *ln = 1;
  const auto colon = line.find(':');
  double hsize = 0.0;
  if (colon == std::string::npos || Trim(line.substr(0, colon), kLineWhitespace) != "Header Size" ||
      !ParseFinite(line.substr(colon + 1), &hsize) || hsize < 1 || hsize > 10000 || hsize != std::floor(hsize))
    throw Error(Where(path, 1), "not a DAQ export: the first line must be 'Header Size: <lines>' (1 to 10000)");
  double dt = 0.0;
  std::string columns;
  while (*ln < static_cast<std::size_t>(hsize) && std::getline(in, line)) {
    ++*ln;
    const auto c = line.find(':');
    if (c != std::string::npos && Trim(line.substr(0, c), kLineWhitespace) == "Sampling Interval" &&
        (!ParseFinite(line.substr(c + 1), &dt) || dt < kMinDtS || dt > kMaxDtS))
      throw Error(Where(path, *ln), fmt::format("bad Sampling Interval (a number of seconds in [{:g}, {:g}])", kMinDtS,
                                                kMaxDtS));
    columns = line;
  }
  if (!(dt > 0.0)) throw Error(Where(path, *ln), "no 'Sampling Interval' in the header");
  if (columns.find("CHANNEL0") == std::string::npos || columns.find("CHANNEL2") == std::string::npos) {
    throw Error(Where(path, *ln), "expected the header's last line to name the columns 'Sample Number, Date/Time, "
                                  "CHANNEL0, CHANNEL1, CHANNEL2'");
  }
  return dt;
}

/// The export's samples, converted: y [mm] = 10 CHANNEL0, f [kN] = 9.80665 CHANNEL1 (9806.65 N/V),
/// u [mm] = 10 CHANNEL2, each checked against the rig record's bounds.
struct UtfsmSamples {
  std::vector<double> y_mm, f_kN, u_mm;
};

UtfsmSamples ReadUtfsmRows(std::istream& in, const std::string& path, std::size_t ln) {
  UtfsmSamples s;
  std::string line;
  while (std::getline(in, line)) {
    ++ln;
    if (Trim(line, kLineWhitespace).empty()) continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) fields.push_back(field);
    double c0 = 0, c1 = 0, c2 = 0;
    if (fields.size() < 5 || !ParseFinite(fields[2], &c0) || !ParseFinite(fields[3], &c1) ||
        !ParseFinite(fields[4], &c2))
      throw Error(Where(path, ln), "expected 'sample, date/time, CHANNEL0, CHANNEL1, CHANNEL2' with numbers");
    s.y_mm.push_back(10.0 * c0);
    s.f_kN.push_back(9.80665 * c1);
    s.u_mm.push_back(10.0 * c2);
    CheckBound(path, ln, "y_mm (10 CHANNEL0)", s.y_mm.back(), kMaxAbsDisplacementMm, "mm");
    CheckBound(path, ln, "f_kN (9.80665 CHANNEL1)", s.f_kN.back(), kMaxAbsForceKN, "kN");
    CheckBound(path, ln, "u_mm (10 CHANNEL2)", s.u_mm.back(), kMaxAbsDisplacementMm, "mm");
  }
  if (s.u_mm.empty()) throw Error(path, "no data rows");
  return s;
}

/// The samples [start, end) from the first to the last with |u - u0| > threshold; start = u.size()
/// if there is none.
std::pair<std::size_t, std::size_t> ChirpSpan(const std::vector<double>& u, double u0, double threshold_mm) {
  std::size_t start = u.size(), end = 0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (std::abs(u[k] - u0) > threshold_mm) {
      start = std::min(start, k);
      end = k + 1;
    }
  }
  return {start, end};
}

}  // namespace

RigRecord ReadUtfsmActuator(const std::string& path, const UtfsmActuatorOptions& o) {
  if (!(o.start_threshold_mm > 0.0)) throw Error(path, "start_threshold_mm must be > 0");
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open the DAQ export");
  std::size_t ln = 0;
  const double dt = ReadUtfsmHeader(in, path, &ln);
  const UtfsmSamples x = ReadUtfsmRows(in, path, ln);
  const std::vector<double>&u = x.u_mm, &y = x.y_mm, &f = x.f_kN;

  // Chirp start/end on u relative to a first idle estimate (the first 0.5 s), then the idle
  // stretch proper and its means, then start and end again with the final offset.
  const auto n0 = std::min<std::size_t>(u.size(), std::max<std::size_t>(1, static_cast<std::size_t>(0.5 / dt)));
  auto [start, end] = ChirpSpan(u, Mean(u, 0, n0), o.start_threshold_mm);
  if (start == u.size()) throw Error(path, fmt::format("|u| never exceeds {} mm: no chirp found", o.start_threshold_mm));
  const auto one_s = static_cast<std::size_t>(std::lround(1.0 / dt));
  std::size_t idle_end = start > one_s ? start - one_s : 0;
  if (static_cast<double>(idle_end) * dt < 0.5) idle_end = start / 2;
  if (idle_end == 0) throw Error(path, "no idle stretch before the chirp to take the offsets from");
  const double mu = Mean(u, 0, idle_end), my = Mean(y, 0, idle_end), mf = Mean(f, 0, idle_end);
  std::tie(start, end) = ChirpSpan(u, mu, o.start_threshold_mm);

  RigRecord rec;
  rec.source = path;
  rec.dt_s = dt;
  for (std::size_t k = start; k < end; ++k) {
    rec.t_s.push_back(static_cast<double>(k - start) * dt);
    rec.u_mm.push_back(u[k] - mu);
    rec.y_mm.push_back(y[k] - my);
    rec.f_kN.push_back(f[k] - mf);
    rec.i_A.push_back(o.current_A);
  }
  rec.metadata = {
      {"source", std::filesystem::path(path).filename().string() + " (UTFSM DAQ export, data/utfsm/)"},
      {"conversion", "y_mm = 10 CHANNEL0, f_kN = 9.80665 CHANNEL1, u_mm = 10 CHANNEL2"},
      {"offsets_subtracted", fmt::format("u_mm {:.6g}, y_mm {:.6g}, f_kN {:.6g} (mean of samples 1..{})", mu, my, mf,
                                         idle_end)},
      {"kept_samples", fmt::format("{}..{} of {} (|u| > {} mm from the first to the last crossing)", start + 1, end,
                                   u.size(), o.start_threshold_mm)},
      {"current_A", fmt::format("{}", o.current_A)},
  };
  ValidateRigRecord(rec, path);
  return rec;
}

double UtfsmCurrentFromName(const std::string& path) {
  const std::string stem = std::filesystem::path(path).stem().string();
  const auto hz = stem.rfind("Hz");
  if (hz == std::string::npos || stem.empty() || stem.back() != 'A')
    throw Error(path, "file name does not end in '<current>A' after '<frequency>Hz' (e.g. 25mm0x5Hz0x75A.txt)");
  std::string cur = stem.substr(hz + 2, stem.size() - hz - 3);
  std::replace(cur.begin(), cur.end(), 'x', '.');
  double v = 0.0;
  if (!ParseFinite(cur, &v) || v < 0.0 || v > kMaxAbsCurrentA)
    throw Error(path, fmt::format("cannot read the current '{}' from the file name (a number of A in [0, {:g}])", cur,
                                  kMaxAbsCurrentA));
  return v;
}

RigRecord ReadUtfsmDamper(const std::string& path) {
  const double current = UtfsmCurrentFromName(path);
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open the damper record");
  RigRecord rec;
  rec.source = path;
  std::string line;
  std::size_t ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    if (Trim(line, kLineWhitespace).empty()) continue;
    std::stringstream ss(line);
    std::vector<std::string> fields;
    std::string field;
    while (ss >> field) fields.push_back(field);
    double v[4];
    if (fields.size() != 4 || !ParseFinite(fields[0], &v[0]) || !ParseFinite(fields[1], &v[1]) ||
        !ParseFinite(fields[2], &v[2]) || !ParseFinite(fields[3], &v[3]))
      throw Error(Where(path, ln), "expected four numbers: t [s], x [mm], xdot [mm/s], F [N]");
    CheckBound(path, ln, "t", v[0], kMaxAbsTimeS, "s");
    CheckBound(path, ln, "x", v[1], kMaxAbsDisplacementMm, "mm");
    CheckBound(path, ln, "F / 1000", v[3] / 1000.0, kMaxAbsForceKN, "kN");
    rec.t_s.push_back(v[0]);
    rec.u_mm.push_back(v[1]);
    rec.y_mm.push_back(v[1]);
    rec.f_kN.push_back(v[3] / 1000.0);
    rec.i_A.push_back(current);
  }
  if (rec.size() < 2) throw Error(path, "fewer than two data rows");
  std::vector<double> steps;
  for (std::size_t k = 1; k < rec.size(); ++k) steps.push_back(rec.t_s[k] - rec.t_s[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  rec.dt_s = steps[steps.size() / 2];
  // The files print t with 7 significant digits: round the step to a microsecond.
  rec.dt_s = std::round(rec.dt_s * 1e6) / 1e6;
  rec.metadata = {
      {"source", std::filesystem::path(path).filename().string() + " (UTFSM MR damper test, data/utfsm/)"},
      {"conversion", "u_mm = y_mm = x [mm], f_kN = F [N] / 1000, i_A from the file name"},
      {"current_A", fmt::format("{}", current)},
  };
  ValidateRigRecord(rec, path);
  return rec;
}

RigRecord ReadUtfsm(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open");
  std::string first;
  std::getline(in, first);
  if (Trim(first, kLineWhitespace).rfind("Header Size", 0) == 0) return ReadUtfsmActuator(path);
  return ReadUtfsmDamper(path);
}

RigRecord ReadRecordOrUtfsm(const std::string& path, TimeAxis time) {
  if (IsLcmLog(path)) return ReadRecordAny(path, time);
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open");
  std::string first;
  std::getline(in, first);
  if (Trim(first, kLineWhitespace).rfind("# rths rig record", 0) == 0) return ReadRecordAny(path, time);
  return ReadUtfsm(path);
}

RigRecord CutRigRecord(const RigRecord& rec, double from_s, double to_s) {
  const std::string where = rec.source.empty() ? "record" : rec.source;
  if (!(from_s >= 0.0) || std::isnan(to_s) || !(to_s > from_s))
    throw Error(where, fmt::format("cut window [{}, {}) s: need 0 <= from < to", from_s, to_s));
  RigRecord out;
  out.dt_s = rec.dt_s;
  out.source = rec.source;
  out.metadata = rec.metadata;
  const double t0 = rec.size() > 0 ? rec.t_s[0] : 0.0;
  // Sample k is kept if from <= t_k - t0 < to, with half a step of slack against rounding.
  const double eps = 0.5 * rec.dt_s;
  std::size_t first = rec.size(), last = 0;
  for (std::size_t k = 0; k < rec.size(); ++k) {
    const double t = rec.t_s[k] - t0;
    if (t >= from_s - eps && t < to_s - eps) {
      if (first == rec.size()) first = k;
      last = k + 1;
      out.t_s.push_back(static_cast<double>(out.t_s.size()) * rec.dt_s);
      out.u_mm.push_back(rec.u_mm[k]);
      out.y_mm.push_back(rec.y_mm[k]);
      out.f_kN.push_back(rec.f_kN[k]);
      if (!rec.i_A.empty()) out.i_A.push_back(rec.i_A[k]);
      if (rec.has_r()) out.r_mm.push_back(rec.r_mm[k]);
      if (rec.has_v()) out.v_V.push_back(rec.v_V[k]);
    }
  }
  if (out.size() == 0)
    throw Error(where, fmt::format("cut window [{}, {}) s holds no sample (the record lasts {:.6g} s)", from_s, to_s,
                                   rec.DurationS()));
  out.metadata.emplace_back("cut_from_record", std::filesystem::path(rec.source).filename().string());
  out.metadata.emplace_back("cut_window_s", fmt::format("[{}, {}) s of the record: samples {}..{} of {}", from_s,
                                                        std::isinf(to_s) ? std::string("end") : fmt::format("{}", to_s),
                                                        first + 1, last, rec.size()));
  ValidateRigRecord(out, fmt::format("{} cut to [{}, {}) s", where, from_s, to_s));
  return out;
}

}  // namespace rths::io
