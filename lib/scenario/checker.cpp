/// @file The Checker: every value in its range; messages name "<file>: <dotted.key>".
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/names.h"
#include "scenario/fields.h"
#include "scenario/walk.h"

namespace rths::scenario::detail {

namespace {

void ValidateServo(const models::ServoModel3& m, std::string_view key, const Check& check) {
  for (auto [name, v] : {std::pair{"K", m.K}, {"p", m.p}, {"b", m.b}, {"c", m.c}}) {
    check.InRange(fmt::format("{}.{}", key, name), v,
                  {0.0, kInf, true, true, "K, p, b, c must all be > 0: stable, minimum phase"});
  }
}

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
  void Servo(std::string_view key, models::ServoModel3& m) { ValidateServo(m, Dotted(key), *check_); }
  void Tf(std::string_view, control::TfCoefficients&) {}  // ValidateController: CheckTf and stability
  template <typename T, std::size_t N>
  void Numbers(std::string_view key, std::array<T, N>& v, const Range& r) {
    for (std::size_t i = 0; i < N; ++i) check_->InRange(fmt::format("{}[{}]", Dotted(key), i), v[i], r);
  }
  template <typename F>
  void Table(std::string_view key, F&& fields, bool present = true) {
    if (!present) return;
    Checker sub(check_, Dotted(key) + ".", dt_s_);
    fields(sub);
  }
  void Renamed(std::string_view, const std::string&) {}
  void Alias(std::string_view, std::string_view, double&, std::string_view) {}  // checked under its key
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

}  // namespace

void CheckRunRanges(const Check& check, const Scenario& s) {
  Scenario copy = s;  // the visitors take mutable references
  Checker checker(&check, "", s.run.dt_s);
  checker.Table("run", [&](Checker& t) { RunFields(t, copy.run, Context{s.run.dt_s, s.steps()}); });
}

void CheckRanges(const Check& check, const Scenario& s) {
  Scenario copy = s;
  Checker checker(&check, "", s.run.dt_s);
  ScenarioFields(checker, copy);
}

}  // namespace rths::scenario::detail
