#include "io/run_signals.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::io {

std::size_t RunSignals::steps() const { return columns.empty() ? 0 : columns.front().values.size(); }

const SignalColumn* RunSignals::Find(std::string_view name) const {
  for (const auto& c : columns)
    if (c.name == name) return &c;
  return nullptr;
}

const SignalColumn& RunSignals::At(std::string_view name) const {
  if (const auto* c = Find(name)) return *c;
  std::string names;
  for (const auto& c : columns) names += (names.empty() ? "" : ", ") + c.name;
  throw Error("run signals", fmt::format("no column '{}' (columns: {})", name, names));
}

namespace {

/// Appends an empty column with room for `n` values; returns its index.
std::size_t AddColumn(RunSignals* s, std::string name, std::string unit, std::string description, std::size_t n) {
  s->columns.push_back({std::move(name), std::move(unit), std::move(description), {}});
  s->columns.back().values.reserve(n);
  return s->columns.size() - 1;
}

/// The fixed columns' indices in RunSignals::columns, and where the per-DOF blocks start.
struct Layout {
  std::size_t k, t, r, rd, rdd, rddd, acc_prev, vel_prev, ground, x0, a0;
  std::size_t u, u_ff, u_fb, y, e, f, i_eff, i_cmd, f_des;
};

/// Adds every column but the adaptive coefficients, empty with room for n steps, in the order of
/// RunSignals::columns.
Layout AddColumns(RunSignals* s, int n_dof, std::size_t n) {
  Layout l{};
  l.k = AddColumn(s, "k", "", "step index k (t_k = k dt)", n);
  l.t = AddColumn(s, "t_s", "s", "time of sample k, t_k = k dt", n);
  l.r = AddColumn(s, "r_mm", "mm", "desired actuator displacement r_k (Eq. 20-22 predictions in rd/rdd/rddd)", n);
  l.rd = AddColumn(s, "rd_mm_s", "mm/s", "predicted desired velocity r'_k (Eq. 21)", n);
  l.rdd = AddColumn(s, "rdd_mm_s2", "mm/s^2", "extrapolated desired acceleration r''_k (Eq. 20)", n);
  l.rddd = AddColumn(s, "rddd_mm_s3", "mm/s^3", "predicted desired jerk r'''_k (Eq. 22)", n);
  l.acc_prev = AddColumn(s, "acc_prev_mm_s2", "mm/s^2", "central-difference acceleration one step back a_{k-1}", n);
  l.vel_prev = AddColumn(s, "vel_prev_mm_s", "mm/s", "central-difference velocity one step back v_{k-1}", n);
  l.ground = AddColumn(s, "ground_acc_mm_s2", "mm/s^2", "ground acceleration at sample k (0 in predefined mode)", n);
  l.x0 = s->columns.size();
  for (int i = 1; i <= n_dof; ++i)
    AddColumn(s, fmt::format("x{}_mm", i), "mm",
              fmt::format("structure displacement of DOF {} relative to ground at sample k", i), n);
  l.a0 = s->columns.size();
  for (int i = 1; i <= n_dof; ++i)
    AddColumn(s, fmt::format("abs_acc{}_mm_s2", i), "mm/s^2",
              fmt::format("absolute acceleration of DOF {} at sample k-1", i), n);
  l.u = AddColumn(s, "u_mm", "mm", "actuator command u_k = u_FF + u_FB (held over [t_k, t_k+1))", n);
  l.u_ff = AddColumn(s, "u_ff_mm", "mm", "feedforward part of the command u_FF", n);
  l.u_fb = AddColumn(s, "u_fb_mm", "mm", "feedback part of the command u_FB", n);
  l.y = AddColumn(s, "y_mm", "mm", "measured actuator displacement y_k (with sensor noise, if any)", n);
  l.e = AddColumn(s, "e_mm", "mm", "tracking error e_k = r_k - y_k", n);
  l.f = AddColumn(s, "f_kN", "kN", "measured specimen (damper) force f_k (with sensor noise, if any)", n);
  l.i_eff = AddColumn(s, "i_eff_A", "A", "effective damper current at t_k (measured_t.current_A)", n);
  l.i_cmd = AddColumn(s, "i_cmd_A", "A", "damper current command i_k (held over [t_k, t_k+1))", n);
  l.f_des = AddColumn(s, "f_desired_kN", "kN", "clipped-optimal nominal force for one damper (0 for other modes)", n);
  return l;
}

/// Appends step j of `log` to every column of `l`. Throws rths::Error if its n_dof is not n_dof.
void AppendStep(const RunLog& log, std::size_t j, int n_dof, const Layout& l, RunSignals* s) {
  const auto& d = log.desired[j];
  const auto& c = log.command[j];
  const auto& m = log.measured[j];
  const auto& i = log.current[j];
  if (d.n_dof != n_dof || static_cast<int>(d.x_mm.size()) != n_dof || static_cast<int>(d.abs_acc_mm_s2.size()) != n_dof)
    throw Error(log.source,
                fmt::format("RTHS_DESIRED k = {}: n_dof = {}, but step 0 has n_dof = {}", j, d.n_dof, n_dof));
  const auto put = [&](std::size_t col, double v) { s->columns[col].values.push_back(v); };
  put(l.k, static_cast<double>(j));
  put(l.t, static_cast<double>(j) * s->dt_s);
  put(l.r, d.r_mm);
  put(l.rd, d.rd_mm_s);
  put(l.rdd, d.rdd_mm_s2);
  put(l.rddd, d.rddd_mm_s3);
  put(l.acc_prev, d.acc_prev_mm_s2);
  put(l.vel_prev, d.vel_prev_mm_s);
  put(l.ground, d.ground_acc_mm_s2);
  for (int q = 0; q < n_dof; ++q) {
    put(l.x0 + static_cast<std::size_t>(q), d.x_mm[static_cast<std::size_t>(q)]);
    put(l.a0 + static_cast<std::size_t>(q), d.abs_acc_mm_s2[static_cast<std::size_t>(q)]);
  }
  put(l.u, c.u_mm);
  put(l.u_ff, c.u_ff_mm);
  put(l.u_fb, c.u_fb_mm);
  put(l.y, m.y_mm);
  put(l.e, d.r_mm - m.y_mm);
  put(l.f, m.f_kN);
  put(l.i_eff, m.current_A);
  put(l.i_cmd, i.i_cmd_A);
  put(l.f_des, i.f_desired_kN);
}

/// An adaptive controller's coefficients (command_t.adapt: ats 3, ambc 4), one column each, at the
/// end so that every other column keeps its place; NaN at a step that reported fewer.
void AddAdaptColumns(const RunLog& log, std::size_t n, RunSignals* s) {
  int n_adapt = 0;
  for (std::size_t j = 0; j < n; ++j) n_adapt = std::max(n_adapt, std::min(log.command[j].n_adapt, 4));
  static constexpr const char* kAdaptNames[4] = {"a0", "a1_s", "a2_s2", "a3_s3"};
  static constexpr const char* kAdaptUnits[4] = {"", "s", "s^2", "s^3"};
  for (int q = 0; q < n_adapt; ++q) {
    const std::size_t col = AddColumn(s, kAdaptNames[q], kAdaptUnits[q],
                                      fmt::format("adaptive controller's coefficient of the target's derivative {} "
                                                  "(u = sum a_i x_t^(i); command_t.adapt[{}])",
                                                  q, q),
                                      n);
    for (std::size_t j = 0; j < n; ++j) {
      const auto& c = log.command[j];
      s->columns[col].values.push_back(q < c.n_adapt && q < static_cast<int>(c.adapt.size()) ? c.adapt[q]
                                                                                              : std::nan(""));
    }
  }
}

/// Several actuators (desired_t.n_act > 0 at step 0: the maRTHS benchmark): each actuator's target,
/// command and stroke, and the interface forces, one column each, at the end; NaN at a step that
/// carries fewer.
void AddActuatorColumns(const RunLog& log, std::size_t n, RunSignals* s) {
  if (n == 0) return;
  const auto at = [](const std::vector<double>& v, std::int32_t count, int q) {
    return q < count && q < static_cast<int>(v.size()) ? v[static_cast<std::size_t>(q)] : std::nan("");
  };
  for (int q = 0; q < log.desired[0].n_act; ++q) {
    const std::size_t r = AddColumn(s, fmt::format("r_act{}_mm", q + 1), "mm",
                                    fmt::format("actuator {}'s target r_k (desired_t.r_act_mm)", q + 1), n);
    const std::size_t u = AddColumn(s, fmt::format("u_act{}_mm", q + 1), "mm",
                                    fmt::format("actuator {}'s command u_k (command_t.u_act_mm)", q + 1), n);
    const std::size_t y = AddColumn(s, fmt::format("y_act{}_mm", q + 1), "mm",
                                    fmt::format("actuator {}'s measured stroke y_k (measured_t.y_act_mm)", q + 1), n);
    for (std::size_t j = 0; j < n; ++j) {
      s->columns[r].values.push_back(at(log.desired[j].r_act_mm, log.desired[j].n_act, q));
      s->columns[u].values.push_back(at(log.command[j].u_act_mm, log.command[j].n_act, q));
      s->columns[y].values.push_back(at(log.measured[j].y_act_mm, log.measured[j].n_act, q));
    }
  }
  for (int q = 0; q < log.measured[0].n_iface; ++q) {
    const std::size_t f = AddColumn(s, fmt::format("f_iface{}", q + 1), "N or N m",
                                    fmt::format("the specimen's force on interface DOF {} of the numerical "
                                                "substructure (measured_t.f_iface; maRTHS: DOFs 27, 21, 29)",
                                                q + 1),
                                    n);
    for (std::size_t j = 0; j < n; ++j) {
      s->columns[f].values.push_back(at(log.measured[j].f_iface, log.measured[j].n_iface, q));
    }
  }
}

}  // namespace

RunSignals SignalsFromRunLog(const RunLog& log, double dt_s) {
  if (!std::isfinite(dt_s) || dt_s <= 0.0)
    throw Error(log.source, fmt::format("dt_s = {} is not a step (must be finite and > 0 s)", dt_s));
  RunSignals s;
  s.dt_s = dt_s;
  const std::int64_t n_steps = log.CompleteSteps();
  const std::size_t n = static_cast<std::size_t>(n_steps > 0 ? n_steps : 0);
  const int n_dof = n > 0 ? log.desired[0].n_dof : 0;
  const Layout layout = AddColumns(&s, n_dof, n);
  for (std::size_t j = 0; j < n; ++j) AppendStep(log, j, n_dof, layout, &s);
  AddAdaptColumns(log, n, &s);
  AddActuatorColumns(log, n, &s);
  return s;
}

RunSignals ReadRunSignals(const std::filesystem::path& run_dir) {
  const std::string path = (run_dir / "log.lcm").string();
  const RunLog log = ReadRunLog(path);
  const double dt_s = log.StepS();
  if (!(dt_s > 0.0)) throw Error(path, "no step size: no handshake in the log carries dt_s");
  return SignalsFromRunLog(log, dt_s);
}

}  // namespace rths::io
