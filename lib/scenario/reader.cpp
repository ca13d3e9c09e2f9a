/// @file The Reader: TOML -> structs (keys and types; ranges are the Checker's).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/names.h"
#include "scenario/fields.h"
#include "scenario/walk.h"

namespace rths::scenario::detail {

namespace {

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
  void Servo(std::string_view key, models::ServoModel3& m) { section_->Servo(key, &m); }
  void Tf(std::string_view key, control::TfCoefficients& tf) { section_->Tf(key, &tf); }
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<double, N>& v, const Range&) { section_->Numbers(key, v.data(), N); }
  /// Whole numbers: as Numbers, each an integer.
  template <std::size_t N>
  void Numbers(std::string_view key, std::array<int, N>& v, const Range&) {
    std::array<double, N> read{};
    for (std::size_t i = 0; i < N; ++i) read[i] = v[i];
    section_->Numbers(key, read.data(), N);
    for (std::size_t i = 0; i < N; ++i) {
      if (!(std::abs(read[i]) < 1e9) || read[i] != std::floor(read[i])) {
        section_->Fail(key, fmt::format("element {} is {}: expected an integer", i + 1, read[i]));
      }
      v[i] = static_cast<int>(read[i]);
    }
  }
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
  /// `old_key`, an old name of the number `key`: read into v (after `key`, so giving both is
  /// refused), with a note on stderr once per process saying `why` it was renamed.
  void Alias(std::string_view old_key, std::string_view key, double& v, std::string_view why) {
    section_->Number(old_key, &v);  // declares the key
    if (!section_->Has(old_key)) return;
    if (section_->Has(key)) {
      section_->Fail(old_key,
                     fmt::format("is the old name of {0}; both are given: keep {0} only", section_->DottedName(key)));
    }
    static std::atomic<bool> noted{false};
    if (!noted.exchange(true)) {
      std::fprintf(stderr, "rths: note: %s is the old name of %s (%.*s); it is read as %s and keeps working\n",
                   section_->DottedName(old_key).c_str(), section_->DottedName(key).c_str(),
                   static_cast<int>(why.size()), why.data(), section_->DottedName(key).c_str());
    }
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

}  // namespace

void ReadFields(Section* top, Scenario* s) {
  Reader reader(top);
  ScenarioFields(reader, *s);
}

}  // namespace rths::scenario::detail
