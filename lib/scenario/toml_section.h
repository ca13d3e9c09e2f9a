#pragma once
/// @file Internal to lib/scenario: one TOML table mapped onto a struct (keys and types), and the
/// helpers its messages use. Every failure is an rths::Error(where = "<file>: <dotted.key>", what).
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "control/lti_controller.h"
#include "core/closest_name.h"
#include "core/error.h"
#include "models/servo_linear.h"

namespace rths::scenario::detail {

/// The name used in messages for the scenario's source.
inline std::string DisplayName(const std::string& path) { return path.empty() ? "<scenario text>" : path; }
/// Comma-separated list, each item wrapped in `quote`.
std::string JoinList(const std::vector<std::string_view>& items, std::string_view quote = "");
/// "string \"abc\"", "float 2.5", "table", ... for type errors.
std::string DescribeNode(const toml::node& node);

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
  void Servo(std::string_view key, models::ServoModel3* out) {
    const toml::node* node = Declare(key, false);
    if (node == nullptr) return;
    constexpr std::string_view kExpected =
        "a preset name (\"0.0A\", \"2.5A\", \"avg\") or a table {K = ..., p = ..., b = ..., c = ...}";
    if (const auto* s = node->as_string()) {
      try {
        *out = models::ServoPreset(s->get());
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
    models::ServoModel3 m;
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
      if (std::string_view close = rths::ClosestName(name, allowed); !close.empty()) {
        problem += fmt::format("; did you mean \"{}{}\"?", prefix_, close);
      }
      Fail(name, problem);
    }
  }

  /// The key's dotted name in the scenario ("plant.ode_rtol").
  std::string DottedName(std::string_view key) const { return Dotted(key); }

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

}  // namespace rths::scenario::detail
