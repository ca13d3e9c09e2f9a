#pragma once
/// @file The UTFSM measured records (data/utfsm/, data/README.md) as rig records (io/rig_record.h).
///
/// actuator/chirp_0A.txt: a DAQ text export: a header of H lines, the first "Header Size: H",
/// the last the column line "Sample Number, Date/Time, CHANNEL0, CHANNEL1, CHANNEL2, Events";
/// then one row per sample (the Events field may be empty or absent), volts at
/// "Sampling Interval" seconds. Conversions (the data's authors'): y_mm = 10 CHANNEL0,
/// f_kN = 9.80665 CHANNEL1 (9806.65 N/V), u_mm = 10 CHANNEL2; i_A = 0 (0 A test).
/// Offsets: the channels are not zero at rest; the mean of the idle stretch before the chirp is
/// subtracted from each channel. Trimming: the chirp starts at the first sample where the
/// offset-free |u| exceeds the threshold (0.4 mm) and ends after the last such sample.
/// The idle stretch: the samples before the start, less the last second (the actuator may already
/// be moving slowly there); if that leaves under 0.5 s, the first half of the samples before the
/// start.
///
/// mr_damper/<amp>mm<freq>Hz<current>A.txt: whitespace-separated t [s], x [mm], xdot [mm/s],
/// F [N]. As a rig record: u = y = x [mm], f = F / 1000 [kN], i = the current in the file name
/// ("0x75A" = 0.75 A), dt = the median step of t; no offset removal, no trimming.
#include <string>

#include "io/rig_record.h"

namespace rths::io {

/// Options of ReadUtfsmActuator.
struct UtfsmActuatorOptions {
  double start_threshold_mm = 0.4;  ///< |u| [mm] (offset-free) that marks the chirp's start and end, > 0
  double current_A = 0.0;           ///< the damper current during the test [A]
};

/// Reads a DAQ export (chirp_0A.txt) into a rig record (file comment). Metadata record the
/// source, the conversions, the offsets subtracted and the samples kept. Throws rths::Error
/// ("path:line") for a malformed header or row, no sample above the threshold, or a result that
/// fails ValidateRigRecord.
RigRecord ReadUtfsmActuator(const std::string& path, const UtfsmActuatorOptions& options = {});

/// The current [A] coded in a UTFSM damper file name: the text between the last "Hz" and the
/// final "A" before the extension, with 'x' as the decimal point ("25mm0x5Hz0x75A.txt" -> 0.75,
/// "10mm1Hz1A.txt" -> 1). Throws rths::Error if the name does not follow the pattern.
double UtfsmCurrentFromName(const std::string& path);

/// Reads a UTFSM damper file (t, x, xdot, F) into a rig record (file comment). Throws
/// rths::Error ("path:line") for a malformed row and whatever ValidateRigRecord finds.
RigRecord ReadUtfsmDamper(const std::string& path);

/// Either of the above, by content: a file whose first line starts with "Header Size" is a DAQ
/// export, anything else a damper file.
RigRecord ReadUtfsm(const std::string& path);

/// Any record a tool takes, by content: an LCM run log of ours (IsLcmLog) or a CSV rig record
/// (first line "# rths rig record ...") through ReadRecordAny, anything else through ReadUtfsm.
/// `time` is how a CSV rig record takes its step (ReadRigRecord).
RigRecord ReadRecordOrUtfsm(const std::string& path, TimeAxis time = TimeAxis::kColumn);

/// The samples of `rec` with from_s <= t_k - t_0 < to_s (times relative to the record's first
/// sample, so the second half of a record starts at its own t = 0 as well), time restarted at 0
/// (t_k = k dt), everything else copied; metadata gain "cut_from_record" (the source) and
/// "cut_window_s" (the window and the samples kept). to_s = infinity keeps the rest.
/// Throws rths::Error (where = rec.source) if from_s < 0, to_s <= from_s, or the window keeps
/// under 2 s (kMinRecordS; ValidateRigRecord).
RigRecord CutRigRecord(const RigRecord& rec, double from_s, double to_s);

}  // namespace rths::io
