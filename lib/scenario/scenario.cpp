/// @file Scenario parsing (toml++) and validation. See scenario.h and docs/scenarios.md.
///
/// Two passes, as the header promises: a reader maps tables and keys 1:1 onto the structs,
/// rejecting unknown keys and wrong types; then one validator per struct checks ranges and
/// cross-field limits. Every failure is an rths::Error(where = "<file>: <dotted.key>", what).
#include "scenario/scenario.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/error.h"

namespace rths::scenario {

using control::ControllerConfig;
using control::SemiactiveConfig;
using lockstep::FaultConfig;
using lockstep::LockstepConfig;
using lockstep::RealtimeConfig;
using models::PhysicalActuatorConfig;
using models::PlantConfig;
using models::ServoModel3;
using models::ServoPreset;
using models::StructureConfig;
using models::UnmodelledConfig;
using safety::SafetyConfig;
using signal::SignalSpec;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The name used in messages for the scenario's source.
std::string DisplayName(const std::string& path) { return path.empty() ? "<scenario text>" : path; }

/// Comma-separated list, each item wrapped in `quote`.
std::string JoinList(const std::vector<std::string_view>& items, std::string_view quote = "") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ", ";
    out += quote;
    out += items[i];
    out += quote;
  }
  return out;
}

std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// The allowed name closest to `name`, or "" if none is close (a typo or a missing/extra suffix).
std::string_view ClosestName(std::string_view name, const std::vector<std::string_view>& allowed) {
  std::string_view best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (std::string_view candidate : allowed) {
    std::size_t d = EditDistance(name, candidate);
    const bool close = d <= std::max<std::size_t>(2, name.size() / 3);
    const bool affix = name.size() >= 3 && (candidate.starts_with(name) || name.starts_with(candidate));
    if (!close && !affix) continue;
    if (affix) d = std::min<std::size_t>(d, 1);  // "noise_y_mm" -> "noise_y_mm_rms"
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

/// "string \"abc\"", "float 2.5", "table", ... for type errors.
std::string DescribeNode(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return fmt::format("string \"{}\"", node.as_string()->get());
    case toml::node_type::integer:
      return fmt::format("integer {}", node.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt::format("float {}", node.as_floating_point()->get());
    case toml::node_type::boolean:
      return fmt::format("boolean {}", node.as_boolean()->get());
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

// ---------------------------------------------------------------------------------------
// Pass 1: TOML -> structs (keys and types).

/// One TOML table mapped onto a struct. Each read declares its key; Finish() rejects the rest.
class Section {
 public:
  Section(std::string file, const toml::table* table, std::string prefix)
      : file_(std::move(file)), table_(table), prefix_(std::move(prefix)) {}

  void Number(std::string_view key, double* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    if (const auto* f = node->as_floating_point()) {
      *out = f->get();
    } else if (const auto* i = node->as_integer()) {
      *out = static_cast<double>(i->get());
    } else {
      WrongType(key, "a number (float or integer)", *node);
    }
  }

  template <typename Int>
  void Integer(std::string_view key, Int* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    const auto* i = node->as_integer();
    if (i == nullptr) WrongType(key, "an integer", *node);
    const std::int64_t v = i->get();
    bool fits = true;
    if constexpr (std::is_unsigned_v<Int>) {
      fits = v >= 0 && static_cast<std::uint64_t>(v) <= std::numeric_limits<Int>::max();
    } else {
      fits = v >= std::numeric_limits<Int>::min() && v <= std::numeric_limits<Int>::max();
    }
    if (!fits) {
      Fail(key, fmt::format("{} is out of range [{}, {}]", v, std::numeric_limits<Int>::min(),
                            std::numeric_limits<Int>::max()));
    }
    *out = static_cast<Int>(v);
  }

  void String(std::string_view key, std::string* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    const auto* s = node->as_string();
    if (s == nullptr) WrongType(key, "a string", *node);
    *out = s->get();
  }

  void Bool(std::string_view key, bool* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    const auto* b = node->as_boolean();
    if (b == nullptr) WrongType(key, "a boolean (true or false)", *node);
    *out = b->get();
  }

  /// A ServoModel3: a preset name or an inline table {K, p, b, c} (all four required).
  void Servo(std::string_view key, ServoModel3* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    constexpr std::string_view kExpected =
        "a preset name (\"0.0A\", \"2.5A\", \"avg\") or a table {K = ..., p = ..., b = ..., c = ...}";
    if (const auto* s = node->as_string()) {
      try {
        *out = ServoPreset(s->get());
      } catch (const Error&) {
        Fail(key, fmt::format("unknown servo model preset \"{}\" (allowed: \"0.0A\", \"2.5A\", \"avg\", "
                              "or a table {{K = ..., p = ..., b = ..., c = ...}})",
                              s->get()));
      }
      return;
    }
    const auto* table = node->as_table();
    if (table == nullptr) WrongType(key, kExpected, *node);
    Section model(file_, table, Dotted(key) + ".");
    ServoModel3 m;
    m.name = "custom";
    for (auto [name, field] : {std::pair{"K", &m.K}, {"p", &m.p}, {"b", &m.b}, {"c", &m.c}}) {
      model.Number(name, field);
    }
    model.Finish();
    for (std::string_view name : {"K", "p", "b", "c"}) {
      if (table->get(name) == nullptr) {
        model.Fail(name, "missing (a servo model table needs all of K, p, b, c, each > 0)");
      }
    }
    *out = m;
  }

  /// A sub-table (absent -> an empty section, so every key keeps its default).
  Section Sub(std::string_view key) {
    const toml::node* node = Declare(key, true);
    const toml::table* table = nullptr;
    if (node != nullptr) {
      table = node->as_table();
      if (table == nullptr) WrongType(key, "a table", *node);
    }
    return Section(file_, table, Dotted(key) + ".");
  }

  /// true if the table exists in the file (a Sub() of an absent table is empty).
  bool Present() const { return table_ != nullptr; }
  /// true if the table has `key` (declared or not).
  bool Has(std::string_view key) const { return table_ != nullptr && table_->get(key) != nullptr; }

  /// Rejects every key that no read declared, suggesting the closest declared one.
  void Finish() const {
    if (table_ == nullptr) return;
    for (auto&& [k, node] : *table_) {
      const std::string_view name = k.str();
      if (std::find(keys_.begin(), keys_.end(), name) != keys_.end() ||
          std::find(tables_.begin(), tables_.end(), name) != tables_.end()) {
        continue;
      }
      const bool is_table = node.is_table() || node.is_array_of_tables();
      std::vector<std::string_view> allowed;
      std::string list;
      if (is_table) {
        allowed = tables_;
        list = tables_.empty() ? "no tables allowed here" : "allowed tables: " + JoinList(tables_);
        if (!keys_.empty()) list += "; allowed keys: " + JoinList(keys_);
      } else {
        allowed = keys_;
        allowed.insert(allowed.end(), tables_.begin(), tables_.end());
        list = "allowed: " + JoinList(allowed);
      }
      std::string problem = fmt::format("unknown {} ({})", is_table ? "table" : "key", list);
      if (std::string_view close = ClosestName(name, allowed); !close.empty()) {
        problem += fmt::format("; did you mean \"{}{}\"?", prefix_, close);
      }
      Fail(name, problem);
    }
  }

  [[noreturn]] void Fail(std::string_view key, std::string problem) const {
    throw Error(fmt::format("{}: {}", file_, Dotted(key)), std::move(problem));
  }

 private:
  std::string Dotted(std::string_view key) const { return prefix_ + std::string(key); }

  const toml::node* Declare(std::string_view key, bool is_table) {
    (is_table ? tables_ : keys_).push_back(key);
    return table_ == nullptr ? nullptr : table_->get(key);
  }

  [[noreturn]] void WrongType(std::string_view key, std::string_view expected, const toml::node& found) const {
    Fail(key, fmt::format("expected {}, found {}", expected, DescribeNode(found)));
  }

  std::string file_;
  const toml::table* table_;
  std::string prefix_;
  std::vector<std::string_view> keys_;    // declared scalar keys (string literals: static storage)
  std::vector<std::string_view> tables_;  // declared sub-tables
};

/// The physical actuator's keys, in file order, with where each goes (read, validate, write).
std::vector<std::pair<const char*, double*>> PhysicalFields(PhysicalActuatorConfig* p) {
  return {{"area_m2", &p->area_m2},
          {"supply_pressure_Pa", &p->supply_pressure_Pa},
          {"volume_m3", &p->volume_m3},
          {"piston_mass_kg", &p->piston_mass_kg},
          {"piston_damping_N_s_m", &p->piston_damping_N_s_m},
          {"valve_hz", &p->valve_hz},
          {"valve_zeta", &p->valve_zeta},
          {"kq_m3_s", &p->kq_m3_s},
          {"kp_per_m", &p->kp_per_m},
          {"beta_Pa", &p->beta_Pa},
          {"leakage_m3_s_Pa", &p->leakage_m3_s_Pa}};
}

/// The Spencer damper's keys ([plant.damper]), in file order: every MrDamperParams field.
std::vector<std::pair<const char*, double*>> DamperFields(models::MrDamperParams* d) {
  return {{"alpha_a", &d->alpha_a}, {"alpha_b", &d->alpha_b}, {"alpha_c", &d->alpha_c},
          {"c0_a", &d->c0_a},       {"c0_b", &d->c0_b},       {"c0_c", &d->c0_c},
          {"c1_a", &d->c1_a},       {"c1_b", &d->c1_b},       {"c1_c", &d->c1_c},
          {"beta_a", &d->beta_a},   {"beta_b", &d->beta_b},   {"beta_c", &d->beta_c},
          {"gamma_a", &d->gamma_a}, {"gamma_b", &d->gamma_b}, {"gamma_c", &d->gamma_c},
          {"A", &d->A},             {"n", &d->n},             {"k0", &d->k0},
          {"k1", &d->k1},           {"x0", &d->x0}};
}

/// One parameter of an effect of the library: its key, where it goes, whether the table must
/// give it.
struct EffectKey {
  const char* key;
  double* field;
  bool required;
};

/// The keys of each effect present in `e` (the contract's parameter names, models/rig_effects.h),
/// in file order; effects that are off have no keys. `e` must outlive the result.
std::vector<std::pair<const char*, std::vector<EffectKey>>> EffectKeys(models::EffectSet* e) {
  std::vector<std::pair<const char*, std::vector<EffectKey>>> out;
  if (e->pure_delay) out.push_back({"pure_delay", {{"tau_ms", &e->pure_delay->tau_ms, true}}});
  if (e->gain_error) out.push_back({"gain_error", {{"gain", &e->gain_error->gain, true}}});
  if (e->load_coupling)
    out.push_back({"load_coupling", {{"compliance_mm_per_kN", &e->load_coupling->compliance_mm_per_kN, true}}});
  if (e->oil_column_resonance)
    out.push_back({"oil_column_resonance",
                   {{"f_hz", &e->oil_column_resonance->f_hz, true}, {"zeta", &e->oil_column_resonance->zeta, false}}});
  if (e->coulomb_friction)
    out.push_back({"coulomb_friction",
                   {{"loss_mm", &e->coulomb_friction->loss_mm, true},
                    {"v_smooth_mm_s", &e->coulomb_friction->v_smooth_mm_s, false}}});
  if (e->backlash) out.push_back({"backlash", {{"gap_mm", &e->backlash->gap_mm, true}}});
  if (e->servovalve_saturation)
    out.push_back({"servovalve_saturation", {{"vmax_mm_per_s", &e->servovalve_saturation->vmax_mm_per_s, true}}});
  if (e->sensor_noise)
    out.push_back({"sensor_noise",
                   {{"rms_y_mm", &e->sensor_noise->rms_y_mm, false}, {"rms_f_kN", &e->sensor_noise->rms_f_kN, false}}});
  if (e->current_lag) out.push_back({"current_lag", {{"tau_ms", &e->current_lag->tau_ms, true}}});
  if (e->damper_scale) out.push_back({"damper_scale", {{"scale", &e->damper_scale->scale, true}}});
  return out;
}

/// Switches on, with its defaults, the effect called `name` (one of models::kEffectNames).
void TurnOn(models::EffectSet* e, std::string_view name) {
  if (name == "pure_delay") e->pure_delay.emplace();
  if (name == "gain_error") e->gain_error.emplace();
  if (name == "load_coupling") e->load_coupling.emplace();
  if (name == "oil_column_resonance") e->oil_column_resonance.emplace();
  if (name == "coulomb_friction") e->coulomb_friction.emplace();
  if (name == "backlash") e->backlash.emplace();
  if (name == "servovalve_saturation") e->servovalve_saturation.emplace();
  if (name == "sensor_noise") e->sensor_noise.emplace();
  if (name == "current_lag") e->current_lag.emplace();
  if (name == "damper_scale") e->damper_scale.emplace();
}

/// [plant.effects]: one sub-table per effect that is on; an unknown name is refused by Finish()
/// with the list of the library's names.
void ReadEffects(Section& effects, models::EffectSet* out, bool* same_sample) {
  models::EffectSet e;
  std::vector<Section> tables;
  tables.reserve(models::kEffectNames.size());
  for (std::string_view name : models::kEffectNames) {
    tables.push_back(effects.Sub(name));
    if (tables.back().Present()) TurnOn(&e, name);
  }
  effects.Finish();
  for (auto& [name, keys] : EffectKeys(&e)) {
    Section* table = nullptr;
    for (std::size_t i = 0; i < models::kEffectNames.size(); ++i) {
      if (models::kEffectNames[i] == name) table = &tables[i];
    }
    for (const EffectKey& k : keys) table->Number(k.key, k.field);
    if (std::string_view(name) == "load_coupling") table->Bool("same_sample", same_sample);  // rig only
    table->Finish();
    for (const EffectKey& k : keys) {
      if (k.required && !table->Has(k.key)) {
        table->Fail(k.key, fmt::format("missing (the effect \"{}\" needs it; remove the table to switch the "
                                       "effect off)",
                                       name));
      }
    }
    if (std::string_view(name) == "sensor_noise" && !table->Has("rms_y_mm") && !table->Has("rms_f_kN")) {
      table->Fail("rms_y_mm", "missing (sensor_noise needs rms_y_mm, rms_f_kN or both)");
    }
  }
  *out = e;
}

/// `rms_key` is the unit-bearing name of SignalSpec::rms in this table.
void ReadSignal(Section& section, std::string_view rms_key, SignalSpec* s) {
  section.String("kind", &s->kind);
  section.Number("band_hz", &s->band_hz);
  section.Number(rms_key, &s->rms);
  section.Integer("seed", &s->seed);
  section.Number("discard_s", &s->discard_s);
  section.String("file", &s->file);
  section.Number("file_dt_s", &s->file_dt_s);
  section.Number("scale", &s->scale);
  section.Number("taper_s", &s->taper_s);
  section.Finish();
}

void ReadScenario(const toml::table& root, const std::string& file, Scenario* s) {
  Section top(file, &root, "");

  Section run = top.Sub("run");
  run.String("name", &s->run.name);
  run.Number("dt_s", &s->run.dt_s);
  run.Number("duration_s", &s->run.duration_s);
  run.Finish();

  Section structure = top.Sub("structure");
  StructureConfig& st = s->structure;
  structure.String("mode", &st.mode);
  structure.String("kind", &st.kind);
  structure.String("file", &st.file);
  structure.Integer("actuator_dof", &st.actuator_dof);
  structure.Number("mass_kg", &st.mass_kg);
  structure.Number("frequency_hz", &st.frequency_hz);
  structure.Number("damping_ratio", &st.damping_ratio);
  structure.Number("specimen_count", &st.specimen_count);
  structure.String("derivatives", &st.derivatives);
  Section ground = structure.Sub("ground");
  ReadSignal(ground, "rms_mm_s2", &st.ground);
  Section desired = structure.Sub("desired");
  ReadSignal(desired, "rms_mm", &st.desired);
  structure.Finish();

  ControllerConfig& c = s->controller;
  Section controller = top.Sub("controller");
  controller.String("kind", &c.kind);
  controller.Servo("model", &c.model);
  controller.Bool("half_step_ahead", &c.half_step_ahead);
  controller.Number("delay_ms", &c.delay_ms);
  controller.Number("max_delay_ms", &c.max_delay_ms);
  controller.Number("lead_tp_ms", &c.lead_tp_ms);
  controller.Number("lp_cutoff_hz", &c.lp_cutoff_hz);
  controller.Integer("lp_order", &c.lp_order);
  controller.Servo("model_low", &c.model_low);
  controller.Servo("model_high", &c.model_high);
  controller.Number("current_high_A", &c.current_high_A);
  Section lqg = controller.Sub("lqg");
  for (auto [key, field] : {std::pair{"q", &c.lqg.q}, {"w_f_hz", &c.lqg.w_f_hz}, {"xi_f", &c.lqg.xi_f},
                            {"eta_f", &c.lqg.eta_f}, {"W", &c.lqg.W}, {"V", &c.lqg.V}}) {
    lqg.Number(key, field);
  }
  lqg.Finish();
  controller.Finish();

  PlantConfig& pl = s->plant;
  Section plant = top.Sub("plant");
  plant.String("kind", &pl.kind);
  plant.Servo("actuator", &s->plant.actuator);
  Section physical = plant.Sub("physical");
  for (auto [key, field] : PhysicalFields(&pl.physical)) physical.Number(key, field);
  physical.Finish();
  plant.Bool("current_dynamics", &pl.current_dynamics);
  plant.String("specimen", &s->plant.specimen);
  plant.Number("noise_y_mm_rms", &s->plant.noise_y_mm_rms);
  plant.Number("noise_f_kN_rms", &s->plant.noise_f_kN_rms);
  plant.Integer("noise_seed", &s->plant.noise_seed);
  plant.Number("cvode_rtol", &s->plant.cvode_rtol);
  Section damper = plant.Sub("damper");
  for (auto [key, field] : DamperFields(&pl.damper)) damper.Number(key, field);
  damper.Finish();
  Section effects = plant.Sub("effects");
  ReadEffects(effects, &pl.effects, &pl.load_coupling_same_sample);
  Section unmodelled = plant.Sub("unmodelled");
  unmodelled.Number("ripple_mm", &pl.unmodelled.ripple_mm);
  unmodelled.Number("ripple_hz", &pl.unmodelled.ripple_hz);
  unmodelled.Number("stiffness_kN_per_mm", &pl.unmodelled.stiffness_kN_per_mm);
  unmodelled.Finish();
  plant.Finish();

  Section semiactive = top.Sub("semiactive");
  semiactive.String("mode", &s->semiactive.mode);
  semiactive.Number("current_A", &s->semiactive.current_A);
  semiactive.Number("max_current_A", &s->semiactive.max_current_A);
  semiactive.Number("pulse_hz", &s->semiactive.pulse_hz);
  semiactive.Number("pulse_duty", &s->semiactive.pulse_duty);
  semiactive.Number("r_weight", &s->semiactive.r_weight);
  semiactive.Number("noise_ratio", &s->semiactive.noise_ratio);
  semiactive.Number("capacity_kN", &s->semiactive.capacity_kN);
  semiactive.Finish();

  SafetyConfig& sf = s->safety;
  Section safety = top.Sub("safety");
  safety.Bool("enabled", &sf.enabled);
  for (auto [key, field] : {std::pair{"stroke_mm", &sf.stroke_mm}, {"force_kN", &sf.force_kN},
                            {"max_error_mm", &sf.max_error_mm}, {"growth_window_s", &sf.growth_window_s},
                            {"growth_factor", &sf.growth_factor}, {"growth_floor_mm", &sf.growth_floor_mm}}) {
    safety.Number(key, field);
  }
  safety.Integer("growth_windows", &sf.growth_windows);
  safety.Finish();

  Section lockstep = top.Sub("lockstep");
  if (lockstep.Has("timeout_ms")) {
    lockstep.Fail("timeout_ms", "was renamed lockstep.rerequest_ms (re-request an incomplete step after this "
                                "silence [ms], [5, 10000]); the give-up time is lockstep.stall_budget_s");
  }
  if (lockstep.Has("max_attempts")) {
    lockstep.Fail("max_attempts", "was replaced by lockstep.stall_budget_s: how long one step may stay "
                                  "incomplete before the run stops [s], [1, 3600] (default 10)");
  }
  lockstep.Number("rerequest_ms", &s->lockstep.rerequest_ms);
  lockstep.Number("stall_budget_s", &s->lockstep.stall_budget_s);
  lockstep.Number("handshake_timeout_s", &s->lockstep.handshake_timeout_s);
  lockstep.Finish();

  RealtimeConfig& rt = s->realtime;
  Section realtime = top.Sub("realtime");
  realtime.Bool("enabled", &rt.enabled);
  realtime.Integer("max_consecutive_misses", &rt.max_consecutive_misses);
  realtime.Bool("sched_fifo", &rt.sched_fifo);
  realtime.Integer("priority", &rt.priority);
  realtime.Bool("lock_memory", &rt.lock_memory);
  realtime.Finish();

  FaultConfig& fc = s->faults;
  Section faults = top.Sub("faults");
  for (auto [key, field] : {std::pair{"drop", &fc.drop}, {"duplicate", &fc.duplicate}, {"delay", &fc.delay},
                            {"reorder", &fc.reorder}, {"delay_ms", &fc.delay_ms}}) {
    faults.Number(key, field);
  }
  faults.Integer("seed", &fc.seed);
  faults.Integer("recv_buf_bytes", &fc.recv_buf_bytes);
  Section process = faults.Sub("process");
  process.String("role", &fc.process_role);
  process.String("kind", &fc.process_kind);
  process.Integer("at_step", &fc.process_at_step);
  process.Number("stop_s", &fc.process_stop_s);
  process.Finish();
  faults.Finish();

  top.Finish();
}

// ---------------------------------------------------------------------------------------
// Pass 2: one validator per struct (ranges as documented in scenario.h).

/// An interval of allowed values; `note` explains a computed bound.
struct Range {
  double lo;
  double hi;
  bool lo_open;
  bool hi_open;
  std::string note = {};
};
Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
Range OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }
Range ClosedOpen(double lo, double hi) { return {lo, hi, false, true}; }
Range Open(double lo, double hi) { return {lo, hi, true, true}; }

class Check {
 public:
  explicit Check(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(std::string_view key, std::string problem) const {
    throw Error(fmt::format("{}: {}", file_, key), std::move(problem));
  }

  const std::string& file() const { return file_; }

  void InRange(std::string_view key, double v, const Range& r) const {
    const bool above_lo = r.lo_open ? v > r.lo : v >= r.lo;
    const bool below_hi = r.hi_open ? v < r.hi : v <= r.hi;
    if (std::isfinite(v) && above_lo && below_hi) return;
    std::string problem = fmt::format("{} is out of range {}{}, {}{}", v, r.lo_open ? '(' : '[', r.lo, r.hi,
                                      r.hi_open ? ')' : ']');
    if (!r.note.empty()) problem += " (" + r.note + ")";
    Fail(key, problem);
  }

  void OneOf(std::string_view key, const std::string& v, std::initializer_list<std::string_view> allowed) const {
    if (std::find(allowed.begin(), allowed.end(), v) != allowed.end()) return;
    Fail(key, fmt::format("\"{}\" is not allowed (allowed: {})", v, JoinList(allowed, "\"")));
  }

 private:
  std::string file_;
};

/// Where a `kind = "file"` path points: relative paths are relative to the scenario's folder.
std::filesystem::path ResolveSignalFile(const std::string& scenario_path, const std::string& file) {
  std::filesystem::path p(file);
  if (p.is_relative()) p = std::filesystem::path(scenario_path).parent_path() / p;
  return std::filesystem::absolute(p).lexically_normal();
}

void ValidateRun(const RunConfig& r, const Check& check) {
  if (r.name.empty() || !std::all_of(r.name.begin(), r.name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
               c == '-' || c == '.';
      })) {
    check.Fail("run.name", fmt::format("\"{}\" is not a usable name (allowed: non-empty, letters, digits, "
                                       "'_', '-', '.')",
                                       r.name));
  }
  check.InRange("run.dt_s", r.dt_s, Closed(1e-5, 0.01));
  check.InRange("run.duration_s", r.duration_s, OpenClosed(0.0, 36000.0));
  if (r.duration_s < r.dt_s) {
    check.Fail("run.duration_s", fmt::format("{} is shorter than one step (run.dt_s = {})", r.duration_s, r.dt_s));
  }
}

void ValidateServo(const ServoModel3& m, std::string_view key, const Check& check) {
  for (auto [name, v] : {std::pair{"K", m.K}, {"p", m.p}, {"b", m.b}, {"c", m.c}}) {
    check.InRange(fmt::format("{}.{}", key, name), v,
                  {0.0, kInf, true, true, "K, p, b, c must all be > 0: stable, minimum phase"});
  }
}

void ValidateSignal(const SignalSpec& s, std::string_view prefix, std::string_view rms_key, double dt_s,
                    const std::string& scenario_path, const Check& check) {
  auto key = [&](std::string_view k) { return fmt::format("{}.{}", prefix, k); };
  check.OneOf(key("kind"), s.kind, {"blwn", "file", "zero"});
  const double nyquist = 0.5 / dt_s;
  check.InRange(key("band_hz"), s.band_hz,
                {0.0, nyquist, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
  check.InRange(key(rms_key), s.rms, Open(0.0, kInf));
  check.InRange(key("discard_s"), s.discard_s, Closed(0.0, 60.0));
  check.InRange(key("file_dt_s"), s.file_dt_s, Closed(0.0, 10.0));
  check.InRange(key("taper_s"), s.taper_s, Closed(0.0, 60.0));
  if (!std::isfinite(s.scale) || s.scale == 0.0) {
    check.Fail(key("scale"), fmt::format("{} is not allowed (allowed: any finite value other than 0)", s.scale));
  }
  if (s.kind == "file") {
    if (s.file.empty()) check.Fail(key("file"), "missing: kind = \"file\" needs a file path");
    const std::filesystem::path resolved = ResolveSignalFile(scenario_path, s.file);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(resolved, ec)) {
      check.Fail(key("file"), fmt::format("file not found: {} (paths are relative to the scenario file's folder)",
                                          resolved.string()));
    }
  }
}

void ValidateStructure(const StructureConfig& st, double dt_s, const std::string& scenario_path,
                       const Check& check) {
  check.OneOf("structure.mode", st.mode, {"rths", "predefined"});
  check.OneOf("structure.kind", st.kind, {"sdof", "file"});
  if (st.mode == "rths" && st.kind == "file") {
    if (st.file.empty()) check.Fail("structure.file", "missing: kind = \"file\" needs a structure file");
    const std::filesystem::path resolved = ResolveSignalFile(scenario_path, st.file);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(resolved, ec)) {
      check.Fail("structure.file", fmt::format("file not found: {} (paths are relative to the scenario file's "
                                               "folder)",
                                               resolved.string()));
    }
    check.InRange("structure.actuator_dof", st.actuator_dof,
                  {1, 10000, false, false, "1-based; at most the structure's number of DOFs"});
  }
  check.InRange("structure.mass_kg", st.mass_kg, OpenClosed(0.0, 1e9));
  // Central difference is stable for omega dt < 2, i.e. f < 1 / (pi dt).
  const double f_max = 1.0 / (kPi * dt_s);
  check.InRange("structure.frequency_hz", st.frequency_hz,
                {0.0, f_max, true, true, "central-difference stability limit 1/(pi run.dt_s)"});
  check.InRange("structure.damping_ratio", st.damping_ratio, ClosedOpen(0.0, 1.0));
  check.InRange("structure.specimen_count", st.specimen_count, OpenClosed(0.0, 1000.0));
  check.OneOf("structure.derivatives", st.derivatives, {"extrapolated", "central"});
  ValidateSignal(st.ground, "structure.ground", "rms_mm_s2", dt_s, scenario_path, check);
  ValidateSignal(st.desired, "structure.desired", "rms_mm", dt_s, scenario_path, check);
}

void ValidateController(const ControllerConfig& c, double dt_s, const Check& check) {
  check.OneOf("controller.kind", c.kind, {"none", "ff", "poly3", "lead", "ff_lp", "bumpless_lp", "ff_lqg"});
  ValidateServo(c.model, "controller.model", check);
  ValidateServo(c.model_low, "controller.model_low", check);
  ValidateServo(c.model_high, "controller.model_high", check);
  check.InRange("controller.max_delay_ms", c.max_delay_ms, OpenClosed(0.0, 100.0));
  check.InRange("controller.delay_ms", c.delay_ms,
                {0.0, c.max_delay_ms, true, false,
                 "extrapolation beyond controller.max_delay_ms amplifies noise too much; raise that "
                 "bound deliberately if you mean it"});
  check.InRange("controller.lead_tp_ms", c.lead_tp_ms, OpenClosed(0.0, 100.0));
  const bool uses_lp = c.kind == "ff_lp" || c.kind == "bumpless_lp";
  check.InRange("controller.lp_cutoff_hz", c.lp_cutoff_hz,
                {0.0, uses_lp ? 0.5 / dt_s : kInf, true, true,
                 uses_lp ? "below the Nyquist frequency 0.5/run.dt_s" : ""});
  check.InRange("controller.lp_order", c.lp_order,
                {3, 8, false, false, "the three-pole inverse needs at least order 3 to be proper"});
  check.InRange("controller.current_high_A", c.current_high_A, OpenClosed(0.0, 5.0));
  check.InRange("controller.lqg.q", c.lqg.q, OpenClosed(0.0, 1e12));
  check.InRange("controller.lqg.w_f_hz", c.lqg.w_f_hz, OpenClosed(0.0, 1000.0));
  check.InRange("controller.lqg.xi_f", c.lqg.xi_f, OpenClosed(0.0, 10.0));
  check.InRange("controller.lqg.eta_f", c.lqg.eta_f, Closed(0.0, 100.0));
  check.InRange("controller.lqg.W", c.lqg.W, OpenClosed(0.0, 1e12));
  check.InRange("controller.lqg.V", c.lqg.V, OpenClosed(0.0, 1e12));
}

void ValidatePhysical(const PhysicalActuatorConfig& p, const Check& check) {
  const std::vector<std::pair<const char*, Range>> ranges = {
      {"area_m2", OpenClosed(0, 1)},          {"supply_pressure_Pa", OpenClosed(0, 1e9)},
      {"volume_m3", OpenClosed(0, 1)},        {"piston_mass_kg", OpenClosed(0, 1e5)},
      {"piston_damping_N_s_m", Closed(0, 1e9)}, {"valve_hz", OpenClosed(0, 1e4)},
      {"valve_zeta", OpenClosed(0, 10)},      {"kq_m3_s", OpenClosed(0, 10)},
      {"kp_per_m", OpenClosed(0, 1e6)},       {"beta_Pa", OpenClosed(0, 1e12)},
      {"leakage_m3_s_Pa", Closed(0, 1e-6)}};
  PhysicalActuatorConfig copy = p;
  const auto fields = PhysicalFields(&copy);
  for (std::size_t i = 0; i < fields.size(); ++i) {
    check.InRange(fmt::format("plant.physical.{}", fields[i].first), *fields[i].second, ranges[i].second);
  }
}

/// The allowed range of each effect parameter (models/rig_effects.h), for the scenario's messages.
Range EffectRange(std::string_view effect, std::string_view key, double dt_s) {
  if (effect == "pure_delay") return Closed(0.0, 100.0);
  if (effect == "gain_error") return Closed(0.5, 2.0);
  if (effect == "load_coupling") return Closed(-1.0, 1.0);
  if (effect == "oil_column_resonance") {
    if (key == "f_hz") return {0.0, 0.45 / dt_s, true, true, "below 0.45/run.dt_s"};
    return OpenClosed(0.0, 2.0);
  }
  if (effect == "coulomb_friction") return key == "loss_mm" ? Closed(0.0, 10.0) : OpenClosed(0.0, 1000.0);
  if (effect == "backlash") return Closed(0.0, 10.0);
  if (effect == "servovalve_saturation") return OpenClosed(0.0, 1e9);
  if (effect == "sensor_noise") return key == "rms_y_mm" ? Closed(0.0, 10.0) : Closed(0.0, 100.0);
  if (effect == "current_lag") return Closed(0.0, 1000.0);
  return Closed(0.1, 10.0);  // damper_scale
}

void ValidateEffects(const PlantConfig& p, double dt_s, const Check& check) {
  models::EffectSet e = p.effects;
  for (auto& [name, keys] : EffectKeys(&e)) {
    for (const EffectKey& k : keys) {
      check.InRange(fmt::format("plant.effects.{}.{}", name, k.key), *k.field, EffectRange(name, k.key, dt_s));
    }
  }
  p.effects.Validate(dt_s, check.file() + ": plant.effects");  // the library's own ranges
  const UnmodelledConfig& u = p.unmodelled;
  check.InRange("plant.unmodelled.ripple_mm", u.ripple_mm, Closed(0.0, 10.0));
  check.InRange("plant.unmodelled.ripple_hz", u.ripple_hz,
                {0.0, 0.5 / dt_s, u.ripple_mm > 0.0, true,
                 u.ripple_mm > 0.0 ? "a ripple needs a frequency below the Nyquist frequency 0.5/run.dt_s"
                                   : "below the Nyquist frequency 0.5/run.dt_s"});
  check.InRange("plant.unmodelled.stiffness_kN_per_mm", u.stiffness_kN_per_mm, Closed(-100.0, 100.0));
  if (p.RigMode() && p.kind != "linear") {
    check.Fail(p.effects.Empty() ? "plant.unmodelled" : "plant.effects",
               fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act around the "
                           "linear actuator model",
                           p.kind));
  }
}

void ValidateDamper(const models::MrDamperParams& d, const Check& check) {
  try {
    d.Validate();
  } catch (const Error& e) {
    // "MrDamperParams: alpha_a" -> plant.damper.alpha_a
    const std::string& w = e.where();
    const std::size_t colon = w.rfind(": ");
    check.Fail(fmt::format("plant.damper.{}", colon == std::string::npos ? w : w.substr(colon + 2)), e.problem());
  }
}

void ValidatePlant(const PlantConfig& p, double dt_s, const Check& check) {
  check.OneOf("plant.kind", p.kind, {"linear", "physical", "ideal"});
  ValidateServo(p.actuator, "plant.actuator", check);
  ValidatePhysical(p.physical, check);
  check.OneOf("plant.specimen", p.specimen, {"mr_damper", "none"});
  check.InRange("plant.noise_y_mm_rms", p.noise_y_mm_rms, Closed(0.0, 10.0));
  check.InRange("plant.noise_f_kN_rms", p.noise_f_kN_rms, Closed(0.0, 100.0));
  check.InRange("plant.cvode_rtol", p.cvode_rtol, OpenClosed(0.0, 1e-2));
  ValidateDamper(p.damper, check);
  ValidateEffects(p, dt_s, check);
}

void ValidateSemiactive(const SemiactiveConfig& s, const Check& check) {
  check.OneOf("semiactive.mode", s.mode, {"passive_off", "passive_on", "constant", "pulse", "clipped_optimal"});
  check.InRange("semiactive.r_weight", s.r_weight, OpenClosed(0.0, 1e6));
  check.InRange("semiactive.noise_ratio", s.noise_ratio, OpenClosed(0.0, 1e6));
  check.InRange("semiactive.capacity_kN", s.capacity_kN, OpenClosed(0.0, 1e6));
  check.InRange("semiactive.pulse_duty", s.pulse_duty, Open(0.0, 1.0));
  check.InRange("semiactive.max_current_A", s.max_current_A, OpenClosed(0.0, 5.0));
  check.InRange("semiactive.current_A", s.current_A,
                {0.0, s.max_current_A, false, false, "at most semiactive.max_current_A"});
}

void ValidateSafety(const SafetyConfig& f, const Check& check) {
  check.InRange("safety.stroke_mm", f.stroke_mm, OpenClosed(0.0, 10000.0));
  check.InRange("safety.force_kN", f.force_kN, OpenClosed(0.0, 1e6));
  check.InRange("safety.max_error_mm", f.max_error_mm, OpenClosed(0.0, 10000.0));
  check.InRange("safety.growth_window_s", f.growth_window_s, OpenClosed(0.0, 10.0));
  check.InRange("safety.growth_factor", f.growth_factor, OpenClosed(1.0, 1000.0));
  check.InRange("safety.growth_windows", f.growth_windows, Closed(2, 1000));
  check.InRange("safety.growth_floor_mm", f.growth_floor_mm, OpenClosed(0.0, 10000.0));
}

void ValidateLockstep(const LockstepConfig& l, const Check& check) {
  // Below ~5 ms a re-request would come before a loaded 2-core host has even scheduled the
  // participants once: it only adds traffic.
  check.InRange("lockstep.rerequest_ms", l.rerequest_ms, Closed(5.0, 10000.0));
  check.InRange("lockstep.stall_budget_s", l.stall_budget_s,
                {std::max(1.0, 4e-3 * l.rerequest_ms), 3600.0, false, false,
                 "at least 1 s and 4 lockstep.rerequest_ms"});
  check.InRange("lockstep.handshake_timeout_s", l.handshake_timeout_s, Closed(0.1, 600.0));
}

void ValidateRealtime(const RealtimeConfig& r, const Check& check) {
  check.InRange("realtime.max_consecutive_misses", static_cast<double>(r.max_consecutive_misses), Closed(0.0, 1e9));
  check.InRange("realtime.priority", r.priority, Closed(1, 99));
}

void ValidateFaults(const FaultConfig& f, std::int64_t steps, const Check& check) {
  for (auto [key, v] : {std::pair{"faults.drop", f.drop}, {"faults.duplicate", f.duplicate},
                        {"faults.delay", f.delay}, {"faults.reorder", f.reorder}}) {
    check.InRange(key, v, Closed(0.0, 0.5));
  }
  check.InRange("faults.drop", f.drop + f.duplicate + f.delay + f.reorder,
                {0.0, 0.5, false, false, "drop + duplicate + delay + reorder must not exceed 0.5"});
  check.InRange("faults.delay_ms", f.delay_ms, OpenClosed(0.0, 10000.0));
  check.InRange("faults.seed", static_cast<double>(f.seed), Closed(0.0, 9007199254740992.0));
  if (f.recv_buf_bytes != 0) {
    check.InRange("faults.recv_buf_bytes", static_cast<double>(f.recv_buf_bytes),
                  {1024.0, 134217728.0, false, false, "0 for the host's default, else [1024, 2^27]"});
  }
  if (f.process_role.empty() && f.process_kind.empty()) return;
  check.OneOf("faults.process.role", f.process_role, {"integrator", "controller", "plant", "semiactive", "logger"});
  check.OneOf("faults.process.kind", f.process_kind, {"stall", "throw", "crash", "kill", "stop"});
  check.InRange("faults.process.at_step", static_cast<double>(f.process_at_step),
                {0.0, static_cast<double>(steps), false, true, "a step of the run: [0, steps)"});
  check.InRange("faults.process.stop_s", f.process_stop_s, Closed(0.0, 3600.0));
}

}  // namespace

std::int64_t Scenario::steps() const { return std::llround(run.duration_s / run.dt_s); }

std::string Sha256Hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw Error("Sha256Hex", "OpenSSL EVP_Digest(sha256) failed");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0x0f];
  }
  return hex;
}

