#include "lockstep/run_loop.h"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>

namespace rths::lockstep {

int RunLoop(lcm::LCM* lcm, const std::vector<Participant*>& participants, const volatile std::sig_atomic_t* stop) {
  return RunLoopWith([lcm](int timeout_ms) { return lcm->handleTimeout(timeout_ms); }, participants, stop);
}

int RunLoopWith(const std::function<int(int)>& handle, const std::vector<Participant*>& participants,
                const volatile std::sig_atomic_t* stop) {
  constexpr int kPollMs = 5;
  for (;;) {
    if (stop && *stop) {
      for (Participant* p : participants) p->Interrupt("stopped by a signal (SIGINT or SIGTERM)");
    }
    bool all_done = true;
    for (Participant* p : participants) all_done = all_done && p->finished();
    if (all_done) break;
    // A paced clock waiting for its next release: handle what has arrived, then sleep to the
    // release on an absolute deadline (no drift, no millisecond rounding).
    auto release = SteadyClock::time_point::max();
    for (const Participant* p : participants) release = std::min(release, p->ReleaseAt());
    if (release != SteadyClock::time_point::max()) {
      int handled = 0;
      while (handled < 64 && handle(0) > 0) {
        ++handled;
        const auto now = SteadyClock::now();
        for (Participant* p : participants) p->Tick(now, false);
      }
      // steady_clock is CLOCK_MONOTONIC (libstdc++ on Linux); a release already past returns at once.
      // With a spin ([realtime] spin_us): sleep to `spin` before the release, then busy-wait.
      SteadyClock::duration spin{};
      for (const Participant* p : participants) spin = std::max(spin, p->SpinBeforeRelease());
      const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>((release - spin).time_since_epoch()).count();
      const timespec ts{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
      while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        if (stop && *stop) break;
      }
      while (spin.count() > 0 && SteadyClock::now() < release && !(stop && *stop)) {
      }
      const auto now = SteadyClock::now();
      for (Participant* p : participants) p->Tick(now, true);
      continue;
    }
    // Wake up for the next deadline (a re-request, a held message), at most kPollMs away.
    auto deadline = SteadyClock::now() + std::chrono::milliseconds(kPollMs);
    for (const Participant* p : participants) deadline = std::min(deadline, p->NextDeadline());
    const auto wait = std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now()).count();
    errno = 0;
    int r = handle(static_cast<int>(std::clamp<std::int64_t>(wait, 0, kPollMs)));
    if (r < 0 && errno == EINTR) r = 0;  // a signal (e.g. SIGTERM: handled through `stop`)
    if (r < 0) {
      for (Participant* p : participants) {
        if (!p->finished()) std::fprintf(stderr, "%s: LCM receive failed\n", p->name().c_str());
      }
      return kExitLockstep;
    }
    const auto now = SteadyClock::now();
    for (Participant* p : participants) p->Tick(now, r == 0);
  }
  int first_own = 0, first_any = 0;
  for (Participant* p : participants) {
    const int c = p->exit_code();
    if (c != 0 && first_any == 0) first_any = c;
    if (c != 0 && c != kExitPeerAbort && first_own == 0) first_own = c;
  }
  return first_own != 0 ? first_own : first_any;
}

}  // namespace rths::lockstep
