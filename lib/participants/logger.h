#pragma once
/// @file The logger: a lockstep participant that never drops a message and never acknowledges
/// a step it could not store (docs/lockstep.md).
///
/// Step k (inputs -> answer):
///   desired_t k, command_t k, measured_t k, current_t k  ->  ack_t k
/// The first copy of every (channel, k) is kept; re-sent duplicates are ignored. Once all four
/// messages of step k are in, they are appended to log.lcm (a standard LCM event log, readable by
/// lcm-logplayer and lcm-spy) in channel order with one write(2), the row k of signals.csv with
/// another, and only then is ack_t k published: the clock cannot advance past a step the logger
/// has not handed to the kernel. The handshake is logged on its own channel as it arrives (first
/// copy per participant and phase).
///
/// Event timestamps are simulated time: the wall-clock time at which the logger started stepping
/// (GO) plus k dt for the events of step k, so `lcm-logplayer --speed 1` replays a run at the pace
/// it represents, whatever pace it ran at. Handshake events before GO carry their receive time,
/// later ones the current step's time.
///
/// A failed or short write (disk full, I/O error) stops the run: both files are cut back to the
/// end of the last acknowledged step (so they end on a whole event and a whole row), ABORT is
/// broadcast naming the file and the error, and the logger exits with kExitOutput.
#include <cstdint>
#include <set>
#include <string>
#include <utility>

#include "lockstep/runtime.h"
#include "rths/ack_t.hpp"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::participants {

/// Bytes of the stored output per step for a structure with `n_dof` degrees of freedom: the four
/// events of log.lcm and the signals.csv row (an upper bound for the row). The supervisor uses
/// it to check the free disk space before a run.
std::int64_t StoredBytesPerStep(int n_dof);
/// Bytes of log.lcm per step (its four events) for `n_dof` degrees of freedom: the log's size
/// divided by this is about the steps written (progress displays).
std::int64_t LogBytesPerStep(int n_dof);

class Logger : public lockstep::Participant {
 public:
  /// Creates `log_path` (LCM event log) and `csv_path` (signals: a row for every `csv_every`-th
  /// step, k = 0, N, 2N, ...; csv_every = 0: no CSV file at all; scenario key run.csv_every);
  /// throws rths::Error.
  Logger(lockstep::RunIdentity id, lockstep::Timing timing, lcm::LCM* lcm, const std::string& log_path,
         const std::string& csv_path, lockstep::Faults faults = {}, int csv_every = 1);
  ~Logger() override;

  /// Steps acknowledged so far.
  std::int64_t steps_written() const { return next_; }

 protected:
  std::string OnDone() override { return {}; }  // every step was written before its ack
  void OnGo() override;
  void ListMissing(std::int64_t k, lockstep::WantList* out) const override;

 private:
  /// Timestamp of the events of step k [us since the epoch]: start + k dt.
  std::int64_t StepUtime(std::int64_t k) const;
  /// The raw bytes of one channel's messages of the last four steps (what is written to the log).
  using RawRing = std::array<lockstep::Bytes, 4>;

  template <class Msg>
  void OnStepMessage(lockstep::StepMailbox<Msg>* box, RawRing* raw, lockstep::Channel channel,
                     const lcm::ReceiveBuffer* rbuf);
  void OnHandshakeSeen(const lcm::ReceiveBuffer* rbuf, const rths::handshake_t& msg) override;
  void TryAck();
  /// Publishes ack_t k (step k is stored) and moves on to k + 1.
  void Acknowledge(std::int64_t k);
  /// Appends `bytes` to the file `fd` (every byte, or none: on failure the file is cut back to
  /// `*good_end`); advances `*good_end`. Returns "" or the error, naming the file.
  std::string Append(int fd, const std::string& path, const std::uint8_t* data, std::size_t size,
                     std::int64_t* good_end);
  /// Cuts both files back to the last acknowledged step and stops the run (kExitOutput).
  void FailWrite(const std::string& why, std::int64_t k);

  std::string log_path_, csv_path_;
  int csv_every_ = 1;  ///< signals.csv row every this many steps; 0: no signals.csv
  int log_fd_ = -1, csv_fd_ = -1;
  std::int64_t log_end_ = 0, csv_end_ = 0;      ///< bytes written, each ending on a whole event / row
  std::int64_t log_acked_ = 0, csv_acked_ = 0;  ///< ... at the last acknowledged step
  std::int64_t event_number_ = 0;
  std::int64_t start_utime_ = -1;  ///< wall-clock time of GO [us since the epoch]; -1 before
  std::int64_t next_ = 0;  ///< next step to acknowledge
  lockstep::StepMailbox<rths::desired_t> desired_;
  lockstep::StepMailbox<rths::command_t> command_;
  lockstep::StepMailbox<rths::measured_t> measured_;
  lockstep::StepMailbox<rths::current_t> current_;
  RawRing raw_desired_{}, raw_command_{}, raw_measured_{}, raw_current_{};
  lockstep::Bytes step_bytes_;  ///< the step's four events, written at once
  lockstep::AnswerCache ack_cache_;
  rths::ack_t ack_{};
  rths::handshake_t hs_{};
  std::set<std::pair<std::string, int>> handshakes_logged_;
};

}  // namespace rths::participants
