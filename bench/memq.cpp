// bench-memq: the default scenario in this process (what `rths run --transport memq` runs: every
// participant on lockstep::InprocChannels), its steps/s beside the same group on LCM's memq:// (the
// former transport), write system calls per step, and the split of a step's CPU time into model
// (integrator, controller, plant), encode/decode, transport and logging, each timed off-line on the
// run's own inputs in the same process, side by side, because absolute times drift on shared
// machines. "other" is what the parts leave of the whole step: the lockstep bookkeeping.
//
//   build/bin/bench-memq [--scenario FILE] [--seconds S] [--repeat N]
//
// Also the MR damper step alone under the run's actuator motion: ARKODE's Dormand-Prince 5(4)
// (OdeMethod::kErk, the default) against CVODE's BDF (kBdf, the former default), both at the
// scenario's rtol, and its force error against CVODE at rtol 1e-12.
#include <fcntl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <lcm/lcm-cpp.hpp>

#include "control/feedforward.h"
#include "control/tracking_controller.h"
#include "io/event_log.h"
#include "io/mapped_log_file.h"
#include "io/signals_csv_writer.h"
#include "io/signals_row.h"
#include "lockstep/participant.h"
#include "lockstep/run_loop.h"
#include "lockstep/step_table.h"
#include "lockstep/transport.h"
#include "models/mr_damper.h"
#include "models/rig.h"
#include "models/structure_file.h"
#include "participants/factory.h"
#include "participants/group.h"
#include "participants/logger.h"
#include "rths/ack_t.hpp"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"
#include "scenario/scenario.h"
#include "signal/history.h"
#include "signal/stats.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double Seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using rths::signal::Median;  // timings: the middle one, or the mean of the two middle ones

// Write and read system calls of this process so far (/proc/self/io: syscw, syscr).
void SysCalls(long* writes, long* reads) {
  std::ifstream in("/proc/self/io");
  std::string key;
  long value;
  *writes = *reads = 0;
  while (in >> key >> value) {
    if (key == "syscw:") *writes = value;
    if (key == "syscr:") *reads = value;
  }
}

// One row of signals.csv.
struct Row {
  double r, u, y, f, i_cmd, i_eff, ground;
};
std::vector<Row> ReadCsv(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    double v[12];
    std::istringstream ss(line);
    for (double& x : v) {
      std::string cell;
      std::getline(ss, cell, ',');
      x = std::strtod(cell.c_str(), nullptr);
    }
    // k,t_s,r_mm,u_mm,u_ff_mm,u_fb_mm,y_mm,e_mm,f_kN,i_cmd_A,i_eff_A,ground_acc_mm_s2
    rows.push_back({v[2], v[3], v[6], v[8], v[9], v[10], v[11]});
  }
  return rows;
}

struct Run {
  double steps_per_s = 0, writes_per_step = 0, reads_per_step = 0, wall_per_step_us = 0;
};

// The default group in this process: on the in-process queue (RunGroupInProcess, what `rths run
// --transport memq` does), or `lcm_memq`: the same participants on one LCM memq:// instance, the
// transport of memq runs before lockstep::InprocChannels (side by side, for the ratio).
Run RunGroup(const rths::scenario::Scenario& s, const fs::path& out, bool lcm_memq = false) {
  fs::remove_all(out);
  fs::create_directories(out);
  long w0, r0, w1, r1;
  SysCalls(&w0, &r0);
  const auto t0 = Clock::now();
  std::vector<rths::participants::Outcome> outcomes;
  if (lcm_memq) {
    lcm::LCM lcm("memq://");
    std::vector<std::unique_ptr<rths::lockstep::Participant>> owned;
    std::vector<rths::lockstep::Participant*> group;
    for (std::string_view role : rths::lockstep::kBuildOrder) {
      owned.push_back(rths::participants::MakeParticipant(role, s, rths::participants::IdentityOf(s, 1), &lcm,
                                                          out.string()));
      group.push_back(owned.back().get());
    }
    rths::lockstep::RunLoop(&lcm, group);
    for (const auto* p : group) outcomes.push_back(rths::participants::OutcomeOf(*p));
  } else {
    outcomes = rths::participants::RunGroupInProcess({s}, 1, out.string());
  }
  const double wall = Seconds(t0);
  SysCalls(&w1, &r1);
  Run r;
  const double n = std::round(s.run.duration_s / s.run.dt_s);
  for (const auto& o : outcomes) {
    if (o.exit_code != 0) std::fprintf(stderr, "bench-memq: %s exited with %d: %s\n", o.role.c_str(), o.exit_code, o.message.c_str());
    if (o.role == "integrator" && o.stepping_s > 0) r.steps_per_s = n / o.stepping_s;
  }
  r.writes_per_step = static_cast<double>(w1 - w0) / n;
  r.reads_per_step = static_cast<double>(r1 - r0) / n;
  r.wall_per_step_us = wall / n * 1e6;
  return r;
}

