#include "lockstep/runtime.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

namespace rths::lockstep {

namespace {
double SecondsBetween(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

Participant::Participant(std::string name, RunIdentity id, Timing timing, lcm::LCM* lcm)
    : name_(std::move(name)), id_(std::move(id)), timing_(timing), lcm_(lcm) {
  created_ = SteadyClock::now();
  last_clock_ = created_;
  lcm_->subscribe(kChHandshake, &Participant::OnHandshake, this);
}

void Participant::PublishBytes(const char* channel, const Bytes& bytes) {
  if (lcm_->publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size())) != 0) {
    Fail(kExitLockstep, fmt::format("could not publish on {}", channel), false);
  }
}

void Participant::Republish(const char* channel, const AnswerCache& cache, std::int64_t k) {
  for (std::int64_t j = k; j <= k + 1; ++j) {
    if (const Bytes* b = cache.Get(j)) PublishBytes(channel, *b);
  }
}

void Participant::SendHandshake(Phase phase, std::int64_t k, const std::string& reason,
                                const std::vector<std::string>* roster) {
  hs_out_.run_id = id_.run_id;
  hs_out_.phase = phase;
  hs_out_.participant = name_;
  hs_out_.scenario_sha256 = id_.scenario_sha256;
  hs_out_.n_steps = id_.n_steps;
  hs_out_.dt_s = id_.dt_s;
  hs_out_.k = k;
  hs_out_.roster_names.clear();
  hs_out_.roster_sha256.clear();
  if (roster) {
    hs_out_.roster_names = *roster;
    hs_out_.roster_sha256.assign(roster->size(), id_.scenario_sha256);
  }
  hs_out_.n_roster = static_cast<std::int32_t>(hs_out_.roster_names.size());
  hs_out_.reason = reason;
  Encode(hs_out_, &hs_bytes_);
  lcm_->publish(kChHandshake, hs_bytes_.data(), static_cast<unsigned int>(hs_bytes_.size()));
}

void Participant::OnHandshake(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  if (finished_) return;
  if (hs_in_.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
  if (hs_in_.run_id != id_.run_id) {
    ++foreign_messages_;
    return;
  }
  if (hs_in_.participant == name_) return;  // our own message, looped back
  const auto now = SteadyClock::now();
  if (is_clock_) {
    if (hs_in_.phase == kAbort) {
      OnStop();
      Fail(kExitPeerAbort, fmt::format("{} aborted the run: {}", hs_in_.participant, hs_in_.reason),
           false);
      return;
    }
    OnHandshakeForClock(hs_in_, now);
    return;
  }
  HeardClock(now);
  switch (hs_in_.phase) {
    case kRequest:
      if (!running_) SendHandshake(kHello);
      break;
    case kGo:
      if (!running_) {
        running_ = true;
        OnGo();
      }
      break;
    case kAbort:
      OnStop();
      Fail(kExitPeerAbort, fmt::format("{} aborted the run: {}", hs_in_.participant, hs_in_.reason),
           false);
      break;
    case kDone:
      OnDone();
      SendHandshake(kBye, hs_in_.k);
      Finish();
      break;
    default:
      break;
  }
}

void Participant::Poll(SteadyClock::time_point now) {
  if (finished_ || is_clock_) return;
  if (!running_) {
    if (SecondsBetween(created_, now) > timing_.handshake_timeout_s) {
      Fail(kExitLockstep,
           fmt::format("no GO from the clock (integrator) within {:g} s of start-up; is it running "
                       "on the same LCM URL and run id?",
                       timing_.handshake_timeout_s),
           false);
    }
    return;
  }
  const double limit_s = timing_.timeout_ms * 1e-3 * (timing_.max_attempts + 2);
  if (SecondsBetween(last_clock_, now) > limit_s) {
    OnStop();
    Fail(kExitLockstep, fmt::format("the clock (integrator) has been silent for {:.3g} s", limit_s),
         false);
  }
}

void Participant::Fail(int exit_code, const std::string& reason, bool broadcast, std::int64_t k) {
  if (finished_) return;
  if (broadcast) SendHandshake(kAbort, k, reason);
  finished_ = true;
  running_ = false;
  exit_code_ = exit_code;
  error_ = reason;
}

void Participant::MaybeThrow(std::int64_t k) const {
  if (faults.throw_at == k) throw std::runtime_error("injected fault (test)");
  if (faults.crash_at == k) std::abort();
}

void Participant::Finish() {
  finished_ = true;
  running_ = false;
}

int RunLoop(lcm::LCM* lcm, const std::vector<Participant*>& participants) {
  constexpr int kPollMs = 5;
  for (;;) {
    bool all_done = true;
    for (Participant* p : participants) all_done = all_done && p->finished();
    if (all_done) break;
    const int r = lcm->handleTimeout(kPollMs);
    if (r < 0) {
      for (Participant* p : participants) {
        if (!p->finished()) std::fprintf(stderr, "%s: LCM receive failed\n", p->name().c_str());
      }
      return kExitLockstep;
    }
    const auto now = SteadyClock::now();
    for (Participant* p : participants) {
      if (!p->finished()) p->Poll(now);
    }
  }
  int first_own = 0, first_any = 0;
  for (Participant* p : participants) {
    const int c = p->exit_code();
    if (c != 0 && first_any == 0) first_any = c;
    if (c != 0 && c != kExitPeerAbort && first_own == 0) first_own = c;
  }
  return first_own != 0 ? first_own : first_any;
}

std::string CheckMulticastRoute() {
  // /proc/net/route: Iface Destination Gateway Flags RefCnt Use Metric Mask ... (hex, little-endian)
  std::ifstream in("/proc/net/route");
  if (!in) return "";  // not Linux-like; let LCM decide
  std::string line;
  std::getline(in, line);  // header
  const std::uint32_t group = 0x010000E0;  // 224.0.0.1 in /proc's byte order
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string iface;
    unsigned long dest = 0, gw = 0, flags = 0, refcnt = 0, use = 0, metric = 0, mask = 0;
    ss >> iface >> std::hex >> dest >> gw >> flags >> std::dec >> refcnt >> use >> metric >> std::hex >>
        mask;
    if (!ss) continue;
    if ((group & mask) == dest && (flags & 0x1)) return "";
  }
  return "this host has no route for multicast (224.0.0.0/4), so LCM's udpm transport cannot work.\n"
         "Fix (as root):  ip route add 224.0.0.0/4 dev lo\n"
         "or run in one process instead:  ./rths run --transport memq";
}

}  // namespace rths::lockstep
