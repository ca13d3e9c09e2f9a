// A run log's messages as CSV columns (io/log_dump.h).
#include "io/log_dump.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "core/error.h"
#include "io/csv.h"
#include "lockstep/protocol.h"

namespace rths::io {

namespace ls = rths::lockstep;

const std::vector<DumpChannel>& DumpChannels() {
  static const std::vector<DumpChannel> channels = {{ls::kChDesired, "desired"},
                                                    {ls::kChCommand, "command"},
                                                    {ls::kChMeasured, "measured"},
                                                    {ls::kChCurrent, "current"},
                                                    {ls::kChHandshake, "handshake"}};
  return channels;
}

std::string DumpChannelName(const std::string& name) {
  std::string upper = name, lower = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  std::string choices;
  for (const auto& c : DumpChannels()) {
    if (upper == c.channel || lower == c.short_name) return c.channel;
    choices += fmt::format("{}{} ({})", choices.empty() ? "" : ", ", c.channel, c.short_name);
  }
  throw Error("--channel " + name, "not a channel of a run log; one of " + choices);
}

namespace {

/// Shortest text that reads back as the same double ("0.0005", not "0.00050000000000000001").
std::string Num(double v) { return fmt::format("{}", v); }
std::string Num(std::int64_t v) { return std::to_string(v); }

const char* PhaseName(int phase) {
  switch (phase) {
    case ls::kRequest: return "REQUEST";
    case ls::kHello: return "HELLO";
    case ls::kGo: return "GO";
    case ls::kAbort: return "ABORT";
    case ls::kDone: return "DONE";
    case ls::kBye: return "BYE";
    case ls::kClose: return "CLOSE";
    case ls::kHeartbeat: return "HEARTBEAT";
    default: return "?";
  }
}

/// One event's payload as T (ReadRunLog already checked that it decodes exactly).
template <typename T>
T Decode(const LogEvent& e) {
  T m;
  if (m.decode(e.data.data(), 0, static_cast<int>(e.data.size())) != static_cast<int>(e.data.size()))
    throw Error(fmt::format("byte {}", e.offset_bytes), "payload does not decode as " + e.channel);
  return m;
}

}  // namespace

std::vector<std::string> DumpFieldNames(const std::string& channel, int n_dof) {
  if (channel == ls::kChDesired) {
    std::vector<std::string> f{"r_mm",           "rd_mm_s",       "rdd_mm_s2",        "rddd_mm_s3",
                               "acc_prev_mm_s2", "vel_prev_mm_s", "ground_acc_mm_s2", "n_dof"};
    for (int i = 1; i <= n_dof; ++i) f.push_back(fmt::format("x{}_mm", i));
    for (int i = 1; i <= n_dof; ++i) f.push_back(fmt::format("abs_acc{}_mm_s2", i));
    return f;
  }
  if (channel == ls::kChCommand) return {"u_mm", "u_ff_mm", "u_fb_mm"};
  if (channel == ls::kChMeasured) return {"y_mm", "f_kN", "current_A"};
  if (channel == ls::kChCurrent) return {"i_cmd_A", "f_desired_kN"};
  return {"phase", "phase_name", "participant", "scenario_sha256", "n_steps", "dt_s", "roster", "reason"};
}

bool DecodeDumpRow(const LogEvent& e, int n_dof, std::vector<std::string>* out) {
  out->clear();
  if (e.channel == ls::kChDesired) {
    const auto m = Decode<rths::desired_t>(e);
    *out = {Num(m.k),           Num(m.run_id),         Num(m.r_mm),          Num(m.rd_mm_s),
            Num(m.rdd_mm_s2),   Num(m.rddd_mm_s3),     Num(m.acc_prev_mm_s2), Num(m.vel_prev_mm_s),
            Num(m.ground_acc_mm_s2), Num(std::int64_t{m.n_dof})};
    for (int i = 0; i < n_dof; ++i) out->push_back(i < m.n_dof ? Num(m.x_mm[static_cast<std::size_t>(i)]) : "");
    for (int i = 0; i < n_dof; ++i)
      out->push_back(i < m.n_dof ? Num(m.abs_acc_mm_s2[static_cast<std::size_t>(i)]) : "");
  } else if (e.channel == ls::kChCommand) {
    const auto m = Decode<rths::command_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.u_mm), Num(m.u_ff_mm), Num(m.u_fb_mm)};
  } else if (e.channel == ls::kChMeasured) {
    const auto m = Decode<rths::measured_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.y_mm), Num(m.f_kN), Num(m.current_A)};
  } else if (e.channel == ls::kChCurrent) {
    const auto m = Decode<rths::current_t>(e);
    *out = {Num(m.k), Num(m.run_id), Num(m.i_cmd_A), Num(m.f_desired_kN)};
  } else if (e.channel == ls::kChHandshake) {
    const auto m = Decode<rths::handshake_t>(e);
    std::string roster;
    for (int i = 0; i < m.n_roster; ++i)
      roster += fmt::format("{}{}={}", i ? ";" : "", m.roster_names[static_cast<std::size_t>(i)],
                            m.roster_sha256[static_cast<std::size_t>(i)]);
    *out = {Num(m.k),         Num(m.run_id),    Num(std::int64_t{m.phase}), PhaseName(m.phase), m.participant,
            m.scenario_sha256, Num(m.n_steps), Num(m.dt_s),                roster,             m.reason};
  } else {
    return false;
  }
  return true;
}

std::int64_t WriteLogDump(const std::string& path, const RunLog& log, const std::string& channel, std::FILE* out,
                          const std::string& out_name, std::int64_t* skipped) {
  int n_dof = 0;
  for (const auto& d : log.desired) n_dof = std::max(n_dof, static_cast<int>(d.n_dof));
  // Where each channel's fields start in a row (after channel, k, run_id when dumping all).
  std::vector<std::string> header;
  std::vector<std::pair<std::string, std::size_t>> offsets;
  if (channel.empty()) header.push_back("channel");
  header.insert(header.end(), {"k", "run_id"});
  for (const auto& c : DumpChannels()) {
    if (!channel.empty() && channel != c.channel) continue;
    offsets.emplace_back(c.channel, header.size());
    const auto names = DumpFieldNames(c.channel, n_dof);
    header.insert(header.end(), names.begin(), names.end());
  }
  const auto write = [&](const std::vector<std::string>& fields) {
    const std::string rec = CsvRecord(fields);
    if (std::fwrite(rec.data(), 1, rec.size(), out) != rec.size())
      throw Error(out_name, fmt::format("write failed: {}", std::strerror(errno)));
  };
  write(header);
  EventLogReader reader(path);
  LogEvent e;
  std::vector<std::string> decoded, row(header.size());
  std::int64_t rows = 0;
  *skipped = 0;
  while (reader.Next(&e)) {
    const auto at = std::find_if(offsets.begin(), offsets.end(), [&](const auto& o) { return o.first == e.channel; });
    if (at == offsets.end() || !DecodeDumpRow(e, n_dof, &decoded)) {
      ++*skipped;
      continue;
    }
    std::fill(row.begin(), row.end(), std::string());
    std::size_t col = 0;
    if (channel.empty()) row[col++] = e.channel;
    row[col++] = decoded[0];  // k
    row[col++] = decoded[1];  // run_id
    std::copy(decoded.begin() + 2, decoded.end(), row.begin() + static_cast<std::ptrdiff_t>(at->second));
    write(row);
    ++rows;
  }
  return rows;
}

}  // namespace rths::io
