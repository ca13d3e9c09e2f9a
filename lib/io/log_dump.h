#pragma once
/// @file A run log's messages decoded to CSV columns, one row per message in log order (`rths log
/// dump`, docs/export.md): the message schema of lcmtypes/*.lcm as column names, beside
/// io/run_signals.h (the per-step signals of the same messages, for export and report). Every
/// message has k and run_id; the field names are those of lcmtypes/*.lcm with their units, arrays
/// one column per element (x_mm[0] -> x1_mm, abs_acc_mm_s2[0] -> abs_acc1_mm_s2, as in rths export).
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "io/event_log.h"
#include "io/run_log.h"

namespace rths::io {

/// A channel the dump decodes: its LCM name and its short name (`--channel desired`).
struct DumpChannel {
  const char* channel;     ///< e.g. "RTHS_DESIRED"
  const char* short_name;  ///< e.g. "desired"
};

/// The channels the dump decodes, in the dump's column order: desired, command, measured,
/// current, handshake.
const std::vector<DumpChannel>& DumpChannels();

/// The channel named by `name` (RTHS_DESIRED or desired, any case). Throws rths::Error
/// ("--channel NAME") listing the choices.
std::string DumpChannelName(const std::string& name);

/// The columns of `channel` after k and run_id (n_dof: the largest desired_t.n_dof of the log).
/// The handshake's roster is one column, "name=sha256" per participant of a GO joined by ';'.
std::vector<std::string> DumpFieldNames(const std::string& channel, int n_dof);

/// Decodes one event as its channel's type: k, run_id and the fields (DumpFieldNames order;
/// arrays padded with "" up to n_dof; numbers as the shortest text that reads back as the same
/// double) go to *out. Returns false for a channel the dump does not know. Throws rths::Error
/// naming the byte offset if the payload does not decode exactly.
bool DecodeDumpRow(const LogEvent& e, int n_dof, std::vector<std::string>* out);

/// Writes the dump of the log at `path` (already read as `log`, io::ReadRunLog) to `out` as CSV
/// (RFC 4180): with `channel` empty every known channel, one header of all their fields after
/// "channel,k,run_id" (a message leaves the other channels' cells empty); else "k,run_id" and
/// that channel's fields, its messages only. Returns the rows written; *skipped counts the events
/// left out. Throws rths::Error naming `out_name` if a write fails.
std::int64_t WriteLogDump(const std::string& path, const RunLog& log, const std::string& channel, std::FILE* out,
                          const std::string& out_name, std::int64_t* skipped);

}  // namespace rths::io
