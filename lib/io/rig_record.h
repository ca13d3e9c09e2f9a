#pragma once
/// @file The rig record: one test on a rig (ours or another lab's) as uniformly sampled
/// command, measurement, force and current (docs/rig_record.md "Rig record, CSV").
///
/// CSV format (v1):
///     # rths rig record v1              <- first line, required
///     # dt_s: 0.0005                    <- required: the time step [s]
///     # key: value                      <- any other metadata, kept in order
///     t_s,u_mm,y_mm,f_kN,i_A[,r_mm]     <- column names, any order; unknown names ignored (warning)
///     0.0000,0.0,0.001,0.02,0.0
/// Columns: t_s time [s], uniform step; u_mm displacement command to the servo-controller [mm];
/// y_mm measured actuator displacement [mm]; f_kN measured specimen force [kN]; i_A damper current
/// command [A]; r_mm (optional) desired displacement [mm]. Offsets are the producer's business:
/// nothing is removed on reading.
///
/// Sample pairing (docs/lockstep.md): row k holds u_k, the command held over [t_k, t_{k+1}), and
/// y_k, f_k measured at t_k; on a rig with a strictly proper actuator y_k depends on u up to k-1.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/run_log.h"

namespace rths::io {

/// A rig record in memory. All vectors have size() samples (r_mm: 0 or size()).
struct RigRecord {
  double dt_s = 0.0;                 ///< time step [s]
  std::vector<double> t_s;           ///< t_k [s]
  std::vector<double> u_mm;          ///< command u_k [mm]
  std::vector<double> y_mm;          ///< measured displacement y_k [mm]
  std::vector<double> f_kN;          ///< measured force f_k [kN]
  std::vector<double> i_A;           ///< damper current command i_k [A]; empty if the record has v_V only
  std::vector<double> r_mm;          ///< desired displacement r_k [mm]; empty if the record has none
  /// damper voltage command v_k [V] (a voltage-driven damper); empty if the record has none.
  /// A record has i_A, v_V or both.
  std::vector<double> v_V;
  /// '# key: value' metadata other than dt_s, in file order.
  std::vector<std::pair<std::string, std::string>> metadata;
  /// Non-fatal findings while reading (e.g. unknown columns), each "file:line: message".
  std::vector<std::string> warnings;
  /// Where the record came from (a path), for messages.
  std::string source;

  std::size_t size() const { return t_s.size(); }
  bool has_r() const { return !r_mm.empty(); }
  bool has_v() const { return !v_V.empty(); }
  /// The damper command the models are driven with: i_A, or v_V for a record without i_A.
  const std::vector<double>& Command() const { return i_A.empty() ? v_V : i_A; }
  /// size() x dt_s [s].
  double DurationS() const { return static_cast<double>(size()) * dt_s; }
  /// The value of metadata `key`, or "" if absent.
  std::string Meta(const std::string& key) const;
};

/// Shortest record accepted [s] (docs/diagnosis.md).
inline constexpr double kMinRecordS = 2.0;

/// Largest magnitudes a record may hold (ReadRigRecord, ValidateRigRecord): far beyond any lab
/// rig, yet small enough that no sum of squares or model prediction of the diagnosis and the
/// identification overflows (a sample of 1e308 used to make every fit NaN).
inline constexpr double kMaxAbsDisplacementMm = 1e4;  ///< |u_mm|, |y_mm|, |r_mm| [mm] (10 m)
inline constexpr double kMaxAbsForceKN = 1e5;         ///< |f_kN| [kN] (100 MN)
inline constexpr double kMaxAbsCurrentA = 100.0;      ///< |i_A| [A]
inline constexpr double kMaxAbsVoltageV = 100.0;      ///< |v_V| [V]
inline constexpr double kMaxAbsTimeS = 1e10;          ///< |t_s| [s] (Unix times fit)
/// The range of dt_s [s]: 1 MHz to 1 Hz sampling.
inline constexpr double kMinDtS = 1e-6, kMaxDtS = 1.0;

/// How a CSV reader takes the step dt.
enum class TimeAxis {
  /// From the time column, checked: uniform (each step within 1 % of the median step, a gap if
  /// above 1.5 steps), and its mean step (t_last - t_0) / (n - 1) equal to '# dt_s' within
  /// kDtAgreement. A rounded column fails with a hint to use kHeader.
  kColumn,
  /// From '# dt_s' (--time-from-header): the time column only has to increase and lie within half
  /// a step of t_0 + k dt_s (no row missing or extra; a column rounded to 0.1 ms at 3 kHz passes);
  /// its largest deviation is a warning, and t_s becomes t_0 + k dt_s.
  kHeader,
};
/// Relative agreement required between '# dt_s' and the time column's mean step (TimeAxis::kColumn).
inline constexpr double kDtAgreement = 1e-4;

/// Reads a CSV rig record. Throws rths::Error with where = "path:line" (line 1-based, of the
/// offending line; or "path" if it cannot be opened) for: a missing or wrong first line, a
/// missing or bad '# dt_s:' line (a number in [kMinDtS, kMaxDtS]), a missing or duplicated column,
/// a row with the wrong number of fields, a field that is not a finite number (NaN, inf, 1e999,
/// text) or is out of its column's bounds (kMaxAbsDisplacementMm, kMaxAbsForceKN, kMaxAbsCurrentA,
/// kMaxAbsTimeS), a non-increasing time, a non-uniform step or a gap (a step off the median step
/// by more than 1 %; a gap if it exceeds 1.5 steps), a mean step that disagrees with dt_s by
/// more than kDtAgreement (where = the dt_s line), and fewer than 2 s of data (where = the last
/// line); `time` says where dt comes from (TimeAxis).
RigRecord ReadRigRecord(const std::string& path, TimeAxis time = TimeAxis::kColumn);

/// ReadRigRecord on the text of a record (`path` names it in messages and becomes its source).
RigRecord ParseRigRecord(std::string_view text, const std::string& path, TimeAxis time = TimeAxis::kColumn);

/// Writes `rec` as a CSV rig record (format above; t_s, u_mm, y_mm, f_kN, i_A[, r_mm]; numbers
/// with 10 significant digits). Throws rths::Error if the file cannot be written or the vectors
/// differ in length.
void WriteRigRecord(const RigRecord& rec, const std::string& path);

/// Checks an in-memory record with the rules of ReadRigRecord (lengths, finite values within the
/// bounds, dt_s in range, uniform time at dt_s, at least 2 s); `where` names it in the error.
/// Throws rths::Error.
void ValidateRigRecord(const RigRecord& rec, const std::string& where);

/// A run of ours as a rig record, over its complete steps k = 0 .. CompleteSteps()-1:
/// t = k dt (dt from the handshake), u = command_t.u_mm at k, y = measured_t.y_mm at k,
/// f = measured_t.f_kN at k, i = current_t.i_cmd_A at k (the semiactive command), r =
/// desired_t.r_mm at k. Metadata: source, run_id. A log that is not RunLog::Complete() (the run
/// did not finish, or the file is cut) gives a warning saying so. Throws rths::Error (where =
/// `source`) if the log has no dt or fails ValidateRigRecord.
RigRecord RigRecordFromRunLog(const RunLog& log, const std::string& source);

/// True if the file starts with the LCM event-log sync word 0xEDA1DA01.
bool IsLcmLog(const std::string& path);

/// Reads `path` as an LCM run log of ours (IsLcmLog) or else as a CSV rig record.
RigRecord ReadRecordAny(const std::string& path, TimeAxis time = TimeAxis::kColumn);

}  // namespace rths::io
