#include "control/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {

using cd = std::complex<double>;

/// Polynomial product, coefficients in ascending powers.
std::vector<double> Multiply(const std::vector<double>& p, const std::vector<double>& q) {
  std::vector<double> r(p.size() + q.size() - 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < q.size(); ++j) r[i + j] += p[i] * q[j];
  return r;
}

/// (x - r_1)(x - r_2)... as real coefficients in descending powers (conjugate pairs make the
/// imaginary parts cancel; they are dropped).
std::vector<double> FromRoots(const Eigen::VectorXcd& roots) {
  std::vector<cd> c{1.0};
  for (Eigen::Index i = 0; i < roots.size(); ++i) {
    std::vector<cd> next(c.size() + 1, 0.0);
    for (std::size_t j = 0; j < c.size(); ++j) {
      next[j] += c[j];
      next[j + 1] -= c[j] * roots(i);
    }
    c = std::move(next);
  }
  std::vector<double> out(c.size());
  for (std::size_t j = 0; j < c.size(); ++j) out[j] = c[j].real();
  return out;
}

/// det(zI - M) in descending powers of z.
std::vector<double> CharPoly(const Eigen::MatrixXd& M) {
  if (M.rows() == 0) return {1.0};
  return FromRoots(Eigen::EigenSolver<Eigen::MatrixXd>(M, false).eigenvalues());
}

std::vector<double> DropLeadingZeros(const std::vector<double>& p) {
  auto it = std::find_if(p.begin(), p.end(), [](double v) { return v != 0.0; });
  return std::vector<double>(it, p.end());
}

std::string List(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{:g}", i ? ", " : "", v[i]);
  return s + "]";
}

/// Pads b on the left to a's length and divides both by a[0].
DiscreteTf Normalised(std::vector<double> b, std::vector<double> a, double dt_s) {
  b.insert(b.begin(), a.size() - b.size(), 0.0);
  const double a0 = a[0];
  for (double& v : b) v /= a0;
  for (double& v : a) v /= a0;
  a[0] = 1.0;
  return {std::move(b), std::move(a), dt_s};
}

}  // namespace

std::complex<double> DiscreteTf::Response(double f_hz) const {
  const cd zi = std::polar(1.0, -2.0 * std::numbers::pi * f_hz * dt_s);  // z^-1
  cd num = 0.0, den = 0.0, p = 1.0;
  for (std::size_t i = 0; i < a.size(); ++i, p *= zi) {
    num += b[i] * p;
    den += a[i] * p;
  }
  return num / den;
}

std::vector<std::complex<double>> PolynomialRoots(const std::vector<double>& descending) {
  const std::vector<double> p = DropLeadingZeros(descending);
  if (p.size() <= 1) return {};
  const Eigen::Index n = static_cast<Eigen::Index>(p.size()) - 1;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) companion(0, j) = -p[j + 1] / p[0];
  for (Eigen::Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  const Eigen::VectorXcd ev = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  std::vector<cd> roots(ev.data(), ev.data() + ev.size());
  std::sort(roots.begin(), roots.end(), [](cd x, cd y) {
    return std::abs(x) != std::abs(y) ? std::abs(x) > std::abs(y) : x.imag() > y.imag();
  });
  return roots;
}

std::vector<std::complex<double>> DiscreteTf::Poles() const { return PolynomialRoots(a); }
std::vector<std::complex<double>> DiscreteTf::Zeros() const { return PolynomialRoots(b); }

DiscreteSs DiscreteTf::ToStateSpace() const {
  // The delay line of FilterStep as the state: y = b0 x + w0, w_i+ = b_{i+1} x - a_{i+1} y + w_{i+1}.
  const int n = order();
  DiscreteSs s{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd(n), Eigen::RowVectorXd::Zero(n), b[0], dt_s};
  for (int i = 0; i < n; ++i) {
    s.A(i, 0) = -a[i + 1];
    if (i + 1 < n) s.A(i, i + 1) = 1.0;
    s.B(i) = b[i + 1] - a[i + 1] * b[0];
  }
  if (n > 0) s.C(0) = 1.0;
  return s;
}

