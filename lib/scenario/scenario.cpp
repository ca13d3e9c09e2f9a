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
#include "core/names.h"
#include "core/text.h"
#include "control/ambc.h"
#include "control/ats.h"
#include "control/lti_controller.h"

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

  /// A transfer function: an inline table {num = [...], den = [...]} of numbers (docs/scenarios.md).
  /// Absent: the default (1). Each array is read as given; CheckTf judges the values.
  void Tf(std::string_view key, control::TfCoefficients* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    constexpr std::string_view kExpected = "a table {num = [...], den = [...]} (coefficients in descending powers)";
    const auto* table = node->as_table();
    if (table == nullptr) WrongType(key, kExpected, *node);
    Section tf(file_, table, Dotted(key) + ".");
    control::TfCoefficients c;
    for (auto [name, field] : {std::pair{"num", &c.num}, {"den", &c.den}}) {
      const toml::node* a = tf.Declare(name, false);
      if (a == nullptr) continue;
      const auto* array = a->as_array();
      if (array == nullptr) tf.WrongType(name, "an array of numbers, e.g. [2.0, 95.0]", *a);
      for (const toml::node& e : *array) {
        if (const auto* f = e.as_floating_point()) {
          field->push_back(f->get());
        } else if (const auto* i = e.as_integer()) {
          field->push_back(static_cast<double>(i->get()));
        } else {
          tf.Fail(name, fmt::format("element {} is {}: expected a number", field->size() + 1, DescribeNode(e)));
        }
      }
    }
    tf.Finish();
    *out = std::move(c);
  }

  /// A fixed number of numbers: an array [v1, ..., vn] of exactly `n` numbers (floats or integers).
  void Numbers(std::string_view key, double* out, std::size_t n) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    const auto* array = node->as_array();
    const std::string expected = fmt::format("an array of {} numbers", n);
    if (array == nullptr) WrongType(key, expected, *node);
    if (array->size() != n) Fail(key, fmt::format("{} values: expected {} ({})", array->size(), n, expected));
    for (std::size_t i = 0; i < n; ++i) {
      const toml::node& e = *array->get(i);
      if (const auto* f = e.as_floating_point()) {
        out[i] = f->get();
      } else if (const auto* v = e.as_integer()) {
        out[i] = static_cast<double>(v->get());
      } else {
        Fail(key, fmt::format("element {} is {}: expected a number", i + 1, DescribeNode(e)));
      }
    }
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

// ---------------------------------------------------------------------------------------
// Allowed values.

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
/// Any value (a seed, a flag): the type is the only check.
const Range kAny{-kInf, kInf, false, false};

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

void ValidateServo(const ServoModel3& m, std::string_view key, const Check& check) {
  for (auto [name, v] : {std::pair{"K", m.K}, {"p", m.p}, {"b", m.b}, {"c", m.c}}) {
    check.InRange(fmt::format("{}.{}", key, name), v,
                  {0.0, kInf, true, true, "K, p, b, c must all be > 0: stable, minimum phase"});
  }
}

// ---------------------------------------------------------------------------------------
// The schema: every table's keys, each listed once, in file order, with its allowed range.
// Three visitors walk it: Reader (TOML -> structs: keys and types), Writer (structs -> TOML
// text, every key explicit) and Checker (each value in its range). A visitor V has
//   Number(key, double&, Range)      Integer(key, Int&, Range = kAny)   Bool(key, bool&)
//   String(key, std::string&)        Choice(key, E&, names)              Servo(key, ServoModel3&)
//   Table(key, fields, present = true)   Effects(key, EffectSet&, bool& same_sample)
//   Renamed(key, message)  (a key that was renamed: the reader refuses it with the message)
// Ranges may depend on other fields and on dt (given by the Context); checks that need files
// or several keys at once are in the Validate* functions after the walk.

/// What a range may depend on besides the table's own fields.
struct Context {
  double dt_s;
  std::int64_t steps;
};

