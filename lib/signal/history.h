#pragma once
/// @file Time histories read or generated at the edge: ground accelerations and desired
/// displacements (signal::SignalSpec).
#include <cstddef>
#include <string>
#include <vector>
#include <cstdint>

#include "core/names.h"

namespace rths::signal {

/// How a time history is made (SignalSpec::kind).
enum class SignalKind { kBlwn, kFile, kZero };
inline constexpr std::array<Named<SignalKind>, 3> kSignalKindNames = {
    {{SignalKind::kBlwn, "blwn"}, {SignalKind::kFile, "file"}, {SignalKind::kZero, "zero"}}};

/// A time-history file's data rows as read (ReadHistoryFile): the time of each row [s] (the file's
/// time column, or j file_dt_s for a one-column file) and its value in the file's unit.
struct HistoryRecord {
  std::vector<double> t;
  std::vector<double> value;
  bool operator==(const HistoryRecord&) const = default;
};

/// A time history generated or read at the edge (ground acceleration or desired displacement).
/// Config is parsed and every file it names is read once, at the edge: `file` stays the path the
/// scenario names (ToToml writes it), `record` holds its rows (scenario::ReadReferencedFiles).
struct SignalSpec {
  SignalKind kind = SignalKind::kBlwn;  ///< "blwn" | "file" | "zero"
  // kind = "blwn": Gaussian white noise through an 8th-order Butterworth low-pass at band_hz,
  // scaled to rms, with the first discard_s seconds thrown away (docs/models.md section 9).
  double band_hz = 30.0;      ///< upper band edge [Hz], (0, 0.5/dt)
  double rms = 1500.0;        ///< RMS in the signal's unit (mm/s^2 for ground, mm for desired), > 0
  std::uint64_t seed = 1;     ///< generator seed
  double discard_s = 2.0;     ///< start-up transient thrown away [s], [0, 60]
  // kind = "file": one column (values at file_dt_s) or two columns (t [s], value).
  std::string file;           ///< path, relative to the scenario file's folder (after parsing: absolute)
  double file_dt_s = 0.0;     ///< step of a one-column file [s]; 0 = the file has a time column
  double scale = 1.0;         ///< multiply the file's values by this to get the signal's unit
  /// Raised-cosine fade-in over the first taper_s seconds [s], [0, 60]: a BLWN record cut after
  /// its discarded start begins mid-motion, which would ask the actuator for a step.
  double taper_s = 0.0;
  /// kind = "file": the record's time 0 falls at this run time [s], [0, 3600]; > 0 pads it with
  /// zeros before and after at the file's own step (the RTHS benchmark's ElCentroAccelNoScaling is
  /// our El Centro record with start_s = 5: 5 s of zeros, the record, then zeros).
  double start_s = 0.0;
  /// kind = "file": the rows of `file`, read once by the scenario loader (ReadHistoryFile); empty
  /// for the other kinds. MakeSignal resamples them.
  HistoryRecord record{};
  bool operator==(const SignalSpec&) const = default;
};

/// Reads a time history from a text file and resamples it to the run's step (ReadHistoryFile, then
/// ResampleHistory).
///
/// Format: one data row per line; fields separated by whitespace or by commas (with optional
/// whitespace around them); '#' starts a comment to the end of the line; blank lines are
/// skipped. Either
///   - one column of values v_j at t_j = j file_dt_s (file_dt_s > 0), or
///   - two columns t [s], value (file_dt_s == 0); t must start at >= 0, increase strictly, and
///     have no gap: no step may exceed 1.5 x the median step (missing rows).
/// Output: x_k = scale * v(k dt_s), k = 0 .. n - 1, with v linearly interpolated between rows;
/// zero before the first row's time and after the last row's time (a record shorter than the
/// run is padded with zeros). The unit of x is the file's unit times `scale`. start_s > 0 delays the
/// record by start_s [s] and adds a zero row one file step before its first row and one after its
/// last, so that it ramps from and to zero as a file padded with zeros at its own step would.
/// Throws rths::Error("path:line", ...) for a non-numeric or empty field, a wrong number of
/// columns, a non-increasing or negative time, a gap; rths::Error("path", ...) for a file that
/// cannot be read or has no data rows; and for file_dt_s < 0, dt_s <= 0 or a non-finite scale.
std::vector<double> LoadHistory(const std::string& path, double file_dt_s, double scale, double dt_s,
                                std::size_t n, double start_s = 0.0);
/// The rows of a time-history file (format and errors as LoadHistory; a one-column file's times are
/// j file_dt_s). Throws rths::Error("path:line", ...) or rths::Error("path", ...).
HistoryRecord ReadHistoryFile(const std::string& path, double file_dt_s);
/// A record read by ReadHistoryFile resampled as LoadHistory describes (x_k = scale * v(k dt_s),
/// start_s [s] the delay, file_dt_s [s] the pad step of a one-row record). Throws rths::Error("history", ...)
/// for an empty record, dt_s <= 0, a non-finite scale or start_s < 0.
std::vector<double> ResampleHistory(const HistoryRecord& record, double file_dt_s, double scale, double dt_s,
                                    std::size_t n, double start_s);

/// The n-sample record described by `spec` at step dt_s [s]:
///   kind "blwn": Blwn(band_hz, rms, dt_s, n, seed, discard_s) (signal/blwn.h);
///   kind "file": ResampleHistory(record, file_dt_s, scale, dt_s, n, start_s), the rows read by the
///                scenario loader (an empty record: rths::Error naming the file);
///   kind "zero": n zeros.
/// Then the first spec.taper_s seconds are faded in (ApplyTaper).
/// Throws rths::Error for any other kind, and whatever the chosen generator throws.
std::vector<double> MakeSignal(const signal::SignalSpec& spec, double dt_s, std::size_t n);

/// Fades a record in from zero over its first taper_s seconds with a raised cosine,
/// w_i = (1 - cos(pi i / m)) / 2 for i < m = round(taper_s / dt_s): a record that starts
/// mid-motion would otherwise ask the actuator for a step (and its derivatives for an impulse).
void ApplyTaper(double taper_s, double dt_s, std::vector<double>* x);

}  // namespace rths::signal