TfChecked CheckTf(const TfCoefficients& tf, const std::string& key) {
  for (auto [name, v] : {std::pair{"num", &tf.num}, {"den", &tf.den}}) {
    if (v->empty()) {
      throw Error(fmt::format("{}.{}", key, name), "missing or empty: give both num and den (coefficients in "
                                                   "descending powers), or leave the whole table out for 1");
    }
    for (std::size_t i = 0; i < v->size(); ++i) {
      if (!std::isfinite((*v)[i])) {
        throw Error(fmt::format("{}.{}", key, name), fmt::format("{}: coefficient {} is not finite", List(*v), i + 1));
      }
    }
  }
  TfChecked c{DropLeadingZeros(tf.num), DropLeadingZeros(tf.den)};
  if (c.den.empty()) throw Error(key + ".den", fmt::format("{}: all zero (the denominator must not vanish)", List(tf.den)));
  if (c.num.empty()) c.num = {0.0};
  const std::size_t poles = c.den.size() - 1;
  if (poles > static_cast<std::size_t>(kMaxTfOrder)) {
    throw Error(key + ".den", fmt::format("{} poles: at most {} are allowed", poles, kMaxTfOrder));
  }
  if (c.num.size() > c.den.size()) {
    throw Error(key + ".num", fmt::format("{} over {}: improper (numerator degree {} above denominator degree {}); a "
                                          "controller cannot use future samples: add poles (e.g. a low-pass) "
                                          "until deg num <= deg den",
                                          List(tf.num), List(tf.den), c.num.size() - 1, poles));
  }
  return c;
}

DiscreteTf TustinTf(const TfChecked& s, double dt_s) {
  const int n = static_cast<int>(s.den.size()) - 1;
  const double c = 2.0 / dt_s;
  // x^i in descending input -> ascending: coefficient of s^i is p[size - 1 - i].
  auto map = [&](const std::vector<double>& p) {
    std::vector<double> out(n + 1, 0.0);  // ascending powers of z
    const int m = static_cast<int>(p.size()) - 1;
    for (int i = 0; i <= m; ++i) {
      const double coef = p[m - i] * std::pow(c, i);
      if (coef == 0.0) continue;
      std::vector<double> term{coef};
      for (int j = 0; j < i; ++j) term = Multiply(term, {-1.0, 1.0});      // (z - 1)
      for (int j = 0; j < n - i; ++j) term = Multiply(term, {1.0, 1.0});   // (z + 1)
      for (std::size_t j = 0; j < term.size(); ++j) out[j] += term[j];
    }
    std::reverse(out.begin(), out.end());  // descending powers of z
    return out;
  };
  return Normalised(map(s.num), map(s.den), dt_s);
}

DiscreteTf ZohTf(const TfChecked& s, double dt_s) {
  const int n = static_cast<int>(s.den.size()) - 1;
  if (n == 0) return {{s.num[0] / s.den[0]}, {1.0}, dt_s};
  // Monic denominator a(s) = s^n + a_1 s^{n-1} + ... + a_n; num = D a(s) + r(s), deg r < n.
  std::vector<double> a(s.den), b(n + 1, 0.0);
  for (double& v : a) v /= s.den[0];
  for (std::size_t i = 0; i < s.num.size(); ++i) b[n + 1 - s.num.size() + i] = s.num[i] / s.den[0];
  const double D = b[0];
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), B = Eigen::MatrixXd::Zero(n, 1);
  Eigen::RowVectorXd C(n);
  // Controllable canonical form: x_1' = -a_1 x_1 - ... - a_n x_n + u, x_{i+1}' = x_i.
  for (int j = 0; j < n; ++j) {
    A(0, j) = -a[j + 1];
    C(j) = b[j + 1] - D * a[j + 1];
  }
  for (int i = 1; i < n; ++i) A(i, i - 1) = 1.0;
  B(0, 0) = 1.0;
  Eigen::MatrixXd Phi, Gamma;
  ZohDiscretise(A, B, dt_s, &Phi, &Gamma);
  const std::vector<double> den = CharPoly(Phi);
  const std::vector<double> closed = CharPoly(Phi - Gamma * C);
  std::vector<double> num(n + 1);
  for (int i = 0; i <= n; ++i) num[i] = closed[i] - den[i] + D * den[i];
  return Normalised(num, den, dt_s);
}

DiscreteTf ZDomainTf(const TfChecked& z, double dt_s) { return Normalised(z.num, z.den, dt_s); }

TfStability StabilityOf(const DiscreteTf& h) {
  TfStability st;
  for (const cd p : h.Poles()) {
    st.spectral_radius = std::max(st.spectral_radius, std::abs(p));
    if (std::abs(p - 1.0) <= kIntegratorTolerance) {
      ++st.integrators;
    } else if (std::abs(p) >= 1.0) {
      ++st.unstable;
    }
  }
  return st;
}

}  // namespace rths::control
