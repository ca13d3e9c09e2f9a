#include "ident/fit_status.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace rths::ident {

namespace {

constexpr std::size_t kMarkNames = 2;  // implausible names in Mark()

std::string List(const std::vector<std::string>& names) {
  std::string o = "[";
  for (std::size_t i = 0; i < names.size(); ++i) o += fmt::format("{}\"{}\"", i ? ", " : "", names[i]);
  return o + "]";
}

// What a state means, for a group of parameters in it (`why` their shared reason).
std::string Meaning(const ParameterStatus& p) {
  switch (p.state) {
    case ParameterState::kAtZero:
      return "at the floor of the range, i.e. 0 (the data ask for none of it)";
    case ParameterState::kAtBound:
      return fmt::format("on {} end of the range [{:.3g}, {:.3g}]: the range, not the data, chose it",
                         std::abs(std::log(p.value / p.lo)) < std::abs(std::log(p.value / p.hi)) ? "the lower"
                                                                                                : "the upper",
                         p.lo, p.hi);
    case ParameterState::kHeld:
      return "held, not fitted: " + p.why;
    case ParameterState::kIrrelevant:
      return "irrelevant: " + p.why;
    case ParameterState::kFree:
      break;
  }
  return "fitted";
}

}  // namespace

std::string Implausible::Warning() const {
  return fmt::format("{} = {:.4g} {} is outside the plausible range {:.3g}..{:.3g} {} (docs/identification.md "
                     "\"Plausible ranges\")",
                     name, value, unit, lo, hi, unit);
}

bool FitStatus::Ok() const { return converged && Names(ParameterState::kAtBound).empty(); }

std::string FitStatus::Mark() const {
  std::string o;
  if (!Ok()) {
    const auto bound = Names(ParameterState::kAtBound);
    o = "FIT FAILED: ";
    if (!converged) o += "not converged";
    if (!bound.empty()) {
      std::string names;
      for (const auto& n : bound) names += (names.empty() ? "" : ", ") + n;
      o += fmt::format("{}{} on {} bound{}", converged ? "" : ", ", names, bound.size() == 1 ? "its" : "their",
                       bound.size() == 1 ? "" : "s");
    }
  }
  if (!implausible.empty()) {
    // At most kMarkNames names, then "+N": a figure's title has room for one line.
    std::string names;
    for (std::size_t i = 0; i < implausible.size() && i < kMarkNames; ++i)
      names += (names.empty() ? "" : ", ") + implausible[i].name;
    if (implausible.size() > kMarkNames) names += fmt::format(" +{}", implausible.size() - kMarkNames);
    o += (o.empty() ? "" : "; ") + std::string("implausible: ") + names;
  }
  return o;
}

std::vector<std::string> FitStatus::Names(ParameterState state) const {
  std::vector<std::string> out;
  for (const auto& p : parameters)
    if (p.state == state) out.push_back(p.name);
  return out;
}

std::string FitStatus::Summary() const {
  const std::string iters =
      converged ? fmt::format("converged in {} iterations", iterations)
                : fmt::format("not converged ({} iterations, the limit)", iterations);
  if (Ok()) return fmt::format("ok ({})", iters);
  std::string o = "FAILED: " + iters;
  for (const auto& p : parameters)
    if (p.state == ParameterState::kAtBound) o += fmt::format("; {} = {:.6g} on a bound of its range", p.name, p.value);
  return o;
}

std::string FitStatus::Details(const std::string& indent) const {
  std::string o = indent + "fit status: " + Summary() + "\n";
  // One line per meaning, naming every parameter that has it.
  std::vector<std::pair<std::string, std::string>> lines;  // meaning, "a = 1, b = 2"
  for (const auto& p : parameters) {
    if (p.state == ParameterState::kFree) continue;
    const std::string meaning = Meaning(p), item = fmt::format("{} = {:.6g}", p.name, p.value);
    auto it = std::find_if(lines.begin(), lines.end(), [&](const auto& l) { return l.first == meaning; });
    if (it == lines.end()) lines.emplace_back(meaning, item);
    else it->second += ", " + item;
  }
  for (const auto& [meaning, items] : lines) o += fmt::format("{}  {}: {}\n", indent, items, meaning);
  for (const auto& p : implausible) o += fmt::format("{}  warning: {}\n", indent, p.Warning());
  return o;
}

std::string FitStatus::Comment() const {
  std::string o;
  if (!Ok())
    o += "# FIT FAILED: this model is where the fit stopped, not a converged fit: check it before using it\n"
         "# as the rig's model (rths identify exits 3 for such a fit unless --accept-unconverged).\n";
  const std::string d = Details("");
  std::size_t start = 0;
  while (start < d.size()) {
    const std::size_t end = d.find('\n', start);
    o += "# " + d.substr(start, end - start) + "\n";
    start = end + 1;
  }
  return o;
}

std::string FitStatus::TomlTable() const {
  std::string o = "[fit]\n";
  o += fmt::format("status = \"{}\"\n", Ok() ? "ok" : "failed");
  o += fmt::format("converged = {}\n", converged ? "true" : "false");
  o += fmt::format("iterations = {}\nmax_iterations = {}\n", iterations, max_iterations);
  o += "at_bound = " + List(Names(ParameterState::kAtBound)) + "\n";
  o += "at_zero = " + List(Names(ParameterState::kAtZero)) + "\n";
  o += "held = " + List(Names(ParameterState::kHeld)) + "\n";
  o += "irrelevant = " + List(Names(ParameterState::kIrrelevant)) + "\n";
  std::vector<std::string> flagged;
  for (const auto& p : implausible) flagged.push_back(p.name);
  o += "implausible = " + List(flagged) + "\n";
  return o;
}

ParameterStatus StatusOf(std::string name, double value, double lo, double hi, bool zero_floor) {
  ParameterStatus p{std::move(name), value, lo, hi, ParameterState::kFree, ""};
  const double l = std::log(value);
  if (std::abs(l - std::log(lo)) <= kBoundTolerance)
    p.state = zero_floor ? ParameterState::kAtZero : ParameterState::kAtBound;
  else if (std::abs(l - std::log(hi)) <= kBoundTolerance)
    p.state = ParameterState::kAtBound;
  return p;
}

}  // namespace rths::ident
