#include <cmath>

#include "diagnosis/diagnosis.h"

namespace rths::diagnosis {

namespace {

using nlohmann::json;

/// A number, or null if not finite (JSON has no inf or NaN).
json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// "where": the residual's bands, conditions and time windows.
json WhereJson(const Result& r) {
  json where;
  where["bands"] = json::array();
  for (const auto& b : r.bands) {
    json o = {{"channel", b.channel}, {"lo_hz", b.lo_hz}, {"hi_hz", b.hi_hz}, {"share_pct", Num(b.share_pct)},
              {"signal_share_pct", Num(b.signal_share_pct)}, {"rel_residual_pct", Num(b.rel_residual_pct)}};
    if (b.coherence >= 0) {
      o["coherence"] = Num(b.coherence);
      o["frf_gain_ratio"] = Num(b.gain_ratio);
      o["frf_phase_diff_deg"] = Num(b.phase_diff_deg);
    }
    where["bands"].push_back(o);
  }
  where["conditions"] = json::array();
  for (const auto& c : r.conditions)
    where["conditions"].push_back({{"channel", c.channel}, {"name", c.name}, {"share_pct", Num(c.share_pct)},
                                   {"samples_pct", Num(c.samples_pct)}, {"informative", c.informative}});
  where["time"] = json::array();
  for (const auto& t : r.time)
    where["time"].push_back({{"channel", t.channel}, {"record", t.record}, {"t0_s", t.t0_s}, {"t1_s", t.t1_s},
                             {"share_pct", Num(t.share_pct)}});
  return where;
}

/// One entry of "effects".
json EffectJson(const EffectResult& e) {
  json o;
  o["name"] = e.name;
  o["channel"] = e.channel;
  json p = json::object();
  for (const auto& [k, v] : e.params) p[k] = Num(v);
  o["params"] = p;
  o["nrmse_" + e.channel + "_pct_after"] = Num(e.test_nrmse_after);
  o["shrink_pct"] = Num(e.shrink_pct);
  o["selected"] = e.selected;
  o["at_bound"] = e.at_bound;
  o["unconfirmed"] = e.unconfirmed;
  o["form_of"] = e.form_of;
  json alts = json::array();
  for (const auto& a : e.alternatives) {
    json pa = json::object();
    for (const auto& [k, v] : a.params) pa[k] = Num(v);
    alts.push_back({{"name", a.name}, {"delta_bic", Num(a.delta_bic)}, {"params", pa}});
  }
  o["alternatives"] = alts;
  json se = json::object();
  for (const auto& [k, v] : e.params_se) se[k] = Num(v);
  o["params_se"] = se;
  json segs = json::array();
  for (const auto& d : e.segments) {
    json vals = json::array(), ses = json::array();
    for (std::size_t j = 0; j < d.values.size(); ++j) vals.push_back(Num(d.values[j])), ses.push_back(Num(d.se[j]));
    segs.push_back({{"key", d.key}, {"values", vals}, {"se", ses}, {"chi2", Num(d.chi2)}});
  }
  o["segments"] = segs;
  o["drift"] = e.drift;
  o["train_nrmse_" + e.channel + "_pct_after"] = Num(e.train_nrmse_after);
  if (e.name != "sensor_noise") {
    o["excess_reduction_pct"] = Num(100.0 * e.excess_reduction);
    o["delta_bic"] = Num(e.delta_bic);
  }
  return o;
}

/// "channels": per channel, its status and numbers.
json ChannelsJson(const Result& r) {
  json ch = json::object();
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      ch[c.channel] = {{"diagnosed", false}, {"status", c.status}};
      continue;
    }
    ch[c.channel] = {{"diagnosed", true},
                     {"status", c.status},
                     {"nrmse_test_pct", Num(c.gap_test_pct)},
                     {"nrmse_train_pct", Num(c.gap_train_pct)},
                     {"nrmse_test_pct_after", Num(c.after_test_pct)},
                     {"noise_floor_rms", Num(c.noise_rms)},
                     {"floor_ratio", Num(c.floor_ratio)},
                     {"floor_ratio_test", Num(c.floor_ratio_test)},
                     {"whiteness_q20", Num(c.whiteness)}};
  }
  return ch;
}

}  // namespace

nlohmann::json ToJson(const Result& r) {
  json j;
  const auto* y = r.Channel("y");
  const auto* f = r.Channel("f");
  j["gap"] = {{"nrmse_y_pct", y && y->diagnosed ? Num(y->gap_test_pct) : json(nullptr)},
              {"nrmse_f_pct", f && f->diagnosed ? Num(f->gap_test_pct) : json(nullptr)}};
  j["where"] = WhereJson(r);
  j["effects"] = json::array();
  for (const auto& e : r.effects) j["effects"].push_back(EffectJson(e));
  j["verdict"] = r.verdict;
  j["channels"] = ChannelsJson(r);
  j["noise_floor"] = {{"y_mm_rms", y && y->diagnosed ? Num(y->noise_rms) : json(nullptr)},
                      {"f_kN_rms", f && f->diagnosed ? Num(f->noise_rms) : json(nullptr)}};
  j["records"] = {{"train", r.train}, {"test", r.test}};
  j["model"] = r.model_source;
  j["dt_s"] = r.dt_s;
  j["samples"] = r.samples;
  j["runtime_s"] = r.runtime_s;
  j["warnings"] = r.warnings;
  j["sensor_faults"] = json::array();
  for (const auto& sf : r.sensor_faults)
    j["sensor_faults"].push_back({{"record", sf.record}, {"channel", sf.channel}, {"t0_s", sf.t0_s},
                                  {"t1_s", sf.t1_s}, {"value", sf.value}});
  j["options"] = ToJson(r.options);
  return j;
}

}  // namespace rths::diagnosis
