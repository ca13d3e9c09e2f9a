// bench-lockstep: what one udpm delivery and one send cost in CPU, the bound that puts on a
// lockstep run of five processes on this machine's cores, and the lockstep rate on one port, on
// a port per channel and on memq, as a fraction of that bound. Everything is measured in one run,
// side by side, repeated (medians printed), because absolute times drift on shared machines.
//
//   build/bin/bench-lockstep [--seconds S] [--repeat N] [--round-trips N] [--scenario FILE]
//
// The bound. A step is CPU-bound, not latency-bound: its five messages (desired_t, command_t,
// measured_t, current_t, ack_t) are each sent once and delivered to sockets. On one port (LCM's
// udpm) every message reaches every socket of the run, the sender's included: 5 x 5 = 25
// deliveries, 14 of them to a subscriber (handled) and 11 to a process that drops them (ignored).
// With a port per channel (lockstep/transport.h) a message reaches only its subscribers: 14
// handled deliveries, on our own sockets read in the event loop's thread (no LCM receive thread).
// A loop of sends with no socket on the port gives the CPU of one send s; ping-pongs between two
// processes, with 0, 1 and 3 idle listeners added, the CPU (user + system, of every process) of
// one round trip, hence one handled delivery h and one ignored delivery i:
//   one port:          C(L idle listeners) per round trip = 2 s + 2 h + 2 (1 + L) i
//   port per channel:  C per round trip                   = 2 s + 2 h
// On a port per channel only 6 of the 14 deliveries wake their reader; the other 8 are read, with
// recvmmsg, when it wakes for the one that completes its step (docs/lockstep.md, "Wake-ups"). A
// ping-pong in which each side also sends one such message before each ping or pong gives the
// cost l of a delivery that wakes no one:  C_later = 2 s + 2 h + 2 (s + l).
// A step then costs 5 s + 14 h + 11 i (one port) or 5 s + 6 h + 8 l (port per channel) of CPU,
// and the bound is cores / that: the rate if the participants computed and logged for free.
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "external_run.h"
#include "lockstep/transport.h"
#include "signal/stats.h"

namespace fs = std::filesystem;
namespace ls = rths::lockstep;