// The parts of a step, each [us per step], timed on the rows of a run.
struct Split {
  double integrator = 0, controller = 0, plant = 0, codec = 0, transport = 0, logging = 0;
  double Sum() const { return integrator + controller + plant + codec + transport + logging; }
};

double TimeIntegrator(const rths::scenario::Scenario& s, const std::vector<Row>& rows) {
  const auto structure = rths::models::StructureFromScenario(s.structure);
  const auto cd = rths::models::CentralDifference::Make(structure, s.run.dt_s);
  auto state = rths::models::MakeState(cd);
  rths::control::ExtrapolationState ex{};
  double sink = 0;
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (k > 0) rths::models::Advance(cd, &state, rows[k - 1].ground, rows[k - 1].f);
    sink += rths::control::StepDerivatives(&ex, state.x[structure.actuator_dof], s.run.dt_s).rd;
  }
  const double us = Seconds(t0) / rows.size() * 1e6;
  if (sink == 12345.678) std::puts("");
  return us;
}

double TimeController(const rths::scenario::Scenario& s, const std::vector<Row>& rows) {
  auto law = rths::control::MakeTrackingController(s.controller, s.run.dt_s);
  rths::control::ExtrapolationState ex{};
  double sink = 0;
  const auto t0 = Clock::now();
  for (const Row& r : rows) {
    const auto d = rths::control::StepDerivatives(&ex, r.r, s.run.dt_s);
    sink += law->Step(d, {r.y, r.f, r.i_eff}).u_mm;
  }
  const double us = Seconds(t0) / rows.size() * 1e6;
  if (sink == 12345.678) std::puts("");
  return us;
}

double TimePlant(const rths::scenario::Scenario& s, const std::vector<Row>& rows) {
  auto rig = rths::models::MakeRig(s.plant, s.run.dt_s);
  double sink = 0;
  const auto t0 = Clock::now();
  for (std::size_t k = 1; k < rows.size(); ++k) {
    rig->Step(rows[k - 1].u, rows[k - 1].i_cmd);
    sink += rig->f_kN() + rig->y_mm();
  }
  const double us = Seconds(t0) / rows.size() * 1e6;
  if (sink == 12345.678) std::puts("");
  return us;
}