template <typename V>
void SignalFields(V& v, SignalSpec& s, std::string_view rms_key, const Context& cx) {
  v.Choice("kind", s.kind, signal::kSignalKindNames);
  v.Number("band_hz", s.band_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
  v.Number(rms_key, s.rms, Open(0.0, kInf));
  v.Integer("seed", s.seed);
  v.Number("discard_s", s.discard_s, Closed(0.0, 60.0));
  v.String("file", s.file);
  v.Number("file_dt_s", s.file_dt_s, Closed(0.0, 10.0));
  v.Number("scale", s.scale, kAny);  // finite and not 0: ValidateSignal
  v.Number("taper_s", s.taper_s, Closed(0.0, 60.0));
  v.Number("start_s", s.start_s, Closed(0.0, 3600.0));
}

template <typename V>
void RunFields(V& v, RunConfig& r, const Context&) {
  v.String("name", r.name);
  v.Number("dt_s", r.dt_s, Closed(1e-5, 0.01));
  v.Number("duration_s", r.duration_s, OpenClosed(0.0, 36000.0));
  v.Integer("csv_every", r.csv_every, Closed(0.0, 1e9));
}

template <typename V>
void StructureFields(V& v, StructureConfig& st, const Context& cx) {
  v.Choice("mode", st.mode, models::kStructureModeNames);
  v.Number("mass_kg", st.mass_kg, OpenClosed(0.0, 1e9));
  // Central difference is stable for omega dt < 2, i.e. f < 1 / (pi dt).
  v.Number("frequency_hz", st.frequency_hz,
           {0.0, 1.0 / (kPi * cx.dt_s), true, true, "central-difference stability limit 1/(pi run.dt_s)"});
  v.Number("damping_ratio", st.damping_ratio, ClosedOpen(0.0, 1.0));
  v.Number("specimen_count", st.specimen_count, OpenClosed(0.0, 1000.0));
  v.Choice("derivatives", st.derivatives, models::kDerivativesNames);
  v.Choice("kind", st.kind, models::kStructureKindNames);
  v.String("file", st.file);
  v.String("reference_file", st.reference_file);  // ValidateStructure: only with kind = "file"
  v.Integer("actuator_dof", st.actuator_dof);  // ValidateStructure: when kind = "file"
  v.Table("ground", [&](V& t) { SignalFields(t, st.ground, "rms_mm_s2", cx); });
  v.Table("desired", [&](V& t) { SignalFields(t, st.desired, "rms_mm", cx); });
}

template <typename V>
void ControllerFields(V& v, ControllerConfig& c, const Context& cx) {
  v.Choice("kind", c.kind, control::kControllerKindNames);
  v.Servo("model", c.model);
  v.Bool("half_step_ahead", c.half_step_ahead);
  v.Number("delay_ms", c.delay_ms,
           {0.0, c.max_delay_ms, true, false,
            "extrapolation beyond controller.max_delay_ms amplifies noise too much; raise that bound "
            "deliberately if you mean it"});
  v.Number("max_delay_ms", c.max_delay_ms, OpenClosed(0.0, 100.0));
  v.Number("lead_tp_ms", c.lead_tp_ms, OpenClosed(0.0, 100.0));
  const bool uses_lp = c.kind == control::ControllerKind::kFfLp || c.kind == control::ControllerKind::kBumplessLp;
  v.Number("lp_cutoff_hz", c.lp_cutoff_hz,
           {0.0, uses_lp ? 0.5 / cx.dt_s : kInf, true, true, uses_lp ? "below the Nyquist frequency 0.5/run.dt_s" : ""});
  v.Integer("lp_order", c.lp_order, {3, 8, false, false, "the three-pole inverse needs at least order 3 to be proper"});
  v.Servo("model_low", c.model_low);
  v.Servo("model_high", c.model_high);
  v.Number("current_high_A", c.current_high_A, OpenClosed(0.0, 5.0));
  v.Table("lqg", [&](V& t) {
    t.Number("q", c.lqg.q, OpenClosed(0.0, 1e12));
    t.Number("w_f_hz", c.lqg.w_f_hz, OpenClosed(0.0, 1000.0));
    t.Number("xi_f", c.lqg.xi_f, OpenClosed(0.0, 10.0));
    t.Number("eta_f", c.lqg.eta_f, Closed(0.0, 100.0));
    t.Number("W", c.lqg.W, OpenClosed(0.0, 1e12));
    t.Number("V", c.lqg.V, OpenClosed(0.0, 1e12));
  });
  v.Table("lti", [&](V& t) {
    t.Tf("feedback", c.lti.feedback);
    t.Tf("reference", c.lti.reference);
    t.Choice("domain", c.lti.domain, control::kTfDomainNames);
    t.Choice("discretisation", c.lti.discretisation, control::kDiscretisationNames);
    t.Bool("allow_unstable", c.lti.allow_unstable);
    t.Number("saturation_mm", c.lti.saturation_mm, {0.0, 1e6, false, false, "0 for no limit"});
    t.Number("rate_limit_mm_s", c.lti.rate_limit_mm_s, {0.0, 1e9, false, false, "0 for no limit"});
  });
  // [controller.ats] and [controller.ambc]: per-key ranges here; bounds against each other and the
  // initial values, the window against dt: ValidateController (the designs' own checks).
  v.Table("ats", [&](V& t) {
    control::AtsConfig& a = c.ats;
    t.Numbers("initial", a.initial, Closed(-1e6, 1e6));
    t.Numbers("lower", a.lower, Closed(-1e6, 1e6));
    t.Numbers("upper", a.upper, Closed(-1e6, 1e6));
    t.Numbers("max_rate_per_s", a.max_rate_per_s, OpenClosed(0.0, 1e12));
    t.Number("window_s", a.window_s, OpenClosed(0.0, 100.0));
    t.Integer("skip", a.skip, Closed(1, 1e6));
    t.Number("filter_hz", a.filter_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
    t.Integer("filter_order", a.filter_order, Closed(1, 8));
    t.Number("threshold_mm", a.threshold_mm, Closed(0.0, 1e4));
    t.Choice("derivatives", a.derivatives, control::kTargetDerivativesNames);
  });
  v.Table("ambc", [&](V& t) {
    control::AmbcConfig& a = c.ambc;
    t.Choice("start", a.start, control::kAmbcStartNames);
    t.Numbers("initial", a.initial, Closed(-1e6, 1e6));
    t.Numbers("gain_log10", a.gain_log10, Closed(-30.0, 30.0));
    t.Numbers("lower", a.lower, Closed(-1e12, 1e12));
    t.Numbers("upper", a.upper, Closed(-1e12, 1e12));
    t.Number("filter_hz", a.filter_hz, {0.0, 0.5 / cx.dt_s, true, true, "below the Nyquist frequency 0.5/run.dt_s"});
    t.Integer("filter_order", a.filter_order, Closed(1, 8));
    t.Choice("derivatives", a.derivatives, control::kTargetDerivativesNames);
  });
}

template <typename V>
void PhysicalFields(V& v, PhysicalActuatorConfig& p) {
  v.Number("area_m2", p.area_m2, OpenClosed(0, 1));
  v.Number("supply_pressure_Pa", p.supply_pressure_Pa, OpenClosed(0, 1e9));
  v.Number("volume_m3", p.volume_m3, OpenClosed(0, 1));
  v.Number("piston_mass_kg", p.piston_mass_kg, OpenClosed(0, 1e5));
  v.Number("piston_damping_N_s_m", p.piston_damping_N_s_m, Closed(0, 1e9));
  v.Number("valve_hz", p.valve_hz, OpenClosed(0, 1e4));
  v.Number("valve_zeta", p.valve_zeta, OpenClosed(0, 10));
  v.Number("kq_m3_s", p.kq_m3_s, OpenClosed(0, 10));
  v.Number("kp_per_m", p.kp_per_m, OpenClosed(0, 1e6));
  v.Number("beta_Pa", p.beta_Pa, OpenClosed(0, 1e12));
  v.Number("leakage_m3_s_Pa", p.leakage_m3_s_Pa, Closed(0, 1e-6));
}

/// Every MrDamperParams field; their ranges are the model's own (MrDamperParams::Validate).
template <typename V>
void DamperFields(V& v, models::MrDamperParams& d) {
  for (const models::MrDamperField& f : models::kMrDamperFields) v.Number(f.key, d.*f.member, kAny);
}

/// `[plant.benchmark]`: the benchmark's plant constants (SI, models::BenchmarkPlantParams) and
/// its DAQ. Per-key ranges here; Gp's stability is ValidatePlant's (ValidateBenchmarkParams).
template <typename V>
void BenchmarkFields(V& v, models::BenchmarkRigConfig& b) {
  models::BenchmarkPlantParams& p = b.params;
  v.Number("gain", p.gain, Open(0.0, kInf));
  v.Number("a1b0", p.a1b0, Open(0.0, kInf));
  v.Number("a2", p.a2, ClosedOpen(0.0, kInf));
  v.Number("a3", p.a3, {-kInf, kInf, true, true, "any finite value; Gp must stay stable"});
  v.Number("b1", p.b1, Open(0.0, kInf));
  v.Number("b2", p.b2, Open(0.0, kInf));
  v.Number("m_e_kg", p.m_e_kg, Open(0.0, kInf));
  v.Number("k_e_N_per_m", p.k_e_N_per_m, Open(0.0, kInf));
  v.Number("zeta_e", p.zeta_e, ClosedOpen(0.0, kInf));
  v.Table("daq", [&](V& t) {
    t.Bool("enabled", b.daq.enabled);
    t.Number("volts_per_m", b.daq.volts_per_m, Open(0.0, kInf));
    t.Number("saturation_V", b.daq.saturation_V, Open(0.0, kInf));
    t.Integer("bits", b.daq.bits, Closed(2, 32));
  });
}

template <typename V>
void PlantFields(V& v, PlantConfig& p, const Context& cx) {
  v.Choice("kind", p.kind, models::kPlantKindNames);
  v.Servo("actuator", p.actuator);
  v.Choice("specimen", p.specimen, models::kSpecimenNames);
  v.Bool("current_dynamics", p.current_dynamics);
  v.Number("noise_y_mm_rms", p.noise_y_mm_rms, Closed(0.0, 10.0));
  v.Number("noise_f_kN_rms", p.noise_f_kN_rms, Closed(0.0, 100.0));
  v.Integer("noise_seed", p.noise_seed);
  v.Number("cvode_rtol", p.cvode_rtol, OpenClosed(0.0, 1e-2));
  v.Table("physical", [&](V& t) { PhysicalFields(t, p.physical); });
  v.Table("benchmark", [&](V& t) { BenchmarkFields(t, p.benchmark); });
  v.Table("damper", [&](V& t) { DamperFields(t, p.damper); });
  v.Table("current_driver", [&](V& t) {
    models::CurrentDriverParams& d = p.current_driver;
    t.Choice("kind", d.kind, models::kCurrentFilterNames);
    t.Number("eta_1_s", d.eta_1_s, OpenClosed(0.0, 1e6));
    t.Number("lag_pole_rad_s", d.lag_pole_rad_s, OpenClosed(0.0, 1e6));
    t.Number("lag_zero_rad_s", d.lag_zero_rad_s, OpenClosed(0.0, 1e6));
    t.Number("lowpass_hz", d.lowpass_hz, OpenClosed(0.0, 1e6));
    t.Number("lowpass_zeta", d.lowpass_zeta, {0.0, 1.0, true, true});
  });
  v.Table("unmodelled", [&](V& t) {
    UnmodelledConfig& u = p.unmodelled;
    t.Number("ripple_mm", u.ripple_mm, Closed(0.0, 10.0));
    t.Number("ripple_hz", u.ripple_hz,
             {0.0, 0.5 / cx.dt_s, u.ripple_mm > 0.0, true,
              u.ripple_mm > 0.0 ? "a ripple needs a frequency below the Nyquist frequency 0.5/run.dt_s"
                                : "below the Nyquist frequency 0.5/run.dt_s"});
    t.Number("stiffness_kN_per_mm", u.stiffness_kN_per_mm, Closed(-100.0, 100.0));
  });
  v.Effects("effects", p.effects, p.load_coupling_same_sample);
}

template <typename V>
void SemiactiveFields(V& v, SemiactiveConfig& s, const Context& cx) {
  v.Choice("mode", s.mode, control::kSemiactiveModeNames);
  v.Number("current_A", s.current_A, {0.0, s.max_current_A, false, false, "at most semiactive.max_current_A"});
  v.Number("max_current_A", s.max_current_A, OpenClosed(0.0, 5.0));
  v.Number("pulse_hz", s.pulse_hz,
           {0.0, 0.25 / cx.dt_s, true, true, "at least four steps per period: below 0.25/run.dt_s"});
  v.Number("pulse_duty", s.pulse_duty, Open(0.0, 1.0));
  v.Integer("pulse_seed", s.pulse_seed);
  v.Number("r_weight", s.r_weight, OpenClosed(0.0, 1e6));
  v.Number("noise_ratio", s.noise_ratio, OpenClosed(0.0, 1e6));
  v.Number("capacity_kN", s.capacity_kN, OpenClosed(0.0, 1e6));
}

template <typename V>
void SafetyFields(V& v, SafetyConfig& f, const Context&) {
  v.Bool("enabled", f.enabled);
  v.Number("stroke_mm", f.stroke_mm, OpenClosed(0.0, 10000.0));
  v.Number("force_kN", f.force_kN, OpenClosed(0.0, 1e6));
  v.Number("max_error_mm", f.max_error_mm, OpenClosed(0.0, 10000.0));
  v.Number("growth_window_s", f.growth_window_s, OpenClosed(0.0, 10.0));
  v.Number("growth_factor", f.growth_factor, OpenClosed(1.0, 1000.0));
  v.Integer("growth_windows", f.growth_windows, Closed(2, 1000));
  v.Number("growth_floor_mm", f.growth_floor_mm, OpenClosed(0.0, 10000.0));
}

template <typename V>
void LockstepFields(V& v, LockstepConfig& l, const Context&) {
  v.Renamed("timeout_ms", "was renamed lockstep.rerequest_ms (re-request an incomplete step after this silence "
                          "[ms], [5, 10000]); the give-up time is lockstep.stall_budget_s");
  v.Renamed("max_attempts", "was replaced by lockstep.stall_budget_s: how long one step may stay incomplete "
                            "before the run stops [s], [1, 3600] (default 10)");
  // Below ~5 ms a re-request would come before a loaded 2-core host has even scheduled the
  // participants once: it only adds traffic.
  v.Number("rerequest_ms", l.rerequest_ms, Closed(5.0, 10000.0));
  v.Number("stall_budget_s", l.stall_budget_s,
           {std::max(1.0, 4e-3 * l.rerequest_ms), 3600.0, false, false, "at least 1 s and 4 lockstep.rerequest_ms"});
  v.Number("handshake_timeout_s", l.handshake_timeout_s, Closed(0.1, 600.0));
}

template <typename V>
void RealtimeFields(V& v, RealtimeConfig& r, const Context&) {
  v.Bool("enabled", r.enabled);
  v.Integer("max_consecutive_misses", r.max_consecutive_misses, Closed(0.0, 1e9));
  v.Bool("sched_fifo", r.sched_fifo);
  v.Integer("priority", r.priority, Closed(1, 99));
  v.Bool("lock_memory", r.lock_memory);
}

template <typename V>
void FaultFields(V& v, FaultConfig& f, const Context& cx) {
  for (auto [key, field] : {std::pair{"drop", &f.drop}, {"duplicate", &f.duplicate}, {"delay", &f.delay},
                            {"reorder", &f.reorder}}) {
    v.Number(key, *field, Closed(0.0, 0.5));
  }
  v.Number("delay_ms", f.delay_ms, OpenClosed(0.0, 10000.0));
  v.Integer("seed", f.seed, Closed(0.0, 9007199254740992.0));
  v.Integer("recv_buf_bytes", f.recv_buf_bytes);  // 0 or a range: ValidateFaults
  const bool present = !f.process_role.empty() || f.process_kind != lockstep::ProcessFault::kNone;
  v.Table(
      "process",
      [&](V& t) {
        t.String("role", f.process_role);
        t.Choice("kind", f.process_kind, lockstep::kProcessFaultNames);
        t.Integer("at_step", f.process_at_step,
                  {0.0, static_cast<double>(cx.steps), false, true, "a step of the run: [0, steps)"});
        t.Number("stop_s", f.process_stop_s, Closed(0.0, 3600.0));
      },
      present);
}

template <typename V>
void ScenarioFields(V& v, Scenario& s) {
  const Context cx{s.run.dt_s, s.steps()};
  v.Table("run", [&](V& t) { RunFields(t, s.run, cx); });
  v.Table("structure", [&](V& t) { StructureFields(t, s.structure, cx); });
  v.Table("controller", [&](V& t) { ControllerFields(t, s.controller, cx); });
  v.Table("plant", [&](V& t) { PlantFields(t, s.plant, cx); });
  v.Table("semiactive", [&](V& t) { SemiactiveFields(t, s.semiactive, cx); });
  v.Table("safety", [&](V& t) { SafetyFields(t, s.safety, cx); });
  v.Table("lockstep", [&](V& t) { LockstepFields(t, s.lockstep, cx); });
  v.Table("realtime", [&](V& t) { RealtimeFields(t, s.realtime, cx); });
  v.Table("faults", [&](V& t) { FaultFields(t, s.faults, cx); });
}

// ---------------------------------------------------------------------------------------
// Reader: TOML -> structs (keys and types; ranges are the Checker's).

class Reader {
 public:
  explicit Reader(Section* section) : section_(section) {}

  void Number(std::string_view key, double& v, const Range&) { section_->Number(key, &v); }
  template <typename Int>
  void Integer(std::string_view key, Int& v, const Range& = kAny) {
    section_->Integer(key, &v);
  }
  void Bool(std::string_view key, bool& v) { section_->Bool(key, &v); }
  void String(std::string_view key, std::string& v) { section_->String(key, &v); }
  template <typename E, std::size_t N>
  void Choice(std::string_view key, E& v, const std::array<Named<E>, N>& names) {
    std::string name;
    section_->String(key, &name);  // declares the key
    if (!section_->Has(key)) return;
    const std::optional<E> value = ValueOf(names, name);
    if (!value) section_->Fail(key, fmt::format("\"{}\" is not allowed (allowed: {})", name, QuotedNames(names)));
    v = *value;
  }
  void Servo(std::string_view key, ServoModel3& m) { section_->Servo(key, &m); }
  void Tf(std::string_view key, control::TfCoefficients& tf) { section_->Tf(key, &tf); }
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<double, N>& v, const Range&) { section_->Numbers(key, v.data(), N); }
  template <typename F>
  void Table(std::string_view key, F&& fields, bool /*present*/ = true) {
    Section sub = section_->Sub(key);
    Reader reader(&sub);
    fields(reader);
    sub.Finish();
  }
  void Renamed(std::string_view key, std::string message) {
    if (section_->Has(key)) section_->Fail(key, std::move(message));
  }

  /// [plant.effects]: one sub-table per effect that is on (models::kEffects); an unknown name is
  /// refused by Finish() with the list of the library's names.
  void Effects(std::string_view key, models::EffectSet& out, bool& same_sample) {
    Section effects = section_->Sub(key);
    models::EffectSet e;
    std::vector<Section> tables;
    tables.reserve(models::kEffects.size());
    for (const models::EffectInfo& info : models::kEffects) {
      tables.push_back(effects.Sub(info.name));
      if (tables.back().Present()) info.turn_on(e);
    }
    effects.Finish();
    for (std::size_t i = 0; i < models::kEffects.size(); ++i) {
      const models::EffectInfo& info = models::kEffects[i];
      if (!info.is_on(e)) continue;
      Section& table = tables[i];
      for (const models::EffectParam& p : info.params()) table.Number(p.key, p.field(e));
      if (info.name == "load_coupling") table.Bool("same_sample", &same_sample);  // rig only
      table.Finish();
      for (const models::EffectParam& p : info.params()) {
        if (p.required && !table.Has(p.key)) {
          table.Fail(p.key, fmt::format("missing (the effect \"{}\" needs it; remove the table to switch the "
                                        "effect off)",
                                        info.name));
        }
      }
      bool any = false;
      for (const models::EffectParam& p : info.params()) any = any || table.Has(p.key);
      if (!any) {
        std::string keys;
        for (const models::EffectParam& p : info.params()) keys += (keys.empty() ? "" : ", ") + std::string(p.key);
        table.Fail(info.params()[0].key, fmt::format("missing ({} needs at least one of {})", info.name, keys));
      }
    }
    out = e;
  }

 private:
  Section* section_;
};

// ---------------------------------------------------------------------------------------
// Writer: structs -> TOML text, every key explicit (a table's own keys, then its sub-tables).

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

class Writer {
 public:
  explicit Writer(std::string path) : path_(std::move(path)) {}

  void Number(std::string_view key, double& v, const Range&) { Key(key, TomlNumber(v)); }
  template <typename Int>
  void Integer(std::string_view key, Int& v, const Range& = kAny) {
    Key(key, fmt::format("{}", v));
  }
  void Bool(std::string_view key, bool& v) { Key(key, v ? "true" : "false"); }
  void String(std::string_view key, std::string& v) { Key(key, TomlString(v)); }
  template <typename E, std::size_t N>
  void Choice(std::string_view key, E& v, const std::array<Named<E>, N>& names) {
    Key(key, TomlString(std::string(NameOf(names, v))));
  }
  void Servo(std::string_view key, ServoModel3& m) { Key(key, TomlServo(m)); }
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<double, N>& v, const Range&) {
    std::string t = "[";
    for (std::size_t i = 0; i < N; ++i) t += (i ? ", " : "") + TomlNumber(v[i]);
    Key(key, t + "]");
  }
  void Tf(std::string_view key, control::TfCoefficients& tf) {
    if (tf.Empty()) return;  // the default, 1
    auto list = [](const std::vector<double>& v) {
      std::string t = "[";
      for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + TomlNumber(v[i]);
      return t + "]";
    };
    Key(key, fmt::format("{{ num = {}, den = {} }}", list(tf.num), list(tf.den)));
  }
  template <typename F>
  void Table(std::string_view key, F&& fields, bool present = true) {
    if (!present) return;
    Writer sub(Join(key));
    fields(sub);
    tables_ += sub.Text();
  }
  void Renamed(std::string_view, const std::string&) {}
  void Effects(std::string_view key, models::EffectSet& e, bool& same_sample) {
    for (const models::EffectInfo& info : models::kEffects) {
      if (!info.is_on(e)) continue;
      Writer table(Join(key) + "." + std::string(info.name));
      for (const models::EffectParam& p : info.params()) table.Number(p.key, *p.field(e), kAny);
      if (info.name == "load_coupling") table.Bool("same_sample", same_sample);
      tables_ += table.Text();
    }
  }

  /// "\n[path]\n" and the keys (if the table has keys of its own), then the sub-tables.
  std::string Text() const { return (keys_.empty() ? "" : fmt::format("\n[{}]\n", path_) + keys_) + tables_; }

 private:
  std::string Join(std::string_view key) const { return path_.empty() ? std::string(key) : path_ + "." + std::string(key); }
  void Key(std::string_view key, const std::string& value) { keys_ += fmt::format("{} = {}\n", key, value); }

  std::string path_;
  std::string keys_;
  std::string tables_;
};