namespace {

/// Handled deliveries per step: the subscribers of each step channel (docs/lockstep.md):
/// desired_t: controller, semiactive, logger (and an "ideal" plant); command_t: integrator, plant, logger;
/// measured_t: integrator, controller, semiactive, logger; current_t: integrator, plant, logger;
/// ack_t: integrator.
constexpr int kSendsPerStep = 5;
constexpr int kHandledPerStep = 3 + 3 + 4 + 3 + 1;
/// Of those, on a port per channel, the ones that wake their reader (clock: ack_t; controller,
/// semiactive: desired_t; plant: command_t, current_t; logger: measured_t) and the others.
constexpr int kWakingPerStep = 6;
constexpr int kLaterPerStep = kHandledPerStep - kWakingPerStep;
constexpr int kProcesses = 5;
constexpr int kIgnoredPerStepOnePort = kSendsPerStep * kProcesses - kHandledPerStep;

double CpuSeconds(int who) {
  rusage u{};
  ::getrusage(who, &u);
  return u.ru_utime.tv_sec + u.ru_utime.tv_usec * 1e-6 + u.ru_stime.tv_sec + u.ru_stime.tv_usec * 1e-6;
}

/// The two channels of the ping-pong (run channels, so a per-channel transport carries them), and
/// the two that carry a message that wakes no one, sent before each ping (to the echo) and each
/// pong (to the pinger).
constexpr const char* kPing = ls::kChDesired;
constexpr const char* kPong = ls::kChCommand;
constexpr const char* kLaterToEcho = ls::kChCurrent;
constexpr const char* kLaterToPinger = ls::kChMeasured;

/// A process that receives on one transport: echoes PING as PONG, or (a listener) only handles
/// what it subscribed to. `subscribe`: 0 nothing (an idle LCM listener: subscribed to a channel no
/// one sends), 1 PING (echo), 2 PING and PONG (a subscribed listener), 3 PING (echo) and, without
/// waking for it, kLaterToEcho; it sends a kLaterToPinger message before each PONG (per channel).
[[noreturn]] void Child(const std::string& url, bool per_channel, int subscribe) {
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  struct Ctx {
    lcm::LCM* lcm = nullptr;
    ls::UdpmChannels* ch = nullptr;
    bool echo = false;
  } ctx;
  ctx.echo = subscribe == 1 || subscribe == 3;
  static bool later = false;
  later = subscribe == 3;
  auto on = [](void* c, const lcm::ReceiveBuffer* rb) {
    auto* x = static_cast<Ctx*>(c);
    if (!x->echo) return;
    if (x->ch && later) x->ch->Publish(kLaterToPinger, rb->data, rb->data_size);
    if (x->ch) x->ch->Publish(kPong, rb->data, rb->data_size);
    else x->lcm->publish(kPong, rb->data, rb->data_size);
  };
  if (per_channel) {
    ls::UdpmChannels ch(*ls::UdpmUrl::Parse(url));
    ctx.ch = &ch;
    if (subscribe >= 1) ch.Subscribe(kPing, on, &ctx);
    if (subscribe == 2) ch.Subscribe(kPong, on, &ctx);
    if (subscribe == 3) ch.Subscribe(kLaterToEcho, [](void*, const lcm::ReceiveBuffer*) {}, nullptr, ls::Wake::kLater);
    for (;;) ch.HandleTimeout(1000);
  }
  lcm::LCM lcm(url);
  ctx.lcm = &lcm;
  struct Sub {
    void (*f)(void*, const lcm::ReceiveBuffer*);
    Ctx* c;
    void On(const lcm::ReceiveBuffer* rb, const std::string&) { f(c, rb); }
  } sub{on, &ctx};
  if (subscribe == 0) lcm.subscribe("BENCH_NOTHING", &Sub::On, &sub);
  if (subscribe >= 1) lcm.subscribe(kPing, &Sub::On, &sub);
  if (subscribe == 2) lcm.subscribe(kPong, &Sub::On, &sub);
  for (;;) lcm.handle();
}

/// CPU of one round trip [s], all processes together, with `idle` idle and `subscribed`
/// subscribed listeners besides the echo, `round_trips` of a 160-byte payload. `later` (per
/// channel): each side also sends a message the other does not wake for before each ping / pong.
double PingPongCpu(const std::string& url, bool per_channel, int idle, int subscribed, int round_trips,
                   bool later = false) {
  std::vector<pid_t> kids;
  auto spawn = [&](int subscribe) {
    const pid_t pid = ::fork();
    if (pid == 0) Child(url, per_channel, subscribe);
    kids.push_back(pid);
  };
  spawn(later ? 3 : 1);
  for (int i = 0; i < idle; ++i) spawn(0);
  for (int i = 0; i < subscribed; ++i) spawn(2);
  std::vector<std::uint8_t> payload(160, 0x5a);
  int got = 0;
  auto on = [](void* c, const lcm::ReceiveBuffer*) { ++*static_cast<int*>(c); };
  std::unique_ptr<ls::UdpmChannels> ch;
  std::unique_ptr<lcm::LCM> lcm;
  struct Sub {
    int* n;
    void On(const lcm::ReceiveBuffer*, const std::string&) { ++*n; }
  } sub{&got};
  if (per_channel) {
    ch = std::make_unique<ls::UdpmChannels>(*ls::UdpmUrl::Parse(url));
    ch->Subscribe(kPong, on, &got);
    if (later) ch->Subscribe(kLaterToPinger, [](void*, const lcm::ReceiveBuffer*) {}, nullptr, ls::Wake::kLater);
  } else {
    lcm = std::make_unique<lcm::LCM>(url);
    lcm->subscribe(kPong, &Sub::On, &sub);
  }
  auto publish = [&] {
    if (ch && later) ch->Publish(kLaterToEcho, payload.data(), 160);
    ch ? ch->Publish(kPing, payload.data(), 160) : lcm->publish(kPing, payload.data(), 160);
  };
  auto handle = [&](int ms) { return ch ? ch->HandleTimeout(ms) : lcm->handleTimeout(ms); };
  // Warm up until the echo answers, and the listeners have had time to join.
  while (got == 0) {
    publish();
    handle(20);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  while (handle(0) > 0) {
  }
  const double self0 = CpuSeconds(RUSAGE_SELF);
  // The children's CPU so far: from their own clock, read through /proc before and after.
  auto kids_cpu = [&] {
    double total = 0;
    const double tick = static_cast<double>(::sysconf(_SC_CLK_TCK));
    for (const pid_t pid : kids) {
      std::ifstream in(fmt::format("/proc/{}/stat", pid));
      std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::istringstream ss(all.substr(all.rfind(')') + 2));
      std::string field;
      unsigned long long ut = 0, st = 0;
      for (int f = 3; f <= 15 && ss >> field; ++f) {
        if (f == 14) ut = std::stoull(field);
        if (f == 15) st = std::stoull(field);
      }
      total += (ut + st) / tick;
    }
    return total;
  };
  const double before = kids_cpu();
  for (int i = 0; i < round_trips; ++i) {
    const int want = got + 1;
    publish();
    while (got < want) {
      if (handle(1000) <= 0) break;  // a lost datagram: count it as slow
    }
  }
  const double self = CpuSeconds(RUSAGE_SELF) - self0;
  const double children = kids_cpu() - before;
  for (const pid_t pid : kids) ::kill(pid, SIGTERM);
  for (const pid_t pid : kids) ::waitpid(pid, nullptr, 0);
  return (self + children) / round_trips;
}

/// CPU of one send [s] with no socket on the port: `sends` publications of a 160-byte payload.
double SendCpu(const std::string& url, bool per_channel, int sends) {
  std::vector<std::uint8_t> payload(160, 0x5a);
  std::unique_ptr<ls::UdpmChannels> ch;
  std::unique_ptr<lcm::LCM> lcm;
  if (per_channel) ch = std::make_unique<ls::UdpmChannels>(*ls::UdpmUrl::Parse(url));
  else lcm = std::make_unique<lcm::LCM>(url);
  const double t0 = CpuSeconds(RUSAGE_SELF);
  for (int i = 0; i < sends; ++i) {
    if (ch) ch->Publish(kPing, payload.data(), 160);
    else lcm->publish(kPing, payload.data(), 160);
  }
  return (CpuSeconds(RUSAGE_SELF) - t0) / sends;
}

struct Run {
  double steps_per_s = 0, cpu_per_step_s = 0;
};

Run LockstepRun(const fs::path& bin, const fs::path& scenario, const std::string& transport_args,
                const fs::path& out, std::int64_t steps) {
  fs::remove_all(out);
  const std::string cmd = fmt::format("{}/rths-run {} {} --out {} --quiet > /dev/null", bin.string(),
                                      scenario.string(), transport_args, out.string());
  const double cpu0 = CpuSeconds(RUSAGE_CHILDREN);
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "bench: %s failed\n", cmd.c_str());
    return {};
  }
  const auto j = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  return {j["steps_per_s"].get<double>(), (CpuSeconds(RUSAGE_CHILDREN) - cpu0) / static_cast<double>(steps)};
}

