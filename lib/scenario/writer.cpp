/// @file The Writer: structs -> TOML text, every key explicit (a table's own keys, then its sub-tables).
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/names.h"
#include "scenario/fields.h"
#include "scenario/walk.h"

namespace rths::scenario::detail {

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
std::string TomlServo(const models::ServoModel3& m) {
  if (m.name != "custom") {
    const models::ServoModel3 preset = models::ServoPreset(m.name);
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
  void Servo(std::string_view key, models::ServoModel3& m) { Key(key, TomlServo(m)); }
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<double, N>& v, const Range&) {
    std::string t = "[";
    for (std::size_t i = 0; i < N; ++i) t += (i ? ", " : "") + TomlNumber(v[i]);
    Key(key, t + "]");
  }
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<int, N>& v, const Range&) {
    std::string t = "[";
    for (std::size_t i = 0; i < N; ++i) t += fmt::format("{}{}", i ? ", " : "", v[i]);
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
  void Alias(std::string_view, std::string_view, double&, std::string_view) {}  // written under its key
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

}  // namespace
}  // namespace rths::scenario::detail

namespace rths::scenario {

std::string ToToml(const Scenario& s) {
  Scenario copy = s;  // the visitors take mutable references
  detail::Writer writer("");
  detail::ScenarioFields(writer, copy);
  return "# Written by rths (scenario::ToToml): every key, explicit.\n" + writer.Text();
}

}  // namespace rths::scenario