// ---------------------------------------------------------------------------------------
// Checker: every value in its range; messages name "<file>: <dotted.key>".

class Checker {
 public:
  Checker(const Check* check, std::string prefix, double dt_s)
      : check_(check), prefix_(std::move(prefix)), dt_s_(dt_s) {}

  void Number(std::string_view key, double& v, const Range& r) { check_->InRange(Dotted(key), v, r); }
  template <typename Int>
  void Integer(std::string_view key, Int& v, const Range& r = kAny) {
    check_->InRange(Dotted(key), static_cast<double>(v), r);
  }
  void Bool(std::string_view, bool&) {}
  void String(std::string_view, std::string&) {}
  template <typename E, std::size_t N>
  void Choice(std::string_view key, E& v, const std::array<Named<E>, N>& names) {
    if (NameOf(names, v).empty()) {
      check_->Fail(Dotted(key), fmt::format("not set (allowed: {})", QuotedNames(names)));
    }
  }
  void Servo(std::string_view key, ServoModel3& m) { ValidateServo(m, Dotted(key), *check_); }
  void Tf(std::string_view, control::TfCoefficients&) {}  // ValidateController: CheckTf and stability
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<double, N>& v, const Range& r) {
    for (std::size_t i = 0; i < N; ++i) check_->InRange(fmt::format("{}[{}]", Dotted(key), i), v[i], r);
  }
  template <typename F>
  void Table(std::string_view key, F&& fields, bool present = true) {
    if (!present) return;
    Checker sub(check_, Dotted(key) + ".", dt_s_);
    fields(sub);
  }
  void Renamed(std::string_view, const std::string&) {}
  /// The library's ranges (models::kEffects) at run.dt_s.
  void Effects(std::string_view key, models::EffectSet& e, bool&) {
    for (const models::EffectInfo& info : models::kEffects) {
      for (const models::EffectParam& p : info.params()) {
        const double* v = p.field(e);
        if (v == nullptr) continue;
        const Range range{p.lo, p.Hi(dt_s_), p.lo_open, p.hi_open,
                          p.hi_per_dt > 0.0 ? fmt::format("below {}/run.dt_s", p.hi_per_dt) : ""};
        check_->InRange(fmt::format("{}.{}.{}", Dotted(key), info.name, p.key), *v, range);
      }
    }
  }

 private:
  std::string Dotted(std::string_view key) const { return prefix_ + std::string(key); }

  const Check* check_;
  std::string prefix_;
  double dt_s_;
};