void ValidateScenario(const Scenario& s) {
  const Check check(DisplayName(s.path));
  ValidateRun(s.run, check);
  ValidateStructure(s.structure, s.run.dt_s, s.path, check);
  ValidateController(s.controller, s.run.dt_s, check);
  if (s.semiactive.mode == "clipped_optimal" && s.structure.mode != "rths") {
    check.Fail("semiactive.mode", "\"clipped_optimal\" needs a structure to control (structure.mode = \"rths\")");
  }
  check.InRange("semiactive.pulse_hz", s.semiactive.pulse_hz,
                {0.0, 0.25 / s.run.dt_s, true, true, "at least four steps per period: below 0.25/run.dt_s"});
  ValidatePlant(s.plant, s.run.dt_s, check);
  ValidateSemiactive(s.semiactive, check);
  ValidateLockstep(s.lockstep, check);
  ValidateRealtime(s.realtime, check);
  ValidateSafety(s.safety, check);
  ValidateFaults(s.faults, s.steps(), check);
}

Scenario ParseScenario(std::string_view toml_text, const std::string& path) {
  const std::string file = DisplayName(path);
  toml::table root;
  try {
    root = toml::parse(toml_text, path);
  } catch (const toml::parse_error& e) {
    const toml::source_position& at = e.source().begin;
    throw Error(fmt::format("{}:{}:{}", file, at.line, at.column),
                fmt::format("TOML syntax error at line {}, column {}: {}", at.line, at.column, e.description()));
  }
  // An empty scenario (an empty file, only comments, only table headers) is a mistake, not a
  // request for the default experiment: at least one key must be set somewhere.
  struct AnyKey {
    static bool In(const toml::table& t) {
      for (auto&& [key, node] : t)
        if (const toml::table* sub = node.as_table(); !sub || In(*sub)) return true;
      return false;
    }
  };
  if (!AnyKey::In(root)) {
    throw Error(file, "empty scenario: no key is set (the text is empty or holds only comments and table headers); "
                      "set at least one key, e.g. [run] name = \"...\" (every key: docs/scenarios.md)");
  }
  Scenario s;
  s.path = path;
  ReadScenario(root, file, &s);
  ValidateScenario(s);
  for (SignalSpec* signal : {&s.structure.ground, &s.structure.desired}) {
    if (signal->kind == "file") signal->file = ResolveSignalFile(path, signal->file).string();
  }
  if (!s.structure.file.empty()) s.structure.file = ResolveSignalFile(path, s.structure.file).string();
  return s;
}

