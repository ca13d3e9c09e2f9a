#pragma once
/// @file Internal to lib/scenario: the whole schema (ScenarioFields), one table per section.
///
/// The schema: every table's keys, each listed once, in file order, with its allowed range.
/// Three visitors walk it: Reader (TOML -> structs: keys and types), Writer (structs -> TOML
/// text, every key explicit) and Checker (each value in its range). A visitor V has
///   Number(key, double&, Range)      Integer(key, Int&, Range = kAny)   Bool(key, bool&)
///   String(key, std::string&)        Choice(key, E&, names)              Servo(key, ServoModel3&)
///   Table(key, fields, present = true)   Effects(key, EffectSet&, bool& same_sample)
///   Renamed(key, message)  (a key that was renamed: the reader refuses it with the message)
///   Alias(old, key, double&, why)  (an old name of the number `key`: the reader takes it, with a note
///                             printed once; giving both is refused; the writer writes `key`)
/// Ranges may depend on other fields and on dt (given by the Context); checks that need files
/// or several keys at once are in validate.cpp, after the walk.
#include "scenario/fields_controller.h"
#include "scenario/fields_marths.h"
#include "scenario/fields_plant.h"
#include "scenario/fields_run.h"
#include "scenario/fields_structure.h"
#include "scenario/scenario.h"

namespace rths::scenario::detail {

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
  // Written only when set (a scenario without it keeps its text, and its hash, as before [marths]).
  v.Table("marths", [&](V& t) { MarthsFields(t, s.marths, cx); }, !(s.marths == control::MarthsConfig{}));
}

}  // namespace rths::scenario::detail
