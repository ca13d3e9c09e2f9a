#include "signal/zero_phase.h"

#include <algorithm>

#include "signal/butterworth.h"

namespace rths::signal {

namespace {

/// Runs the cascade over w in place (causal), from the state `start` says.
void Pass(const Sos& sos, FilterStart start, std::vector<double>* w) {
  auto st = SosAtRest(sos);
  if (start == FilterStart::kSteadyState)
    for (int i = 0; i < 400; ++i) SosStep(sos, &st, w->front());
  for (double& v : *w) v = SosStep(sos, &st, v);
}

}  // namespace

std::vector<double> ZeroPhaseLowpass(std::span<const double> x, double dt_s, double fc_hz, int order,
                                     std::size_t pad, Reflection reflection, FilterStart start) {
  const std::size_t n = x.size();
  if (n == 0) return {};
  pad = std::min(pad, n - 1);
  const auto sos = ButterworthLowpass(order, fc_hz, 1.0 / dt_s);
  const bool odd = reflection == Reflection::kOdd;
  std::vector<double> w;
  w.reserve(n + 2 * pad);
  for (std::size_t j = pad; j >= 1; --j) w.push_back(odd ? 2.0 * x[0] - x[j] : x[j]);
  for (double v : x) w.push_back(v);
  for (std::size_t j = 1; j <= pad; ++j) w.push_back(odd ? 2.0 * x[n - 1] - x[n - 1 - j] : x[n - 1 - j]);
  Pass(sos, start, &w);
  std::reverse(w.begin(), w.end());
  Pass(sos, start, &w);
  std::reverse(w.begin(), w.end());
  return {w.begin() + static_cast<std::ptrdiff_t>(pad), w.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

}  // namespace rths::signal
