#include "control/rodeac.h"

#include <cmath>

#include "core/error.h"

namespace rths::control {

namespace {

/// Shifts `x` into the newest-first window.
void PushNewest(Eigen::Vector4d* taps, double x) {
  (*taps)(3) = (*taps)(2);
  (*taps)(2) = (*taps)(1);
  (*taps)(1) = (*taps)(0);
  (*taps)(0) = x;
}

/// The cascade's output for input x is b x + s: returns {b, s} without touching the state
/// (each section: y = b0 x + z1).
std::array<double, 2> AffineOutput(const signal::Sos& sos, const signal::SosFilter& f) {
  double b = 1.0, s = 0.0;
  for (std::size_t i = 0; i < sos.sections.size(); ++i) {
    b *= sos.sections[i].b0;
    s = sos.sections[i].b0 * s + f.z[i][0];
  }
  return {b, s};
}

}  // namespace

RodeacDesign MakeRodeacDesign(const Eigen::Vector4d& theta0, const Eigen::Matrix4d& P0,
                              double fs_hz, double forgetting, int filter_order,
                              double filter_hz) {
  if (!(fs_hz > 2.0 * filter_hz)) throw Error("rodeac", "the sample rate must exceed twice the filter's cutoff");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw Error("rodeac", "forgetting factor must be in (0, 1]");
  if (!theta0.allFinite() || !P0.allFinite()) throw Error("rodeac", "initial parameters must be finite");
  RodeacDesign d;
  d.theta0 = theta0;
  d.P0 = P0;
  d.forgetting = forgetting;
  d.filter = signal::ButterworthLowpass(filter_order, filter_hz, fs_hz);
  return d;
}

RodeacState RodeacAtRest(const RodeacDesign& d) {
  RodeacState s;
  s.theta = d.theta0;
  s.P = d.P0;
  s.measured_filter = signal::SosAtRest(d.filter);
  s.command_filter = signal::SosAtRest(d.filter);
  return s;
}

double RodeacStep(const RodeacDesign& d, RodeacState* s, double target_mm, double measured_mm) {
  PushNewest(&s->target_taps, target_mm);
  PushNewest(&s->measured_taps, signal::SosStep(d.filter, &s->measured_filter, measured_mm));
  const Eigen::Vector4d& phi = s->measured_taps;
  const Eigen::Vector4d& T = s->target_taps;
  const Eigen::Vector4d Pphi = s->P * phi;
  const Eigen::Vector4d gain = Pphi / (d.forgetting + phi.dot(Pphi));
  const auto [b, filter_rest] = AffineOutput(d.filter, s->command_filter);
  const double predicted = phi.dot(s->theta);
  const double Tk = T.dot(gain);
  const double u = (T.dot(s->theta) + Tk * (filter_rest - predicted)) / (1.0 - b * Tk);
  const double u_filtered = signal::SosStep(d.filter, &s->command_filter, u);
  s->theta += gain * (u_filtered - predicted);
  s->P = (s->P - gain * phi.transpose() * s->P) / d.forgetting;
  return u;
}

}  // namespace rths::control