// ---------------------------------------------------------------------------------------
// Checks across keys and against files (after the per-key ranges).

/// Where a `kind = "file"` path points: relative paths are relative to the scenario's folder.
std::filesystem::path ResolveSignalFile(const std::string& scenario_path, const std::string& file) {
  std::filesystem::path p(file);
  if (p.is_relative()) p = std::filesystem::path(scenario_path).parent_path() / p;
  return std::filesystem::absolute(p).lexically_normal();
}

void CheckFileExists(const Check& check, const std::string& key, const std::string& scenario_path,
                     const std::string& file) {
  const std::filesystem::path resolved = ResolveSignalFile(scenario_path, file);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(resolved, ec)) {
    check.Fail(key, fmt::format("file not found: {} (paths are relative to the scenario file's folder)",
                                resolved.string()));
  }
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
  if (r.duration_s < r.dt_s) {
    check.Fail("run.duration_s", fmt::format("{} is shorter than one step (run.dt_s = {})", r.duration_s, r.dt_s));
  }
}

void ValidateSignal(const SignalSpec& s, std::string_view prefix, const std::string& scenario_path,
                    const Check& check) {
  auto key = [&](std::string_view k) { return fmt::format("{}.{}", prefix, k); };
  if (!std::isfinite(s.scale) || s.scale == 0.0) {
    check.Fail(key("scale"), fmt::format("{} is not allowed (allowed: any finite value other than 0)", s.scale));
  }
  if (s.kind == signal::SignalKind::kFile) {
    if (s.file.empty()) check.Fail(key("file"), "missing: kind = \"file\" needs a file path");
    CheckFileExists(check, key("file"), scenario_path, s.file);
  }
}

