#include "io/log_compare.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/core.h>

#include "core/error.h"

namespace rths::io {

namespace {

/// The numeric fields of a message, by name, appended to `out` (names and values in order).
using Fields = std::vector<std::pair<std::string, double>>;

void FieldsOf(const rths::desired_t& m, Fields* out) {
  *out = {{"r_mm", m.r_mm},
          {"rd_mm_s", m.rd_mm_s},
          {"rdd_mm_s2", m.rdd_mm_s2},
          {"rddd_mm_s3", m.rddd_mm_s3},
          {"acc_prev_mm_s2", m.acc_prev_mm_s2},
          {"vel_prev_mm_s", m.vel_prev_mm_s},
          {"ground_acc_mm_s2", m.ground_acc_mm_s2}};
  for (std::size_t i = 0; i < m.x_mm.size(); ++i) out->emplace_back(fmt::format("x_mm[{}]", i), m.x_mm[i]);
  for (std::size_t i = 0; i < m.abs_acc_mm_s2.size(); ++i) {
    out->emplace_back(fmt::format("abs_acc_mm_s2[{}]", i), m.abs_acc_mm_s2[i]);
  }
}
void FieldsOf(const rths::command_t& m, Fields* out) {
  *out = {{"u_mm", m.u_mm}, {"u_ff_mm", m.u_ff_mm}, {"u_fb_mm", m.u_fb_mm}};
}
void FieldsOf(const rths::measured_t& m, Fields* out) {
  *out = {{"y_mm", m.y_mm}, {"f_kN", m.f_kN}, {"current_A", m.current_A}};
}
void FieldsOf(const rths::current_t& m, Fields* out) {
  *out = {{"i_cmd_A", m.i_cmd_A}, {"f_desired_kN", m.f_desired_kN}};
}

template <class Msg>
ChannelDiff Compare(const std::vector<Msg>& a, const std::vector<Msg>& b, const RunLog& la, const RunLog& lb,
                    const std::string& channel, std::int64_t steps) {
  ChannelDiff d;
  d.channel = channel;
  const auto& pa = la.payload.count(channel) ? la.payload.at(channel) : std::vector<std::vector<std::uint8_t>>{};
  const auto& pb = lb.payload.count(channel) ? lb.payload.at(channel) : std::vector<std::vector<std::uint8_t>>{};
  const std::int64_t n = std::min({steps, static_cast<std::int64_t>(a.size()), static_cast<std::int64_t>(b.size())});
  Fields fa, fb;
  std::vector<double> sum_sq, sum_sq_a;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto sk = static_cast<std::size_t>(k);
    if (a[sk].k != k || b[sk].k != k) break;  // a missing step ends the comparison
    ++d.steps;
    const bool same_bytes = sk < pa.size() && sk < pb.size() && pa[sk] == pb[sk];
    FieldsOf(a[sk], &fa);
    FieldsOf(b[sk], &fb);
    if (d.fields.empty()) {
      for (const auto& [name, v] : fa) d.fields.push_back({name});
      sum_sq.assign(fa.size(), 0.0);
      sum_sq_a.assign(fa.size(), 0.0);
    }
    if (!same_bytes) {
      ++d.differing_steps;
      if (d.first_difference < 0) d.first_difference = k;
    }
    const std::size_t m = std::min({fa.size(), fb.size(), d.fields.size()});
    for (std::size_t i = 0; i < m; ++i) {
      const double diff = fb[i].second - fa[i].second;
      sum_sq[i] += diff * diff;
      sum_sq_a[i] += fa[i].second * fa[i].second;
      if (std::abs(diff) > d.fields[i].peak) {
        d.fields[i].peak = std::abs(diff);
        d.fields[i].peak_step = k;
      }
    }
    if (fa.size() != fb.size() && d.first_difference < 0) d.first_difference = k;
  }
  for (std::size_t i = 0; i < d.fields.size(); ++i) {
    if (d.steps == 0) break;
    d.fields[i].rms = std::sqrt(sum_sq[i] / static_cast<double>(d.steps));
    d.fields[i].rms_a = std::sqrt(sum_sq_a[i] / static_cast<double>(d.steps));
  }
  return d;
}

}  // namespace

