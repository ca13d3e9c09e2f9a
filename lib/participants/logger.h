#pragma once
/// @file The logger: a lockstep participant that never drops a message and never acknowledges
/// a step it could not store (docs/lockstep.md).
///
/// Step k (inputs -> answer):
///   desired_t k, command_t k, measured_t k, current_t k (+ measured_t k+1)  ->  ack_t k
/// The first copy of every (channel, k) is kept; re-sent duplicates are ignored. Once all four
/// messages of step k are in, they are appended to log.lcm (a standard LCM event log, readable by
/// lcm-logplayer and lcm-spy) in channel order, copied into the file's shared mapping
/// (io::MappedLogFile: in the kernel's page cache, as after a write(2), without a system call; a
/// killed logger leaves every acknowledged step in the file), and only then, and once the
/// rest of the barrier of step k is in too (measured_t k+1 where the plant answers command_t k: the
/// logger's row of the step table, lockstep/step_table.h), is ack_t k published: the clock cannot advance past a step the logger has not handed to the kernel. The
/// handshake is logged on its own channel as it arrives (first copy per participant and phase).
///
/// signals.csv is a derived copy of the log (every column comes from the four messages): the step
/// hands the row's numbers to io::SignalsCsvWriter's queue (a copy of twelve numbers) and its
/// writer thread formats the rows and writes them 64 kB at a time, into space reserved ahead with
/// fallocate(2) (so a full disk cannot fail the write of a row already handed over); where the file
/// system cannot reserve space, each row is formatted and written with the step, as before. Every
/// row handed over is written when DONE arrives, when the run stops (ABORT, an interrupt, a write
/// error) and when the logger is destroyed: signals.csv then ends on the last written step, like
/// log.lcm. Only if the logger process itself is killed (SIGKILL) may signals.csv end earlier, on
/// a whole row; log.lcm is complete regardless. No write system call per step: the log's
/// reservations and one per 64 kB of rows (bench/memq.cpp counts them). Rows are formatted with
/// std::to_chars, to the same bytes as printf's %.17g and %.6f.
///
/// Event timestamps are simulated time: the wall-clock time at which the logger started stepping
/// (GO) plus k dt for the events of step k, so `lcm-logplayer --speed 1` replays a run at the pace
/// it represents, whatever pace it ran at. Handshake events before GO carry their receive time,
/// later ones the current step's time.
///
/// A failed or short write (disk full, I/O error) stops the run: log.lcm is cut back to the end of
/// the last written step, the buffered rows (all of written steps) are written to
/// signals.csv (cut back to its last whole row if that fails too), ABORT is broadcast naming the
/// file and the error, and the logger exits with kExitOutput.
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <utility>

#include "io/mapped_log_file.h"
#include "io/signals_csv_writer.h"
#include "lockstep/step_participant.h"
#include "rths/ack_t.hpp"
#include "rths/handshake_t.hpp"

namespace rths::participants {

/// Bytes of the stored output per step for a structure with `n_dof` degrees of freedom, `n_act`
/// actuators' arrays (0: one actuator, the scalars only) and `n_iface` interface forces: the four
/// events of log.lcm and the signals.csv row (an upper bound for the row). The supervisor uses
/// it to check the free disk space before a run.
std::int64_t StoredBytesPerStep(int n_dof, int n_act = 0, int n_iface = 0);
/// Bytes of log.lcm per step (its four events; an adaptive controller's coefficients aside): the
/// log's size divided by this is about the steps written (progress displays).
std::int64_t LogBytesPerStep(int n_dof, int n_act = 0, int n_iface = 0);

class Logger : public lockstep::StepAnswerer<rths::ack_t> {
 public:
  /// Creates `log_path` (LCM event log) and `csv_path` (signals: a row for every `csv_every`-th
  /// step, k = 0, N, 2N, ...; csv_every = 0: no CSV file at all; scenario key run.csv_every);
  /// throws rths::Error. `wiring`: the run's (WiringOf(s), or a replay's): step k is written as
  /// soon as its four messages are in, and acknowledged once everything else the barrier of step k
  /// waits for is in as well (measured_t k+1 where the plant answers command_t k): the clock then
  /// sends desired_t k+1 after measured_t k+1 in every run, so the controller and the semiactive
  /// law wake once per step, for desired_t (docs/lockstep.md, "Wake-ups"). `paced`: a real-time
  /// run (scenario [realtime] enabled): log.lcm reserved in 64 KiB pieces, no pre-fault helper
  /// (io::MappedLogFile).
  Logger(lockstep::RunIdentity id, lockstep::LockstepConfig config, lcm::LCM* lcm, const lockstep::Wiring& wiring,
         const std::string& log_path, const std::string& csv_path, lockstep::Faults faults = {}, int csv_every = 1,
         bool paced = false);
  ~Logger() override;

  /// Steps written so far (every step acknowledged, and at most one more whose acknowledgement
  /// waits for measured_t k+1).
  std::int64_t steps_written() const { return written_; }
  /// File system calls (pwrite, ftruncate, fallocate, mmap) made so far, handshake included.
  std::int64_t write_calls() const;
  /// Steps whose signals.csv row waited for the writer thread (its queue was full); in
  /// summary.json as participants.logger.output_stalls.
  std::int64_t output_stalls() const override;

 protected:
  std::string OnDone() override;  // writes every row of signals.csv
  void OnStop() override;         // the same, on an abnormal stop
  void OnGo() override;
  /// Writes step k (log.lcm and its signals.csv row); the ack follows once the barrier is in.
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::ack_t* out) override;
  /// Keeps the raw bytes of the four logged channels (what is written to the log).
  void OnInput(lockstep::Channel channel, std::int64_t k, const lcm::ReceiveBuffer* rbuf) override;

 private:
  /// Timestamp of the events of step k [us since the epoch]: start + k dt.
  std::int64_t StepUtime(std::int64_t k) const;
  /// The raw bytes of one channel's messages of the last four steps (what is written to the log).
  using RawRing = std::array<lockstep::Bytes, 4>;

  void OnHandshakeSeen(const lcm::ReceiveBuffer* rbuf, const rths::handshake_t& msg) override;
  /// Writes step k (log.lcm and its signals.csv row) from its four messages; false if the write
  /// failed (the run is then stopped).
  bool WriteStep(std::int64_t k, const lockstep::StepInputs& in);
  /// Cuts both files back to the last written step and stops the run (kExitOutput).
  void FailWrite(const std::string& why, std::int64_t k);
  /// Writes every row of signals.csv and closes it (once; later calls return ""): "" or the error.
  std::string CloseCsv();

  std::string log_path_, csv_path_;
  int csv_every_ = 1;  ///< signals.csv row every this many steps; 0: no signals.csv
  std::unique_ptr<io::MappedLogFile> log_;    ///< log.lcm
  std::unique_ptr<io::SignalsCsvWriter> csv_;  ///< signals.csv; null when csv_every = 0
  std::int64_t log_acked_ = 0;                  ///< log bytes at the end of the last written step
  bool csv_closed_ = false;                     ///< signals.csv closed: no more rows
  std::int64_t event_number_ = 0;
  std::int64_t start_utime_ = -1;  ///< wall-clock time of GO [us since the epoch]; -1 before
  std::int64_t written_ = 0;  ///< steps written: the next to acknowledge, or one more
  RawRing raw_desired_{}, raw_command_{}, raw_measured_{}, raw_current_{};
  lockstep::Bytes step_bytes_;  ///< the step's four events, written at once
  rths::handshake_t hs_{};
  std::set<std::pair<std::string, int>> handshakes_logged_;
};

}  // namespace rths::participants