/// The controller's design checks that span keys (an `lti` transfer function's coefficients and
/// poles; the bounds, initial values and windows of `ats` and `ambc`): the design is made once
/// here, as the participant will make it, and its error is given the scenario's file name.
void ValidateController(const ControllerConfig& c, double dt_s, const Check& check) {
  try {
    if (c.kind == control::ControllerKind::kLti) control::MakeLtiDesign(c.lti, dt_s);
    if (c.kind == control::ControllerKind::kAts) control::MakeAtsDesign(c.ats, dt_s);
    if (c.kind == control::ControllerKind::kAmbc) control::MakeAmbcDesign(c.ambc, c.model, dt_s);
  } catch (const Error& e) {
    check.Fail(e.where(), e.problem());
  }
}

/// structure.reference_file (the benchmark criteria's monolithic reference, io/benchmark_run.h):
/// only beside a structure file, loadable, with as many DOFs as structure.file.
void ValidateReferenceFile(const StructureConfig& st, const std::string& scenario_path, const Check& check) {
  const char* key = "structure.reference_file";
  if (st.mode != models::StructureMode::kRths || st.kind != models::StructureKind::kFile) {
    check.Fail(key, fmt::format("needs structure.mode = \"rths\" and structure.kind = \"file\" (got \"{}\", \"{}\"): "
                                "the reference is compared with a structure file's floors; leave it \"\" otherwise",
                                NameOf(models::kStructureModeNames, st.mode), NameOf(models::kStructureKindNames, st.kind)));
  }
  CheckFileExists(check, key, scenario_path, st.reference_file);
  models::StructureMatrices ref, run;
  try {
    ref = models::LoadStructureFile(ResolveSignalFile(scenario_path, st.reference_file).string());
  } catch (const Error& e) {
    check.Fail(key, e.what());
  }
  try {
    run = models::LoadStructureFile(ResolveSignalFile(scenario_path, st.file).string());
  } catch (const Error&) {
    return;  // structure.file's own problem, reported where the structure is built
  }
  if (ref.M.rows() != run.M.rows()) {
    check.Fail(key, fmt::format("{} has {} DOFs but structure.file ({}) has {}: they must match",
                                st.reference_file, ref.M.rows(), st.file, run.M.rows()));
  }
}