using rths::signal::Median;  // timings: the middle one, or the mean of the two middle ones

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-lockstep: udpm delivery and send CPU, the bound it sets, and lockstep steps/s on one "
               "port, a port per channel and memq, side by side"};
  double seconds = 5.0;
  int repeat = 3, round_trips = 10000;
  std::string scenario;
  app.add_option("--seconds", seconds, "simulated seconds per lockstep run")->capture_default_str();
  app.add_option("--repeat", repeat, "measurements of each kind (medians printed)")->capture_default_str();
  app.add_option("--round-trips", round_trips, "round trips per ping-pong")->capture_default_str();
  app.add_option("--scenario", scenario, "base scenario (default: scenarios/default.toml)");
  CLI11_PARSE(app, argc, argv);

  const fs::path bin = fs::read_symlink("/proc/self/exe").parent_path();
  if (scenario.empty()) scenario = (bin / "../../scenarios/default.toml").lexically_normal().string();
  if (const auto hint = ls::CheckMulticastRoute(); !hint.empty()) {
    std::fprintf(stderr, "bench: %s\n", hint.c_str());
    return 3;
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_bench_{}", ::getpid());
  fs::create_directories(tmp);
  std::string text;
  double dt = 0.0005;
  {
    std::ifstream in(scenario);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("duration_s", 0) == 0) line = fmt::format("duration_s = {}", seconds);
      if (line.rfind("dt_s", 0) == 0) dt = std::stod(line.substr(line.find('=') + 1));
      text += line + "\n";
    }
  }
  const auto steps = static_cast<std::int64_t>(std::llround(seconds / dt));
  const fs::path scen = tmp / "bench.toml";
  std::ofstream(scen) << text;

  const int port = 17600 + ::getpid() % 2000 * 8;
  const std::string one = fmt::format("udpm://239.255.76.67:{}?ttl=0", port);
  const std::string per = fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1", port);
  std::vector<double> c00, c10, c30, s_one, s_per, p00, p_later, r_one, r_per, r_memq, cpu_one, cpu_per, cpu_memq, gain;
  std::vector<double> r_mixed;  // mixed run (rths run --external plant) with rths-plant as the external plant
  for (int r = 0; r < repeat; ++r) {
    c00.push_back(PingPongCpu(one, false, 0, 0, round_trips));
    c10.push_back(PingPongCpu(one, false, 1, 0, round_trips));
    c30.push_back(PingPongCpu(one, false, 3, 0, round_trips));
    s_one.push_back(SendCpu(one, false, 4 * round_trips));
    p00.push_back(PingPongCpu(per, true, 0, 0, round_trips));
    p_later.push_back(PingPongCpu(per, true, 0, 0, round_trips, true));
    s_per.push_back(SendCpu(per, true, 4 * round_trips));
    const Run a = LockstepRun(bin, scen, "--transport udpm", tmp / "one", steps);
    const Run b = LockstepRun(bin, scen, "--transport udpm --port-per-channel", tmp / "per", steps);
    const Run m = LockstepRun(bin, scen, "--transport memq", tmp / "memq", steps);
    double mixed_rate = 0;
    if (rths_bench::RunWithExternalPlant(bin, "--quiet", scen, tmp / "mixed", "builtin", steps, dt, port + 16) == 0) {
      mixed_rate = nlohmann::json::parse(std::ifstream(tmp / "mixed" / "summary.json"))["steps_per_s"].get<double>();
    }
    r_mixed.push_back(mixed_rate);
    r_one.push_back(a.steps_per_s);
    r_per.push_back(b.steps_per_s);
    r_memq.push_back(m.steps_per_s);
    cpu_one.push_back(a.cpu_per_step_s);
    cpu_per.push_back(b.cpu_per_step_s);
    cpu_memq.push_back(m.cpu_per_step_s);
    gain.push_back(a.steps_per_s > 0 ? b.steps_per_s / a.steps_per_s : 0.0);
  }
  // One port: C(L) = 2 s + 2 h + 2 (1 + L) i.
  const double C00 = Median(c00), C10 = Median(c10), C30 = Median(c30);
  const double i = ((C10 - C00) + (C30 - C00) / 3.0) / 2.0 / 2.0;  // per message per idle listener
  const double s = Median(s_one);
  const double h = (C00 - 2 * s - 2 * i) / 2.0;
  const double step_one = kSendsPerStep * s + kHandledPerStep * h + kIgnoredPerStepOnePort * i;
  // Port per channel: C = 2 s' + 2 h'; C_later = C + 2 (s' + l).
  const double P00 = Median(p00), PL = Median(p_later);
  const double sp = Median(s_per), hp = (P00 - 2 * sp) / 2.0, lp = (PL - P00) / 2.0 - sp;
  const double step_per = kSendsPerStep * sp + kWakingPerStep * hp + kLaterPerStep * lp;
  const double bound_one = cores / step_one, bound_per = cores / step_per;
  const double one_rate = Median(r_one), per_rate = Median(r_per), memq_rate = Median(r_memq);
  auto us = [](double x) { return x * 1e6; };

  std::printf("bench-lockstep: %d repeats, medians; %u cores; %lld steps per lockstep run\n", repeat, cores,
              static_cast<long long>(steps));
  std::printf("ping-pong CPU per round trip (all processes, user + system), 160-byte payload:\n");
  std::printf("  LCM, one port: no listener %6.1f us, 1 idle listener %6.1f us, 3 idle listeners %6.1f us\n", us(C00),
              us(C10), us(C30));
  std::printf("  port per channel:          %6.1f us, with a message each way that wakes no one %6.1f us\n", us(P00),
              us(PL));
  std::printf("cost of one          send     handled delivery   ignored delivery   delivery read later\n");
  std::printf("  LCM, one port      %6.1f us   %6.1f us          %6.1f us                -\n", us(s), us(h), us(i));
  std::printf("  port per channel   %6.1f us   %6.1f us               -          %6.1f us\n", us(sp), us(hp), us(lp));
  std::printf("per step: %d sends; one port %d deliveries (%d handled, %d ignored); port per channel %d (%d wake "
              "their reader, %d are read later)\n",
              kSendsPerStep, kSendsPerStep * kProcesses, kHandledPerStep, kIgnoredPerStepOnePort, kHandledPerStep,
              kWakingPerStep, kLaterPerStep);
  std::printf("transport CPU per step: one port %6.1f us, port per channel %6.1f us\n", us(step_one), us(step_per));
  std::printf("bound (%u cores / transport CPU per step): one port %8.0f steps/s, port per channel %8.0f steps/s\n",
              cores, bound_one, bound_per);
  std::printf("lockstep udpm, one port          %8.0f steps/s = %.2f of its bound; CPU %6.1f us/step (all processes)\n",
              one_rate, one_rate / bound_one, us(Median(cpu_one)));
  std::printf("lockstep udpm, port per channel  %8.0f steps/s = %.2f of its bound; CPU %6.1f us/step; %.2f x one port "
              "(median of per-repeat ratios)\n",
              per_rate, per_rate / bound_per, us(Median(cpu_per)), Median(gain));
  std::printf("lockstep memq (1 process)        %8.0f steps/s = %.2f x port per channel; CPU %6.1f us/step\n", memq_rate,
              per_rate > 0 ? memq_rate / per_rate : 0.0, us(Median(cpu_memq)));
  const double mixed_rate = Median(r_mixed);
  std::printf("lockstep mixed (external plant)  %8.0f steps/s = %.2f x udpm one port (rths-plant on udpm, the rest "
              "in 1 process)\n",
              mixed_rate, one_rate > 0 ? mixed_rate / one_rate : 0.0);
  std::printf("per repeat (one port / port per channel / memq / mixed steps/s):");
  for (int r = 0; r < repeat; ++r) std::printf(" %.0f/%.0f/%.0f/%.0f", r_one[r], r_per[r], r_memq[r], r_mixed[r]);
  std::printf("\ntarget >= 8000 steps/s on udpm with a port per channel: %s\n", per_rate >= 8000 ? "met" : "NOT met");
  fs::remove_all(tmp);
  return 0;
}