namespace {
std::string TomlString(const std::string& v) {
  std::string out = "\"";
  for (char ch : v) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if ((c < 0x20 && ch != '\t') || c == 0x7F) {  // TOML forbids them unescaped (found by fuzzing)
      out += fmt::format("\\u{:04X}", c);
    } else {
      out += ch;
    }
  }
  return out + "\"";
}
std::string TomlNumber(double v) {
  // "-0" would read back as the integer 0, i.e. +0.0 (found by fuzzing): keep it a float.
  if (v == 0.0 && std::signbit(v)) return "-0.0";
  return fmt::format("{:.17g}", v);
}
std::string TomlServo(const ServoModel3& m) {
  if (m.name != "custom") {
    const ServoModel3 preset = ServoPreset(m.name);
    if (preset.K == m.K && preset.p == m.p && preset.b == m.b && preset.c == m.c) return TomlString(m.name);
  }
  return fmt::format("{{ K = {}, p = {}, b = {}, c = {} }}", TomlNumber(m.K), TomlNumber(m.p), TomlNumber(m.b),
                     TomlNumber(m.c));
}
void WriteSignal(std::string* out, const char* table, const char* rms_key, const SignalSpec& g) {
  *out += fmt::format("\n[{}]\nkind = {}\nband_hz = {}\n{} = {}\nseed = {}\ndiscard_s = {}\n", table,
                      TomlString(g.kind), TomlNumber(g.band_hz), rms_key, TomlNumber(g.rms), g.seed,
                      TomlNumber(g.discard_s));
  *out += fmt::format("file = {}\nfile_dt_s = {}\nscale = {}\ntaper_s = {}\n", TomlString(g.file),
                      TomlNumber(g.file_dt_s), TomlNumber(g.scale), TomlNumber(g.taper_s));
}
}  // namespace