void ValidateStructure(const StructureConfig& st, const std::string& scenario_path, const Check& check) {
  if (st.mode == models::StructureMode::kRths && st.kind == models::StructureKind::kFile) {
    if (st.file.empty()) check.Fail("structure.file", "missing: kind = \"file\" needs a structure file");
    CheckFileExists(check, "structure.file", scenario_path, st.file);
    check.InRange("structure.actuator_dof", st.actuator_dof,
                  {1, 10000, false, false, "1-based; at most the structure's number of DOFs"});
  } else if (st.mode == models::StructureMode::kRths && st.actuator_dof != 1) {
    check.Fail("structure.actuator_dof", fmt::format("{}: an SDOF structure has one DOF (only kind = \"file\" takes "
                                                     "another)",
                                                     st.actuator_dof));
  }
  if (!st.reference_file.empty()) ValidateReferenceFile(st, scenario_path, check);
  ValidateSignal(st.ground, "structure.ground", scenario_path, check);
  ValidateSignal(st.desired, "structure.desired", scenario_path, check);
}

void ValidatePlant(const PlantConfig& p, const Check& check) {
  try {
    p.damper.Validate();
  } catch (const Error& e) {
    // "MrDamperParams: alpha_a" -> plant.damper.alpha_a
    const std::string& w = e.where();
    const std::size_t colon = w.rfind(": ");
    check.Fail(fmt::format("plant.damper.{}", colon == std::string::npos ? w : w.substr(colon + 2)), e.problem());
  }
  // The benchmark plant's stability (its keys' ranges are checked already): every kind, like
  // plant.damper, so a table that cannot run is refused even while another kind is chosen.
  models::ValidateBenchmarkParams(p.benchmark.params, fmt::format("{}: plant.benchmark", check.file()));
  models::ValidateBenchmarkDaq(p.benchmark.daq, fmt::format("{}: plant.benchmark.daq", check.file()));
  if (p.current_driver.kind == models::CurrentFilter::kEq40 &&
      p.current_driver.lag_zero_rad_s == p.current_driver.lag_pole_rad_s)
    check.Fail("plant.current_driver.lag_zero_rad_s",
               fmt::format("{} equals lag_pole_rad_s: Eq. 40 needs a zero apart from its pole",
                           p.current_driver.lag_zero_rad_s));
  if (p.RigMode() && p.kind != models::PlantKind::kLinear) {
    check.Fail(p.effects.Empty() ? "plant.unmodelled" : "plant.effects",
               fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act around the "
                           "linear actuator model",
                           NameOf(models::kPlantKindNames, p.kind)));
  }
}

