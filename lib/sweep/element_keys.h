#pragma once
/// @file One element of an array-valued scenario key as a [draw] key (issue 43): a SPEC may draw
/// `"controller.lti.feedback.num[0]"` (0-based) so that a Monte Carlo over a PI's gains is one
/// SPEC. The run's drawn value is written in its row and table under that key; the scenario gets
/// the whole array, as `--set controller.lti.feedback.num=[2.31, 95.0]`: the array the key has in
/// the run's case with the sets before it applied (the case's file, [set], the grid, earlier draws),
/// element i replaced. Whole arrays as [set] values and [grid] levels are lib/sweep/spec.h's.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "sweep/spec.h"

namespace rths::sweep {

/// A key `ARRAY_KEY[index]`.
struct ElementKey {
  std::string array_key;  ///< dotted scenario key of the array, e.g. "controller.lti.feedback.num"
  std::size_t index = 0;  ///< 0-based
};

/// "a.b[3]" -> {"a.b", 3}; nullopt for a key without '[' or ']'. Throws rths::Error(where) for a
/// malformed one ("a[x]", "a[1", "a[1].b", an index above 1e6).
std::optional<ElementKey> SplitElementKey(const std::string& key, const std::string& where);

/// The numbers of the array `array_key` in scenario file `scenario` with `sets` (--set KEY=VALUE)
/// applied, each as a TOML literal: the file's text as --set changes it, or, where the key is not
/// written there, the value the scenario takes by default (scenario::ToToml). Throws rths::Error
/// naming the scenario and key when it is not an array of numbers.
std::vector<std::string> ArrayIn(const std::string& scenario, const std::vector<std::string>& sets,
                                 const std::string& array_key);

/// Run p's --set values for scenario::LoadScenario: p.sets with each "KEY[i]=V" replaced by the
/// whole array "KEY=[...]" (ArrayIn with the sets before it, element i set to V). Throws
/// rths::Error for an index beyond the array (the run's row then says so).
std::vector<std::string> ScenarioSets(const RunPoint& p);

/// Checks each element key of spec's [draw] against each case, with [set] applied and each level
/// of a [grid] key of the same array: the array exists and holds the index. Throws rths::Error
/// naming the SPEC file, the key and the allowed range of the index.
void CheckElementKeys(const Spec& spec);

}  // namespace rths::sweep
