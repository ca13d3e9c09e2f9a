#pragma once
/// @file One mailbox per per-step channel, addressed by channel code: what a participant built from
/// the step table (StepParticipant, ClockParticipant) receives.
#include <cstdint>

#include "lockstep/mailbox.h"
#include "lockstep/protocol.h"
#include "rths/ack_t.hpp"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::lockstep {

struct StepMailboxes {
  StepMailbox<rths::desired_t> desired;
  StepMailbox<rths::command_t> command;
  StepMailbox<rths::measured_t> measured;
  StepMailbox<rths::current_t> current;
  StepMailbox<rths::ack_t> ack;

  /// Adds a message of `channel`; *k is its step (valid unless kBad or kForeign).
  Put Add(Channel channel, const lcm::ReceiveBuffer* rbuf, std::int64_t run_id, std::int64_t* k) {
    Put put = Put::kBad;
    switch (channel) {
      case kDesired: put = desired.Add(rbuf, run_id), *k = desired.last_k(); break;
      case kCommand: put = command.Add(rbuf, run_id), *k = command.last_k(); break;
      case kMeasured: put = measured.Add(rbuf, run_id), *k = measured.last_k(); break;
      case kCurrent: put = current.Add(rbuf, run_id), *k = current.last_k(); break;
      case kAck: put = ack.Add(rbuf, run_id), *k = ack.last_k(); break;
      default: break;
    }
    return put;
  }
  /// Whether the message of step k on `channel` is in.
  bool Has(Channel channel, std::int64_t k) const {
    switch (channel) {
      case kDesired: return desired.Get(k) != nullptr;
      case kCommand: return command.Get(k) != nullptr;
      case kMeasured: return measured.Get(k) != nullptr;
      case kCurrent: return current.Get(k) != nullptr;
      case kAck: return ack.Get(k) != nullptr;
      default: return false;
    }
  }
};

/// The decoded inputs of one step, one per channel (nullptr: not an input of this role, or of a
/// step before 0). Handed to a role's step function.
struct StepInputs {
  const rths::desired_t* desired = nullptr;
  const rths::command_t* command = nullptr;
  const rths::measured_t* measured = nullptr;
  const rths::current_t* current = nullptr;
};

}  // namespace rths::lockstep