// The step's five messages, each encoded once and decoded by each of its receivers (desired_t by
// the controller, semiactive law and logger (and an "ideal" plant); command_t by the plant, logger and clock;
// measured_t by the controller, semiactive law, logger and clock; current_t by the plant, logger
// and clock; ack_t by the clock).
double TimeCodec(const std::vector<Row>& rows) {
  rths::desired_t d{};
  d.n_dof = 1;
  d.x_mm.resize(1);
  d.abs_acc_mm_s2.resize(1);
  rths::command_t c{};
  rths::measured_t m{};
  rths::current_t i{};
  rths::ack_t a{};
  a.participant = "logger";
  rths::lockstep::Bytes bd, bc, bm, bi, ba;
  double sink = 0;
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    d.k = c.k = m.k = i.k = a.k = static_cast<std::int64_t>(k);
    d.r_mm = rows[k].r, c.u_mm = rows[k].u, m.y_mm = rows[k].y, m.f_kN = rows[k].f, i.i_cmd_A = rows[k].i_cmd;
    rths::lockstep::Encode(d, &bd);
    rths::lockstep::Encode(c, &bc);
    rths::lockstep::Encode(m, &bm);
    rths::lockstep::Encode(i, &bi);
    rths::lockstep::Encode(a, &ba);
    for (int j = 0; j < 3; ++j) sink += d.decode(bd.data(), 0, static_cast<int>(bd.size()));
    for (int j = 0; j < 3; ++j) sink += c.decode(bc.data(), 0, static_cast<int>(bc.size()));
    for (int j = 0; j < 4; ++j) sink += m.decode(bm.data(), 0, static_cast<int>(bm.size()));
    for (int j = 0; j < 3; ++j) sink += i.decode(bi.data(), 0, static_cast<int>(bi.size()));
    sink += a.decode(ba.data(), 0, static_cast<int>(ba.size()));
  }
  const double us = Seconds(t0) / rows.size() * 1e6;
  if (sink == 12345.678) std::puts("");
  return us;
}

// Publish and dispatch of the step's five messages with the group's fan-out (the plant reads
// desired_t only when "ideal": 14 handled deliveries), on lockstep::InprocChannels or, `lcm_memq`,
// on LCM's memq://.
double TimeTransport(std::size_t steps, bool lcm_memq) {
  const std::pair<const char*, int> fanout[] = {{rths::lockstep::kChDesired, 3}, {rths::lockstep::kChCommand, 3},
                                                {rths::lockstep::kChMeasured, 4}, {rths::lockstep::kChCurrent, 3},
                                                {rths::lockstep::kChAck, 1}};
  std::vector<std::uint8_t> payload(100, 0x5a);
  long n_handled = 0;
  if (lcm_memq) {
    lcm::LCM lcm("memq://");
    struct Sink {
      long* n;
      void On(const lcm::ReceiveBuffer*, const std::string&) { ++*n; }
    } sink{&n_handled};
    for (const auto& [ch, n] : fanout)
      for (int j = 0; j < n; ++j) lcm.subscribe(ch, &Sink::On, &sink);
    const auto t0 = Clock::now();
    for (std::size_t k = 0; k < steps; ++k) {
      for (const auto& [ch, n] : fanout) {
        lcm.publish(ch, payload.data(), static_cast<unsigned>(payload.size()));
        lcm.handle();
      }
    }
    return Seconds(t0) / steps * 1e6;
  }
  rths::lockstep::InprocChannels bus;
  const auto on = [](void* n, const lcm::ReceiveBuffer*) { ++*static_cast<long*>(n); };
  for (const auto& [ch, n] : fanout)
    for (int j = 0; j < n; ++j) bus.Subscribe(ch, on, &n_handled);
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < steps; ++k) {
    for (const auto& [ch, n] : fanout) {
      bus.Publish(ch, payload.data(), static_cast<unsigned>(payload.size()));
      bus.HandleTimeout(0);
    }
  }
  return Seconds(t0) / steps * 1e6;
}

