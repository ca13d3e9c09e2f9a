#include "diagnosis/candidates.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis {

void SetEffect(models::EffectSet* set, const std::string& name, const std::map<std::string, double>& p) {
  const models::EffectInfo* info = models::FindEffect(name);
  if (info == nullptr) throw Error("effect", fmt::format("unknown effect \"{}\"", name));
  info->turn_on(*set);  // its defaults
  for (const models::EffectParam& q : info->params()) {
    const auto it = p.find(std::string(q.key));
    if (it != p.end()) {
      *q.field(*set) = it->second;
    } else if (q.required) {
      throw Error("effect " + name, fmt::format("missing parameter {}", q.key));
    }
  }
}

namespace stages {

std::vector<CandidateSpec> Candidates(double dt_s, double data_hi) {
  std::vector<CandidateSpec> out;
  for (const models::EffectInfo& e : models::kEffects) {
    if (!e.diagnosable) continue;
    CandidateSpec c{&e, std::string(e.name), e.channel, {}};
    for (const models::EffectParam& p : e.params()) {
      if (!p.fitted) continue;
      const double hi = p.search_hi_from_data ? data_hi
                        : p.search_hi_per_dt > 0.0 ? p.search_hi_per_dt / dt_s
                                                   : p.search_hi;
      c.params.push_back({std::string(p.key), p.search_lo, hi, p.log, p.grid});
    }
    out.push_back(std::move(c));
  }
  return out;
}

models::EffectSet ToSet(const std::vector<CandidateSpec>& specs, const Params& p) {
  models::EffectSet set;
  for (const auto& [name, vals] : p) {
    const auto& s = SpecOf(specs, name);
    std::map<std::string, double> m;
    for (std::size_t j = 0; j < s.params.size(); ++j) m[s.params[j].key] = vals[j];
    SetEffect(&set, name, m);
  }
  return set;
}

const CandidateSpec& SpecOf(const std::vector<CandidateSpec>& c, const std::string& name) {
  for (const auto& s : c)
    if (name == s.name) return s;
  throw Error("diagnosis", "unknown effect " + name);
}

int FreeParams(const CandidateSpec& spec, std::size_t records) {
  if (spec.name == "supply_ripple") return 1 + 2 * models::kRippleHarmonics * static_cast<int>(records);
  int p = 0;
  for (const auto& q : spec.params) p += q.grid >= 0;  // a switch (grid < 0) is no free parameter
  return p;
}

bool AtBound(const CandidateSpec& spec, const std::vector<double>& v) {
  for (std::size_t j = 0; j < spec.params.size() && j < v.size(); ++j) {
    const auto& p = spec.params[j];
    if (p.grid < 0) continue;  // a switch: 0 and 1 are its values, not bounds
    const double lo = p.log ? std::log(p.lo) : p.lo, hi = p.log ? std::log(p.hi) : p.hi;
    const double x = p.log ? std::log(std::max(v[j], 1e-300)) : v[j];
    const double tol = tuning::kAtBoundFraction * (hi - lo);
    if (x <= lo + tol || x >= hi - tol) return true;
  }
  return false;
}

std::string FormOf(const CandidateSpec& spec, const std::vector<double>& v) {
  if (spec.name == "presliding_friction" && v.size() == 2) {
    const double loss = v[0], travel = v[1];
    if (travel < tuning::kPlayCreepSlope * (travel + 2.0 * loss)) return "backlash";
  }
  return "";
}

bool SkewTooShort(const ChannelState& s, const Params& p) {
  const auto it = p.find("channel_skew");
  return it != p.end() && 1e-3 * std::abs(it->second[0]) < s.min_skew_s;
}

bool SubSampleDelayBeside(const Params& p, double dt, const Options& o) {
  const auto it = p.find("pure_delay");
  return it != p.end() && p.size() >= 2 && 1e-3 * it->second[0] < o.min_delay_samples * dt;
}

std::map<std::string, double> ParamMap(const std::vector<CandidateSpec>& specs, const std::string& name,
                                       const std::vector<double>& v) {
  std::map<std::string, double> m;
  const auto& s = SpecOf(specs, name);
  for (std::size_t j = 0; j < s.params.size(); ++j) m[s.params[j].key] = v[j];
  // The parameters the diagnosis does not fit keep their defaults (coulomb_friction's v_smooth).
  models::EffectSet defaults;
  s.info->turn_on(defaults);
  for (const models::EffectParam& q : s.info->params()) {
    if (!q.fitted) m[std::string(q.key)] = *q.field(defaults);
  }
  return m;
}

}  // namespace stages
}  // namespace rths::diagnosis