std::string ToToml(const Scenario& s) {
  std::string o = "# Written by rths (scenario::ToToml): every key, explicit.\n";
  const auto& r = s.run;
  o += fmt::format("\n[run]\nname = {}\ndt_s = {}\nduration_s = {}\n", TomlString(r.name), TomlNumber(r.dt_s),
                   TomlNumber(r.duration_s));
  const auto& st = s.structure;
  o += fmt::format(
      "\n[structure]\nmode = {}\nmass_kg = {}\nfrequency_hz = {}\ndamping_ratio = {}\nspecimen_count = "
      "{}\nderivatives = {}\nkind = {}\nfile = {}\nactuator_dof = {}\n",
      TomlString(st.mode), TomlNumber(st.mass_kg), TomlNumber(st.frequency_hz), TomlNumber(st.damping_ratio),
      TomlNumber(st.specimen_count), TomlString(st.derivatives), TomlString(st.kind), TomlString(st.file),
      st.actuator_dof);
  WriteSignal(&o, "structure.ground", "rms_mm_s2", st.ground);
  WriteSignal(&o, "structure.desired", "rms_mm", st.desired);
  const auto& c = s.controller;
  o += fmt::format(
      "\n[controller]\nkind = {}\nmodel = {}\nhalf_step_ahead = {}\ndelay_ms = {}\nmax_delay_ms = {}\n"
      "lead_tp_ms = {}\nlp_cutoff_hz = {}\nlp_order = {}\nmodel_low = {}\nmodel_high = {}\n"
      "current_high_A = {}\n",
      TomlString(c.kind), TomlServo(c.model), c.half_step_ahead, TomlNumber(c.delay_ms),
      TomlNumber(c.max_delay_ms), TomlNumber(c.lead_tp_ms), TomlNumber(c.lp_cutoff_hz), c.lp_order,
      TomlServo(c.model_low), TomlServo(c.model_high), TomlNumber(c.current_high_A));
  o += fmt::format("\n[controller.lqg]\nq = {}\nw_f_hz = {}\nxi_f = {}\neta_f = {}\nW = {}\nV = {}\n",
                   TomlNumber(c.lqg.q), TomlNumber(c.lqg.w_f_hz), TomlNumber(c.lqg.xi_f), TomlNumber(c.lqg.eta_f),
                   TomlNumber(c.lqg.W), TomlNumber(c.lqg.V));
  const auto& p = s.plant;
  o += fmt::format(
      "\n[plant]\nkind = {}\nactuator = {}\nspecimen = {}\ncurrent_dynamics = {}\nnoise_y_mm_rms = {}\n"
      "noise_f_kN_rms = {}\nnoise_seed = {}\ncvode_rtol = {}\n",
      TomlString(p.kind), TomlServo(p.actuator), TomlString(p.specimen), p.current_dynamics,
      TomlNumber(p.noise_y_mm_rms), TomlNumber(p.noise_f_kN_rms), p.noise_seed, TomlNumber(p.cvode_rtol));
  o += "\n[plant.physical]\n";
  PhysicalActuatorConfig phys = p.physical;
  for (auto [key, field] : PhysicalFields(&phys)) o += fmt::format("{} = {}\n", key, TomlNumber(*field));
  o += "\n[plant.damper]\n";
  models::MrDamperParams damper = p.damper;
  for (auto [key, field] : DamperFields(&damper)) o += fmt::format("{} = {}\n", key, TomlNumber(*field));
  o += fmt::format("\n[plant.unmodelled]\nripple_mm = {}\nripple_hz = {}\nstiffness_kN_per_mm = {}\n",
                   TomlNumber(p.unmodelled.ripple_mm), TomlNumber(p.unmodelled.ripple_hz),
                   TomlNumber(p.unmodelled.stiffness_kN_per_mm));
  models::EffectSet effects = p.effects;
  for (auto& [name, keys] : EffectKeys(&effects)) {
    o += fmt::format("\n[plant.effects.{}]\n", name);
    for (const EffectKey& k : keys) o += fmt::format("{} = {}\n", k.key, TomlNumber(*k.field));
    if (std::string_view(name) == "load_coupling") o += fmt::format("same_sample = {}\n", p.load_coupling_same_sample);
  }
  const auto& sa = s.semiactive;
  o += fmt::format(
      "\n[semiactive]\nmode = {}\ncurrent_A = {}\nmax_current_A = {}\npulse_hz = {}\npulse_duty = {}\n"
      "r_weight = {}\nnoise_ratio = {}\ncapacity_kN = {}\n",
      TomlString(sa.mode), TomlNumber(sa.current_A), TomlNumber(sa.max_current_A), TomlNumber(sa.pulse_hz),
      TomlNumber(sa.pulse_duty), TomlNumber(sa.r_weight), TomlNumber(sa.noise_ratio), TomlNumber(sa.capacity_kN));
  const auto& f = s.safety;
  o += fmt::format(
      "\n[safety]\nenabled = {}\nstroke_mm = {}\nforce_kN = {}\nmax_error_mm = {}\ngrowth_window_s = {}\n"
      "growth_factor = {}\ngrowth_windows = {}\ngrowth_floor_mm = {}\n",
      f.enabled, TomlNumber(f.stroke_mm), TomlNumber(f.force_kN), TomlNumber(f.max_error_mm),
      TomlNumber(f.growth_window_s), TomlNumber(f.growth_factor), f.growth_windows, TomlNumber(f.growth_floor_mm));
  const auto& l = s.lockstep;
  o += fmt::format("\n[lockstep]\nrerequest_ms = {}\nstall_budget_s = {}\nhandshake_timeout_s = {}\n",
                   TomlNumber(l.rerequest_ms), TomlNumber(l.stall_budget_s), TomlNumber(l.handshake_timeout_s));
  const auto& rt = s.realtime;
  o += fmt::format("\n[realtime]\nenabled = {}\nmax_consecutive_misses = {}\nsched_fifo = {}\npriority = {}\n"
                   "lock_memory = {}\n",
                   rt.enabled, rt.max_consecutive_misses, rt.sched_fifo, rt.priority, rt.lock_memory);
  const auto& fc = s.faults;
  o += fmt::format("\n[faults]\ndrop = {}\nduplicate = {}\ndelay = {}\nreorder = {}\ndelay_ms = {}\nseed = {}\n"
                   "recv_buf_bytes = {}\n",
                   TomlNumber(fc.drop), TomlNumber(fc.duplicate), TomlNumber(fc.delay), TomlNumber(fc.reorder),
                   TomlNumber(fc.delay_ms), fc.seed, fc.recv_buf_bytes);
  if (!fc.process_role.empty() || !fc.process_kind.empty()) {
    o += fmt::format("\n[faults.process]\nrole = {}\nkind = {}\nat_step = {}\nstop_s = {}\n",
                     TomlString(fc.process_role), TomlString(fc.process_kind), fc.process_at_step,
                     TomlNumber(fc.process_stop_s));
  }
  return o;
}

Scenario LoadScenario(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open scenario file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(path, "cannot read scenario file");
  Scenario s = ParseScenario(bytes, path);
  s.sha256 = Sha256Hex(bytes);
  return s;
}

}  // namespace rths::scenario