void ValidateFaults(const FaultConfig& f, const Check& check) {
  if (const double sum = f.drop + f.duplicate + f.delay + f.reorder; !(sum <= 0.5 + 1e-12)) {
    check.Fail("faults", fmt::format("drop + duplicate + delay + reorder = {} + {} + {} + {} = {:.6g}: the sum must not "
                                     "exceed 0.5 (each in [0, 0.5])",
                                     f.drop, f.duplicate, f.delay, f.reorder, sum));
  }
  if (f.recv_buf_bytes != 0) {
    check.InRange("faults.recv_buf_bytes", static_cast<double>(f.recv_buf_bytes),
                  {1024.0, 134217728.0, false, false, "0 for the host's default, else [1024, 2^27]"});
  }
  if (f.process_role.empty() && f.process_kind == lockstep::ProcessFault::kNone) return;
  check.OneOf("faults.process.role", f.process_role, {"integrator", "controller", "plant", "semiactive", "logger"});
  if (f.process_kind == lockstep::ProcessFault::kNone) {
    check.Fail("faults.process.kind", fmt::format("missing (allowed: {})", QuotedNames(lockstep::kProcessFaultNames)));
  }
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
  Scenario copy = s;  // the visitors take mutable references
  Checker checker(&check, "", s.run.dt_s);
  // run.dt_s and run.duration_s first: every other range and check depends on them.
  checker.Table("run", [&](Checker& t) { RunFields(t, copy.run, Context{s.run.dt_s, s.steps()}); });
  ValidateRun(s.run, check);
  ScenarioFields(checker, copy);
  ValidateStructure(s.structure, s.path, check);
  if (s.semiactive.mode == control::SemiactiveMode::kClippedOptimal &&
      s.structure.mode != models::StructureMode::kRths) {
    check.Fail("semiactive.mode", "\"clipped_optimal\" needs a structure to control (structure.mode = \"rths\")");
  }
  ValidateController(s.controller, s.run.dt_s, check);
  ValidatePlant(s.plant, check);
  ValidateFaults(s.faults, check);
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
  Section top(file, &root, "");
  Reader reader(&top);
  ScenarioFields(reader, s);
  top.Finish();
  ValidateScenario(s);
  for (SignalSpec* signal : {&s.structure.ground, &s.structure.desired}) {
    if (signal->kind == signal::SignalKind::kFile) signal->file = ResolveSignalFile(path, signal->file).string();
  }
  if (!s.structure.file.empty()) s.structure.file = ResolveSignalFile(path, s.structure.file).string();
  if (!s.structure.reference_file.empty())
    s.structure.reference_file = ResolveSignalFile(path, s.structure.reference_file).string();
  return s;
}

std::string ToToml(const Scenario& s) {
  Scenario copy = s;  // the visitors take mutable references
  Writer writer("");
  ScenarioFields(writer, copy);
  return "# Written by rths (scenario::ToToml): every key, explicit.\n" + writer.Text();
}

