#include "diagnosis/search.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rths::diagnosis::stages {

namespace {

/// Golden-section search of a function of one variable on [a, b] (a < b), iters iterations.
double Golden(const std::function<double(double)>& f, double a, double b, int iters, double* fbest) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < iters; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  if (fc < fd) {
    *fbest = fc;
    return c;
  }
  *fbest = fd;
  return d;
}

}  // namespace

double Minimise1D(const std::function<double(double)>& f, const ParamSpec& s, int golden_iters, double* fbest,
                  std::vector<double> extra) {
  auto to = [&](double x) { return s.log ? std::log(x) : x; };
  auto from = [&](double t) { return std::clamp(s.log ? std::exp(t) : t, s.lo, s.hi); };
  const double a = to(s.lo), b = to(s.hi);
  std::vector<double> ts;
  for (int j = 0; j < s.grid; ++j) ts.push_back(a + (b - a) * j / (s.grid - 1));
  for (double x : extra)
    if (x >= s.lo && x <= s.hi) ts.push_back(to(x));
  std::sort(ts.begin(), ts.end());
  const double tol = 1e-6 * (b - a);
  ts.erase(std::unique(ts.begin(), ts.end(), [&](double x, double y) { return std::abs(x - y) <= tol; }), ts.end());
  std::vector<double> fs(ts.size());
  std::size_t best = 0;
  for (std::size_t j = 0; j < ts.size(); ++j) {
    fs[j] = f(from(ts[j]));
    if (fs[j] < fs[best]) best = j;
  }
  const double l = ts[best == 0 ? 0 : best - 1], r = ts[std::min(best + 1, ts.size() - 1)];
  double fg = fs[best];
  double tg = ts[best];
  if (r > l && golden_iters > 0) {
    double fv;
    const double t = Golden([&](double t) { return f(from(t)); }, l, r, golden_iters, &fv);
    if (fv < fg) fg = fv, tg = t;
  }
  *fbest = fg;
  return from(tg);
}

std::vector<double> NelderMead2(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                                const std::vector<double>& dx, int evals, double* fbest) {
  std::vector<std::vector<double>> p = {x0, {x0[0] + dx[0], x0[1]}, {x0[0], x0[1] + dx[1]}};
  std::vector<double> fv = {f(p[0]), f(p[1]), f(p[2])};
  int n = 3;
  while (n < evals) {
    std::array<int, 3> idx = {0, 1, 2};
    std::sort(idx.begin(), idx.end(), [&](int a, int b) { return fv[a] < fv[b]; });
    const auto& b = p[idx[0]];
    const auto& m = p[idx[1]];
    const auto& w = p[idx[2]];
    const std::vector<double> c = {0.5 * (b[0] + m[0]), 0.5 * (b[1] + m[1])};
    auto at = [&](double t) { return std::vector<double>{c[0] + t * (w[0] - c[0]), c[1] + t * (w[1] - c[1])}; };
    const auto r = at(-1.0);
    const double fr = f(r);
    ++n;
    if (fr < fv[idx[0]]) {
      const auto e = at(-2.0);
      const double fe = f(e);
      ++n;
      if (fe < fr) p[idx[2]] = e, fv[idx[2]] = fe;
      else p[idx[2]] = r, fv[idx[2]] = fr;
    } else if (fr < fv[idx[1]]) {
      p[idx[2]] = r, fv[idx[2]] = fr;
    } else {
      const auto k = at(0.5);
      const double fk = f(k);
      ++n;
      if (fk < fv[idx[2]]) {
        p[idx[2]] = k, fv[idx[2]] = fk;
      } else {  // shrink towards the best
        for (int j : {idx[1], idx[2]}) {
          p[j] = {0.5 * (p[j][0] + b[0]), 0.5 * (p[j][1] + b[1])};
          fv[j] = f(p[j]);
          ++n;
        }
      }
    }
  }
  int best = 0;
  for (int j = 1; j < 3; ++j)
    if (fv[j] < fv[best]) best = j;
  *fbest = fv[best];
  return p[best];
}

ParamSpec BracketAround(const ParamSpec& range, double v, double factor, double fraction, int grid) {
  ParamSpec br = range;
  if (range.log) {
    br.lo = std::max(range.lo, v / factor);
    br.hi = std::min(range.hi, v * factor);
  } else {
    const double w = fraction * (range.hi - range.lo);
    br.lo = std::max(range.lo, v - w), br.hi = std::min(range.hi, v + w);
  }
  br.grid = grid;
  return br;
}

}  // namespace rths::diagnosis::stages