// What the logger does per step (lib/participants/logger.cpp), timed on this thread:
//   kQueued: the four events appended to log.lcm through its shared mapping (io::MappedLogFile) and
//            the row's numbers handed to io::SignalsCsvWriter's queue (its thread formats and
//            writes them); `cpu_us`: CPU time of both threads per step;
//   kInline: the same log, the row formatted by io::FormatSignalsRow on this thread, buffered and
//            written 64 kB at a time (the logger earlier in issue 46);
//   kFormer: the logger before issue 46: the events in one pwrite per step, the row by snprintf.
enum class Logging { kQueued, kInline, kFormer };
double CpuSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double TimeLogging(const std::vector<Row>& rows, const fs::path& dir, Logging how, double* cpu_us = nullptr,
                   std::int64_t* stalls = nullptr) {
  const fs::path log_path = dir / "bench_log.lcm";
  const int log = ::open(log_path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
  rths::io::MappedLogFile mapped(::dup(log), log_path.string());
  const fs::path csv_path = dir / "bench_signals.csv";
  std::unique_ptr<rths::io::SignalsCsvWriter> queued;
  if (how == Logging::kQueued) {
    queued = std::make_unique<rths::io::SignalsCsvWriter>(csv_path.string());
    mapped.PrefaultInBackground();
  }
  const int csv = how == Logging::kQueued ? -1 : ::open(csv_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::uint8_t> step, payload(80, 0x33);
  step.reserve(4096);
  std::string buf;
  buf.reserve(rths::io::SignalsCsvWriter::kFlushBytes + 512);
  std::int64_t log_end = 0, csv_end = 0, event = 0;
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    step.clear();
    for (const char* ch : {rths::lockstep::kChDesired, rths::lockstep::kChCommand, rths::lockstep::kChMeasured,
                           rths::lockstep::kChCurrent})
      rths::io::AppendEvent(&step, event++, static_cast<std::int64_t>(k) * 500, ch, payload.data(), payload.size());
    const Row& r = rows[k];
    const double t = static_cast<double>(k) * 0.0005;
    const std::array<double, 10> values{r.r, r.u, r.u, 0.0, r.y, r.r - r.y, r.f, r.i_cmd, r.i_eff, r.ground};
    if (how == Logging::kQueued) {
      mapped.Append(step.data(), step.size());
      queued->Add({static_cast<std::int64_t>(k), t, values});
      continue;
    }
    char row[400];
    std::size_t n = 0;
    if (how == Logging::kFormer) {
      log_end += ::pwrite(log, step.data(), step.size(), log_end);
      n = static_cast<std::size_t>(std::snprintf(row, sizeof row,
                                                 "%zu,%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                                                 k, t, r.r, r.u, r.u, 0.0, r.y, r.r - r.y, r.f, r.i_cmd, r.i_eff, r.ground));
    } else {
      mapped.Append(step.data(), step.size());
      n = rths::io::FormatSignalsRow(row, static_cast<std::int64_t>(k), t, values);
    }
    buf.append(row, n);
    if (buf.size() >= rths::io::SignalsCsvWriter::kFlushBytes) {
      csv_end += ::pwrite(csv, buf.data(), buf.size(), csv_end);
      buf.clear();
    }
  }
  const double us = Seconds(t0) / static_cast<double>(rows.size()) * 1e6;
  if (queued) {
    queued->Close();  // the writer's remaining rows count in the CPU time
    if (stalls) *stalls = queued->stalls();
  }
  if (cpu_us) *cpu_us = (CpuSeconds() - cpu0) / static_cast<double>(rows.size()) * 1e6;
  mapped.Close();
  ::close(log);
  if (csv >= 0) ::close(csv);
  return us;
}

struct DamperFigures {
  double erk_us = 0, bdf_us = 0, erk_rms = 0, erk_peak = 0, bdf_rms = 0, bdf_peak = 0;
};

// The damper alone, driven by the run's measured displacement (linear between samples).
struct SampledMotion {
  const std::vector<double>* x;
  double dt;
  std::size_t k = 0;
};
void MotionAt(double t, void* ctx, double* x, double* xdot) {
  const auto* m = static_cast<const SampledMotion*>(ctx);
  const double v = ((*m->x)[m->k + 1] - (*m->x)[m->k]) / m->dt;
  *x = (*m->x)[m->k] + v * (t - static_cast<double>(m->k) * m->dt);
  *xdot = v;
}
std::vector<double> DamperForces(const std::vector<double>& x, double dt, const std::vector<Row>& rows, double rtol,
                                 rths::models::OdeMethod method, double* us) {
  SampledMotion motion{&x, dt};
  rths::models::MrDamperStepper st(rths::models::MrDamperParams::Table3(), &MotionAt, &motion, rtol, method);
  rths::models::MrDamperState s;
  std::vector<double> f(x.size() - 1);
  const auto t0 = Clock::now();
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    motion.k = k;
    const double t = static_cast<double>(k) * dt;
    f[k] = st.ForceKn(t, rows[k].i_cmd, s);
    st.Advance(t, t + dt, rows[k].i_cmd, &s);
  }
  *us = Seconds(t0) / static_cast<double>(f.size()) * 1e6;
  return f;
}
void ErrorOf(const std::vector<double>& f, const std::vector<double>& ref, double* rms, double* peak) {
  double e2 = 0, r2 = 0, em = 0, rm = 0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    e2 += (f[k] - ref[k]) * (f[k] - ref[k]);
    r2 += ref[k] * ref[k];
    em = std::max(em, std::abs(f[k] - ref[k]));
    rm = std::max(rm, std::abs(ref[k]));
  }
  *rms = std::sqrt(e2 / r2);
  *peak = em / rm;
}
DamperFigures TimeDamper(const rths::scenario::Scenario& s, const std::vector<Row>& rows) {
  std::vector<double> x;
  for (const Row& r : rows) x.push_back(r.y);
  DamperFigures d;
  double ref_us;
  const auto ref = DamperForces(x, s.run.dt_s, rows, 1e-12, rths::models::OdeMethod::kBdf, &ref_us);
  const double rtol = s.plant.ode_rtol;
  const auto erk = DamperForces(x, s.run.dt_s, rows, rtol, rths::models::OdeMethod::kErk, &d.erk_us);
  const auto bdf = DamperForces(x, s.run.dt_s, rows, rtol, rths::models::OdeMethod::kBdf, &d.bdf_us);
  ErrorOf(erk, ref, &d.erk_rms, &d.erk_peak);
  ErrorOf(bdf, ref, &d.bdf_rms, &d.bdf_peak);
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-memq: the default scenario on memq:// in this process, its steps/s and their split"};
  double seconds = 20.0;
  int repeat = 3;
  std::string scenario_path;
  app.add_option("--seconds", seconds, "simulated seconds per run")->capture_default_str();
  app.add_option("--repeat", repeat, "runs (medians are printed)")->capture_default_str();
  app.add_option("--scenario", scenario_path, "scenario (default: scenarios/default.toml)");
  CLI11_PARSE(app, argc, argv);

  const fs::path bin = fs::read_symlink("/proc/self/exe").parent_path();
  if (scenario_path.empty()) scenario_path = (bin / "../../scenarios/default.toml").lexically_normal().string();
  const auto s = rths::scenario::LoadScenario(scenario_path, {fmt::format("run.duration_s={}", seconds)});
  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_bench_memq_{}", ::getpid());
  fs::create_directories(tmp);

  std::vector<double> rate, wall, writes, reads, integ, ctrl, plant, codec, transport, logging, logging_cpu,
      logging_inline, logging_old;
  std::int64_t csv_stalls = 0;
  std::vector<double> rate_lcm, transport_lcm, ratio;
  std::vector<double> erk_us, bdf_us;
  DamperFigures damper;
  for (int j = 0; j < repeat; ++j) {
    const Run r = RunGroup(s, tmp / "run");
    const Run r_lcm = RunGroup(s, tmp / "run_lcm", true);
    rate_lcm.push_back(r_lcm.steps_per_s);
    ratio.push_back(r.steps_per_s / r_lcm.steps_per_s);
    rate.push_back(r.steps_per_s);
    wall.push_back(r.wall_per_step_us);
    writes.push_back(r.writes_per_step);
    reads.push_back(r.reads_per_step);
    const std::vector<Row> rows = ReadCsv(tmp / "run" / "signals.csv");
    integ.push_back(TimeIntegrator(s, rows));
    ctrl.push_back(TimeController(s, rows));
    plant.push_back(TimePlant(s, rows));
    codec.push_back(TimeCodec(rows));
    transport.push_back(TimeTransport(rows.size(), false));
    transport_lcm.push_back(TimeTransport(rows.size(), true));
    double cpu_us = 0;
    std::int64_t stalls = 0;
    logging.push_back(TimeLogging(rows, tmp, Logging::kQueued, &cpu_us, &stalls));
    logging_cpu.push_back(cpu_us);
    csv_stalls += stalls;
    logging_inline.push_back(TimeLogging(rows, tmp, Logging::kInline));
    logging_old.push_back(TimeLogging(rows, tmp, Logging::kFormer));
    damper = TimeDamper(s, rows);
    erk_us.push_back(damper.erk_us);
    bdf_us.push_back(damper.bdf_us);
  }
  const double step_us = 1e6 / Median(rate);
  Split p{Median(integ), Median(ctrl), Median(plant), Median(codec), Median(transport), Median(logging)};
  std::printf("bench-memq: %s, %g s simulated (%.0f steps), %d runs, medians\n", scenario_path.c_str(), seconds,
              std::round(seconds / s.run.dt_s), repeat);
  std::printf("memq lockstep (1 process)   %10.0f steps/s = %.1fx real time (%.2f us/step; wall incl. setup %.2f)\n",
              Median(rate), Median(rate) * s.run.dt_s, step_us, Median(wall));
  std::printf("  on LCM's memq:// (former)   %10.0f steps/s; in-process queue / LCM memq = %.2fx (median of per-run ratios)\n",
              Median(rate_lcm), Median(ratio));
  std::printf("system calls per step        %6.2f write, %.2f read (/proc/self/io; the logger)\n",
              Median(writes), Median(reads));
  std::printf("split of a step (each part timed off-line on the run's inputs):\n");
  const auto line = [&](const char* name, double us) {
    std::printf("  %-34s %7.2f us  %5.1f %%\n", name, us, 100.0 * us / step_us);
  };
  line("model: integrator", p.integrator);
  line("model: controller", p.controller);
  line("model: plant (servo + damper)", p.plant);
  line("encode/decode (5 messages, 14 dec)", p.codec);
  line("transport (in-process queue)", p.transport);
  line("logging (mapped log + CSV queue)", p.logging);
  line("other (lockstep bookkeeping)", std::max(0.0, step_us - p.Sum()));
  std::printf("  logging, CPU of both threads         %7.2f us  (the writer thread formats the rows: %lld stalls "
              "on a full queue)\n",
              Median(logging_cpu), static_cast<long long>(csv_stalls));
  std::printf("  logging, row formatted on the step   %7.2f us  = %.2fx the current one\n", Median(logging_inline),
              Median(logging_inline) / p.logging);
  std::printf("  logging, former (pwrite + snprintf)  %7.2f us  = %.2fx the current one\n", Median(logging_old),
              Median(logging_old) / p.logging);
  const double model_us = p.integrator + p.controller + p.plant;
  std::printf("model-only bound 1 / (%.2f us) = %.0f steps/s; memq run / bound = %.2f (issue 46 goal >= 0.7: %s)\n",
              model_us, 1e6 / model_us, Median(rate) * model_us * 1e-6,
              Median(rate) * model_us * 1e-6 >= 0.7 ? "met" : "NOT met");
  std::printf("  transport on LCM's memq:// (former)  %7.2f us  = %.2fx the current one\n", Median(transport_lcm),
              Median(transport_lcm) / p.transport);
  std::printf("MR damper step alone, the run's motion and current, rtol %g:\n", s.plant.ode_rtol);
  std::printf("  ARKODE ERK DP5(4) (default) %7.2f us/step, force error vs CVODE 1e-12: RMS %.2e, peak %.2e\n",
              Median(erk_us), damper.erk_rms, damper.erk_peak);
  std::printf("  CVODE BDF (former default)  %7.2f us/step, force error vs CVODE 1e-12: RMS %.2e, peak %.2e\n",
              Median(bdf_us), damper.bdf_rms, damper.bdf_peak);
  std::printf("  ratio BDF / ERK             %7.2f\n", Median(bdf_us) / Median(erk_us));
  std::printf("target >= 50000 steps/s on memq: %s\n", Median(rate) >= 50000 ? "met" : "NOT met");
  fs::remove_all(tmp);
  return 0;
}