namespace {

/// The bytes of a scenario file. Throws rths::Error naming `path` if it is a folder (a run folder
/// given by mistake, say) or cannot be read.
std::string ReadScenarioFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(path, "is a folder, not a scenario file (give a .toml file, e.g. scenarios/default.toml; a run "
                      "folder's scenario is RUN_DIR/scenario.toml)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open scenario file");
  std::string bytes;
  try {
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {
    throw Error(path, std::string("cannot read scenario file: ") + e.what());
  }
  if (in.bad()) throw Error(path, "cannot read scenario file");
  return bytes;
}

}  // namespace

Scenario LoadScenario(const std::string& path) {
  const std::string bytes = ReadScenarioFile(path);
  Scenario s = ParseScenario(bytes, path);
  s.sha256 = Sha256Hex(bytes);
  return s;
}

namespace {

/// "run.duration_s" -> {"run", "duration_s"}; quoted parts are not supported (no scenario key needs them).
std::vector<std::string> SplitDotted(const std::string& key) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : key) {
    if (c == '.') {
      parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  parts.push_back(part);
  return parts;
}

/// Rethrows a validation error about a key that --set changed with the --set argument named: the
/// error's key (after "FILE: ") is the set key, a table holding it ("foo" for --set foo.bar=1, an
/// unknown table), or a key inside it. A --set of exactly the error's key is named alone (the last
/// one: it is in force); else every --set inside the table (a sum over its keys, say).
[[noreturn]] void RethrowWithSet(const Error& e, const std::vector<std::string>& sets) {
  const std::string& where = e.where();
  const auto colon = where.rfind(": ");
  const std::string wkey = colon == std::string::npos ? where : where.substr(colon + 2);
  const auto within = [](const std::string& inner, const std::string& outer) {
    return inner == outer || (inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
                              inner[outer.size()] == '.');
  };
  std::string exact, inside;
  for (const auto& set : sets) {
    const std::string key(Trim(std::string_view(set).substr(0, set.find('=')), kTomlWhitespace));
    if (key.empty() || wkey.empty()) continue;
    if (key == wkey) exact = set;
    if (within(key, wkey) || within(wkey, key)) inside += (inside.empty() ? "--set " : ", --set ") + set;
  }
  if (!exact.empty()) throw Error(where, e.problem() + " (set by --set " + exact + ")");
  if (!inside.empty()) throw Error(where, e.problem() + " (set by " + inside + ")");
  throw e;
}

}  // namespace

std::string ApplyOverrides(std::string_view toml_text, const std::vector<std::string>& sets, const std::string& path) {
  toml::table root;
  try {
    root = toml::parse(toml_text, path);
  } catch (const toml::parse_error& e) {
    const toml::source_position& at = e.source().begin;
    throw Error(fmt::format("{}:{}:{}", DisplayName(path), at.line, at.column),
                fmt::format("TOML syntax error at line {}, column {}: {}", at.line, at.column, e.description()));
  }
  for (const auto& set : sets) {
    const auto eq = set.find('=');
    const std::string key =
        eq == std::string::npos ? "" : std::string(Trim(std::string_view(set).substr(0, eq), kTomlWhitespace));
    if (eq == std::string::npos || key.empty()) {
      throw Error("--set " + set, "expected KEY=VALUE with a dotted scenario key, e.g. --set run.duration_s=5 "
                                  "(every key: docs/scenarios.md)");
    }
    const std::string text(Trim(std::string_view(set).substr(eq + 1), kTomlWhitespace));
    toml::table value_table;
    try {
      value_table = toml::parse("v = " + text);
    } catch (const toml::parse_error&) {
      // Not a TOML value: a bare word is a string (--set controller.kind=ff_lqg).
      value_table = toml::table{{"v", text}};
    }
    const std::vector<std::string> parts = SplitDotted(key);
    toml::table* t = &root;
    std::string walked;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (parts[i].empty()) throw Error("--set " + set, fmt::format("\"{}\": empty part in the dotted key", key));
      walked += (walked.empty() ? "" : ".") + parts[i];
      toml::node* next = t->get(parts[i]);
      if (next == nullptr) {
        t = t->insert_or_assign(parts[i], toml::table{}).first->second.as_table();
      } else if (next->is_table()) {
        t = next->as_table();
      } else {
        throw Error("--set " + set, fmt::format("{} is a value in the scenario, not a table, so {} cannot be set",
                                                walked, key));
      }
    }
    if (parts.back().empty()) throw Error("--set " + set, fmt::format("\"{}\": empty part in the dotted key", key));
    value_table.get("v")->visit([&](auto&& v) { t->insert_or_assign(parts.back(), v); });
  }
  std::ostringstream out;
  out << root << "\n";
  return out.str();
}

Scenario LoadScenario(const std::string& path, const std::vector<std::string>& sets) {
  if (sets.empty()) return LoadScenario(path);
  const std::string bytes = ReadScenarioFile(path);
  const std::string text = ApplyOverrides(bytes, sets, path);
  try {
    Scenario s = ParseScenario(text, path);
    s.sha256 = Sha256Hex(text);
    return s;
  } catch (const Error& e) {
    RethrowWithSet(e, sets);
  }
}

Scenario WithOverrides(const Scenario& s, const std::vector<std::string>& sets) {
  if (sets.empty()) return s;
  const std::string text = ApplyOverrides(ToToml(s), sets, s.path);
  try {
    Scenario out = ParseScenario(text, s.path);
    out.sha256 = Sha256Hex(text);
    return out;
  } catch (const Error& e) {
    RethrowWithSet(e, sets);
  }
}

}  // namespace rths::scenario
