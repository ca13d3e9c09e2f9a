#include <cmath>

#include <fmt/format.h>

#include "diagnosis/diagnosis.h"

namespace rths::diagnosis {

const ChannelSummary* Result::Channel(const std::string& c) const {
  for (const auto& ch : channels)
    if (ch.channel == c) return &ch;
  return nullptr;
}

std::string VerdictText(const Result& r) {
  std::string s;
  for (std::size_t i = 0; i < r.verdict.size(); ++i) {
    s += (i ? ", " : "") + r.verdict[i];
    for (const auto& e : r.effects)
      if (e.name == r.verdict[i]) {
        if (!e.drift.empty()) s += ", " + e.drift;
        if (!e.unconfirmed.empty()) s += " (unconfirmed: " + e.unconfirmed + ")";
        for (const auto& a : e.alternatives) s += fmt::format(" (close call: or {}, BIC +{:.1f})", a.name, a.delta_bic);
      }
  }
  return s;
}

namespace {

/// The verdict line of the summaries.
std::string VerdictLine(const Result& r) { return "verdict: " + VerdictText(r) + "\n"; }

/// The brief report: the verdict and, per channel, its status and test NRMSE before -> after.
std::string BriefSummary(const Result& r) {
  std::string s = VerdictLine(r);
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      s += fmt::format("channel {}: not diagnosed\n", c.channel);
      continue;
    }
    s += fmt::format("channel {}: {}, test NRMSE {:.3f} % -> {:.3f} % (shrink {:.1f} %)\n", c.channel, c.status,
                     c.gap_test_pct, c.after_test_pct, ShrinkPct(c.gap_test_pct, c.after_test_pct));
  }
  if (!r.warnings.empty()) s += fmt::format("warnings: {} (in the full report)\n", r.warnings.size());
  return s;
}

}  // namespace

std::string Summary(const Result& r, SummaryDetail detail) {
  if (detail == SummaryDetail::kBrief) return BriefSummary(r);
  std::string s;
  s += fmt::format("model: {}\n", r.model_source);
  s += fmt::format("records: {} training, {} test, dt {} s, {} samples\n", r.train.size(), r.test.size(), r.dt_s, r.samples);
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      s += fmt::format("channel {}: not diagnosed\n", c.channel);
      continue;
    }
    s += fmt::format("channel {}: gap {:.3f} % (test; train {:.3f} %), noise floor {:.4g} {}, residual/floor {:.2f} "
                     "-> {}; after: {:.3f} %\n",
                     c.channel, c.gap_test_pct, c.gap_train_pct, c.noise_rms, c.channel == "y" ? "mm" : "kN",
                     c.floor_ratio, c.status, c.after_test_pct);
  }
  for (const auto& ch : {std::string("y"), std::string("f")}) {
    const Band* top = nullptr;
    for (const auto& b : r.bands)
      if (b.channel == ch && (!top || b.share_pct > top->share_pct)) top = &b;
    if (top) s += fmt::format("where ({}): {:.0f}-{:.0f} Hz holds {:.1f} % of the residual", ch, top->lo_hz, top->hi_hz, top->share_pct);
    const Condition* tc = nullptr;
    std::string uninformative;
    for (const auto& c : r.conditions) {
      if (c.channel != ch) continue;
      if (!c.informative) {
        uninformative += fmt::format("{}{} ({:.0f} % of the samples)", uninformative.empty() ? "" : ", ", c.name, c.samples_pct);
        continue;
      }
      if (!tc || c.share_pct / c.samples_pct > tc->share_pct / tc->samples_pct) tc = &c;
    }
    if (tc) s += fmt::format("; {} holds {:.1f} % of it in {:.1f} % of the samples", tc->name, tc->share_pct, tc->samples_pct);
    if (top && !uninformative.empty()) s += fmt::format("; uninformative: {}", uninformative);
    if (top) s += "\n";
  }
  s += "effects (test NRMSE after, shrink):\n";
  std::vector<std::string> pinned, other_form;
  for (const auto& e : r.effects) {
    if (e.at_bound && !e.selected) {
      pinned.push_back(e.name);
      continue;
    }
    if (!e.form_of.empty() && !e.selected) {
      other_form.push_back(fmt::format("{} (fitted as {})", e.name, e.form_of));
      continue;
    }
    std::string ps;
    for (const auto& [k, v] : e.params) ps += fmt::format(" {}={:.4g}", k, v);
    // "excess": the training residual's sum of squares above the noise floor (rule (b)).
    const double red_pct = 100.0 * e.excess_reduction;
    s += fmt::format("  {} {:<22} [{}]{}: {:.3f} %, shrink {:.1f} % (training: {} {:.0f} % of the residual above noise)\n",
                     e.selected ? "*" : " ", e.name, e.channel, ps, e.test_nrmse_after, e.shrink_pct,
                     red_pct >= 0.0 ? "removes" : "adds", std::abs(red_pct));
    // A selected effect's parameters with their uncertainty, and per segment of the training records.
    for (const auto& seg : e.segments) {
      const auto se = e.params_se.find(seg.key);
      std::string parts;
      for (std::size_t j = 0; j < seg.values.size(); ++j)
        parts += fmt::format("{}{:.4g} +- {:.2g}", j ? ", " : "", seg.values[j], seg.se[j]);
      s += fmt::format("      {} = {:.4g} +- {:.2g}; per {} of the training records: {} (chi2 {:.3g})\n", seg.key,
                       e.params.count(seg.key) ? e.params.at(seg.key) : 0.0, se == e.params_se.end() ? 0.0 : se->second,
                       seg.values.size() == 4 ? "quarter" : "segment", parts, seg.chi2);
    }
  }
  if (!pinned.empty()) {
    s += fmt::format("  (not shown: {} fitted to an end of the search range, so not a description of the residual; "
                     "diagnosis.json has them)\n",
                     fmt::join(pinned, ", "));
  }
  if (!other_form.empty()) {
    s += fmt::format("  (not shown: {}: another effect's form, not an explanation of its own)\n", fmt::join(other_form, ", "));
  }
  s += VerdictLine(r);
  for (const auto& w : r.warnings) s += "warning: " + w + "\n";
  s += fmt::format("runtime: {:.2f} s\n", r.runtime_s);
  return s;
}

}  // namespace rths::diagnosis