ChannelDiff CompareChannel(const RunLog& a, const RunLog& b, const std::string& channel, std::int64_t steps) {
  if (channel == "RTHS_DESIRED") return Compare(a.desired, b.desired, a, b, channel, steps);
  if (channel == "RTHS_COMMAND") return Compare(a.command, b.command, a, b, channel, steps);
  if (channel == "RTHS_MEASURED") return Compare(a.measured, b.measured, a, b, channel, steps);
  if (channel == "RTHS_CURRENT") return Compare(a.current, b.current, a, b, channel, steps);
  throw Error("CompareChannel", fmt::format("unknown channel '{}'", channel));
}

std::string Describe(const ChannelDiff& d) {
  if (d.identical()) return fmt::format("{}: identical over {} steps", d.channel, d.steps);
  std::string s = fmt::format("{}: differs from step {} ({} of {} steps)", d.channel, d.first_difference,
                              d.differing_steps, d.steps);
  for (const auto& f : d.fields) {
    if (f.peak == 0.0) continue;
    s += fmt::format("\n    {:<18} RMS {:.4g}, peak {:.4g} at step {}", f.name, f.rms, f.peak, f.peak_step);
    if (f.rms_a > 0) s += fmt::format(" (RMS {:.3g} % of the recorded signal's)", 100.0 * f.rms / f.rms_a);
  }
  return s;
}

std::vector<PayloadDifference> CompareLogs(const RunLog& a, const RunLog& b) {
  std::vector<PayloadDifference> out;
  for (const auto& [ch, pa] : a.payload) {
    const auto it = b.payload.find(ch);
    if (it == b.payload.end()) {
      out.push_back({PayloadDifference::kOnlyInA, ch, pa.size(), 0, -1, ""});
      continue;
    }
    const auto& pb = it->second;
    if (pa.size() != pb.size()) {
      out.push_back({PayloadDifference::kStepCount, ch, pa.size(), pb.size(), -1, ""});
      continue;
    }
    for (std::size_t k = 0; k < pa.size(); ++k) {
      if (pa[k] == pb[k]) continue;
      PayloadDifference d{PayloadDifference::kPayload, ch, pa.size(), pb.size(), static_cast<std::int64_t>(k), ""};
      if (ch == "RTHS_DESIRED" || ch == "RTHS_COMMAND" || ch == "RTHS_MEASURED" || ch == "RTHS_CURRENT") {
        // How much, field by field (B - A): Describe's lines after its first.
        const std::string text = Describe(CompareChannel(a, b, ch, static_cast<std::int64_t>(pa.size())));
        if (const auto nl = text.find('\n'); nl != std::string::npos) d.fields = text.substr(nl + 1);
      }
      out.push_back(std::move(d));
      break;
    }
  }
  for (const auto& [ch, pb] : b.payload) {
    if (!a.payload.count(ch)) out.push_back({PayloadDifference::kOnlyInB, ch, 0, pb.size(), -1, ""});
  }
  return out;
}

std::string Describe(const PayloadDifference& d, const std::string& name_a, const std::string& name_b) {
  switch (d.kind) {
    case PayloadDifference::kOnlyInA: return fmt::format("{}: only in {} ({} steps)\n", d.channel, name_a, d.steps_a);
    case PayloadDifference::kOnlyInB: return fmt::format("{}: only in {} ({} steps)\n", d.channel, name_b, d.steps_b);
    case PayloadDifference::kStepCount: return fmt::format("{}: {} vs {} steps\n", d.channel, d.steps_a, d.steps_b);
    case PayloadDifference::kPayload: break;
  }
  std::string s = fmt::format("{}: first difference at k = {}\n", d.channel, d.first_k);
  if (!d.fields.empty()) s += d.fields + "\n";
  return s;
}

}  // namespace rths::io
