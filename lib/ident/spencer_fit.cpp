#include "ident/spencer_fit.h"

#include <algorithm>
#include <functional>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"
#include "ident/damper_fit.h"
#include "ident/bouc_wen_rk4.h"
#include "ident/lm.h"
#include "ident/plausible_range.h"

namespace rths::ident {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// theta layout (file comment of spencer_fit.h): 5 laws x (a, b, c), then k0, then eta.
constexpr int kLaws = 5;  // alpha, c0, c1, beta, gamma
constexpr int kK0 = 3 * kLaws;
constexpr int kEta = kK0 + 1;

// Bounds of each law's ends a, b (natural units) and of the rates [1/A or 1/V].
constexpr double kEndLo[kLaws] = {1e-7, 1e-7, 1e-7, 1e-9, 1e-9};
constexpr double kEndHi[kLaws] = {1e3, 1e4, 1e4, 1e4, 1e4};
constexpr double kFitRateLo = 1e-4, kFitRateHi = 1e3;
constexpr double kK0Lo = 1e-8, kK0Hi = 1e2;
constexpr double kEtaLo = 1.0, kEtaHi = 1e5;
// The starts' share of every record (and its least length [s]).
constexpr double kStartShare = 0.25, kStartMinS = 3.0;

int Dim(ControlFilter f) { return f == ControlFilter::kFirstOrder ? kEta + 1 : kK0 + 1; }

double LoBound(int i) {
  if (i < kK0) return i % 3 == 2 ? kFitRateLo : kEndLo[i / 3];
  return i == kK0 ? kK0Lo : kEtaLo;
}
double HiBound(int i) {
  if (i < kK0) return i % 3 == 2 ? kFitRateHi : kEndHi[i / 3];
  return i == kK0 ? kK0Hi : kEtaHi;
}
// The lower bound of theta_i stands for 0 (fit_status.h): the laws' ends and k0, not the rates or eta.
bool ZeroFloor(int i) { return i < kK0 ? i % 3 != 2 : i == kK0; }

constexpr const char* kParamNames[kEta + 1] = {"alpha_a", "alpha_b", "alpha_c", "c0_a",    "c0_b",    "c0_c",
                                               "c1_a",    "c1_b",    "c1_c",    "beta_a",  "beta_b",  "beta_c",
                                               "gamma_a", "gamma_b", "gamma_c", "k0",      "eta_1_s"};

// The box the fit searches theta in: ln of the bounds, or a point for a held parameter.
using Box = LmBox<Eigen::VectorXd>;
Box MakeBox(int dim) {
  return Box(dim, [](int i) { return std::log(LoBound(i)); }, [](int i) { return std::log(HiBound(i)); });
}

models::MrDamperParams ParamsOf(const Eigen::VectorXd& th, double A) {
  models::MrDamperParams p;
  double* ends[kLaws][3] = {{&p.alpha_a, &p.alpha_b, &p.alpha_c},
                            {&p.c0_a, &p.c0_b, &p.c0_c},
                            {&p.c1_a, &p.c1_b, &p.c1_c},
                            {&p.beta_a, &p.beta_b, &p.beta_c},
                            {&p.gamma_a, &p.gamma_b, &p.gamma_c}};
  for (int l = 0; l < kLaws; ++l)
    for (int j = 0; j < 3; ++j) *ends[l][j] = std::exp(th[3 * l + j]);
  p.A = A;
  p.n = 2.0;
  p.k0 = std::exp(th[kK0]);
  p.k1 = 0.0;
  p.x0 = 0.0;
  return p;
}

models::CurrentDriverParams DriverOf(const Eigen::VectorXd& th, ControlFilter f) {
  models::CurrentDriverParams d;
  if (f == ControlFilter::kFirstOrder) {
    d.kind = models::CurrentFilter::kFirstOrder;
    d.eta_1_s = std::exp(th[kEta]);
  }
  return d;
}

// The filtered input u_k at the sample times (file comment), from u_0 = v_0.
void FilteredInput(std::span<const double> v, double dt, ControlFilter f, const models::CurrentDriverParams& d,
                   std::vector<double>* u) {
  const std::size_t n = v.size();
  u->resize(n);
  if (n == 0) return;
  if (f == ControlFilter::kNone) {
    std::copy(v.begin(), v.end(), u->begin());
    return;
  }
  const auto driver = models::CurrentDriver::Make(d, dt);
  auto st = models::SteadyState(v[0]);
  for (std::size_t k = 0; k < n; ++k) {
    (*u)[k] = models::EffectiveCurrentA(driver, st);
    models::Step(driver, &st, v[k]);
  }
}

// One record prepared for the fit.
struct Prepared {
  const io::RigRecord* rec = nullptr;
  std::vector<double> v;      // the command the model is driven with (CommandForModel)
  std::vector<double> xdot;   // smoothed velocity [mm/s]
  double cutoff_hz = 0.0;
  double weight = 0.0;        // 1 / sum f^2
  std::size_t n = 0;          // samples used: all, or the first part for the starts
};

// Substeps of sample step j -> j+1 from the local rate bound (damper_fit.h, lambda with the
// coefficients and |x'| of both ends); kMaxSpencerSubsteps + 1 if too stiff.
int LocalSubsteps(const models::MrDamperCoefficients& c0, const models::MrDamperCoefficients& c1, double A, double k0,
                  double v0, double v1, double dt) {
  const double bg = std::max(c0.beta + c0.gamma, c1.beta + c1.gamma);
  const double slow = std::max((A * c0.alpha + k0) / (c0.c0 + c0.c1), (A * c1.alpha + k0) / (c1.c0 + c1.c1));
  const double lambda = BoucWenRateBound(A, bg, std::max(std::abs(v0), std::abs(v1)), slow);
  if (!(lambda < 1e300)) return kMaxSpencerSubsteps + 1;
  const double m = SubstepsFor(dt, lambda);
  return m > kMaxSpencerSubsteps ? kMaxSpencerSubsteps + 1 : std::max(1, static_cast<int>(m));
}

// Nonlinear part of the force, F_nl = alpha z + c0 (x' - y') + k0 (x - y), at the first d.n
// samples of a record, into out; false if a step is too stiff for kMaxSpencerSubsteps or the
// state stops being finite. `m` holds the substeps per sample step: chosen here (LocalSubsteps)
// if `choose`, else given (the Jacobian's columns keep the base point's, so that the finite
// differences see a smooth function).
struct Workspace {
  std::vector<double> u;
  std::vector<models::MrDamperCoefficients> c;
};

bool SimulateNonlinear(const models::MrDamperParams& p, const models::CurrentDriverParams& drv, ControlFilter filter,
                       const Prepared& d, bool choose, std::vector<std::uint8_t>* msteps, Workspace* w, double* out) {
  const auto& rec = *d.rec;
  const std::size_t n = d.n;
  const double dt = rec.dt_s;
  FilteredInput(std::span<const double>(d.v).subspan(0, n), dt, filter, drv, &w->u);
  w->c.resize(n);
  for (std::size_t k = 0; k < n; ++k) w->c[k] = models::CoefficientsAt(p, w->u[k]);
  if (choose) msteps->assign(n, 1);
  const double A = p.A, k0 = p.k0;
  const auto& x = rec.y_mm;
  const auto& xd = d.xdot;
  double y = x[0], z = 0.0;
  // Rates at fraction s in [0, 1] of sample step j -> j+1 (x, x', coefficients linear in s).
  auto rates = [&](std::size_t j, double s, double ys, double zs, double* dy, double* dz) {
    const auto& c0 = w->c[j];
    const auto& c1 = w->c[j + 1];
    const double xs = x[j] + s * (x[j + 1] - x[j]), vs = xd[j] + s * (xd[j + 1] - xd[j]);
    const double alpha = c0.alpha + s * (c1.alpha - c0.alpha), cc0 = c0.c0 + s * (c1.c0 - c0.c0),
                 cc1 = c0.c1 + s * (c1.c1 - c0.c1), beta = c0.beta + s * (c1.beta - c0.beta),
                 gamma = c0.gamma + s * (c1.gamma - c0.gamma);
    *dy = (alpha * zs + k0 * (xs - ys) + cc0 * vs) / (cc0 + cc1);
    const double rel = vs - *dy;
    *dz = -gamma * std::abs(rel) * zs * std::abs(zs) - beta * rel * zs * zs + A * rel;
  };
  for (std::size_t j = 0; j < n; ++j) {
    const auto& c = w->c[j];
    const double ydot = (c.alpha * z + k0 * (x[j] - y) + c.c0 * xd[j]) / (c.c0 + c.c1);
    out[j] = c.alpha * z + c.c0 * (xd[j] - ydot) + k0 * (x[j] - y);
    if (!std::isfinite(out[j])) return false;
    if (j + 1 == n) break;
    if (choose) {
      const int mj = LocalSubsteps(w->c[j], w->c[j + 1], A, k0, xd[j], xd[j + 1], dt);
      if (mj > kMaxSpencerSubsteps) return false;
      (*msteps)[j] = static_cast<std::uint8_t>(mj);
    }
    Rk4Substeps((*msteps)[j], dt, &y, &z,
                [&](double s, double ys, double zs, double* dy, double* dz) { rates(j, s, ys, zs, dy, dz); });
  }
  return true;
}

struct Evaluation {
  Eigen::VectorXd r;
  double cost = kInf;
  double k1 = 0.0, x0 = 0.0, offset = 0.0;
  std::vector<std::vector<std::uint8_t>> substeps;  // per record, per sample step
};

class Problem {
 public:
  Problem(const std::vector<Prepared>& data, const DamperFitOptions& o, const Box& box) : data_(data), o_(o), box_(box) {
    for (const auto& d : data_) total_ += d.n;
  }
  int dim() const { return Dim(o_.filter); }
  const Box& box() const { return box_; }

  // fixed: substeps of a base evaluation to keep (nullptr: choose them here).
  Evaluation Evaluate(const Eigen::VectorXd& th, const Evaluation* fixed, Workspace* w,
                      std::vector<double>* fnl) const {
    Evaluation ev;
    const auto p = ParamsOf(th, o_.A);
    const auto drv = DriverOf(th, o_.filter);
    fnl->resize(total_);
    ev.substeps.resize(data_.size());
    std::size_t off = 0;
    for (std::size_t i = 0; i < data_.size(); ++i) {
      const auto& d = data_[i];
      if (fixed != nullptr) ev.substeps[i] = fixed->substeps[i];
      if (!SimulateNonlinear(p, drv, o_.filter, d, fixed == nullptr, &ev.substeps[i], w, fnl->data() + off))
        return ev;  // cost inf
      off += d.n;
    }
    LinearTerms::Solution lin;  // k1, x0 and the offset (LinearTerms), or none without the accumulator
    if (o_.accumulator) {
      LinearTerms sums;
      off = 0;
      for (const auto& d : data_) {
        for (std::size_t j = 0; j < d.n; ++j) sums.Add(d.weight, d.rec->y_mm[j], d.rec->f_kN[j] - (*fnl)[off + j]);
        off += d.n;
      }
      lin = sums.Solve();
    }
    ev.k1 = lin.k1;
    ev.x0 = lin.x0;
    ev.offset = lin.offset_kN;
    ev.r.resize(static_cast<Eigen::Index>(total_));
    off = 0;
    for (const auto& d : data_) {
      const double sw = std::sqrt(d.weight);
      for (std::size_t j = 0; j < d.n; ++j)
        ev.r[static_cast<Eigen::Index>(off + j)] = sw * (d.rec->f_kN[j] - (*fnl)[off + j] - lin.At(d.rec->y_mm[j]));
      off += d.n;
    }
    ev.cost = ev.r.squaredNorm();
    if (!std::isfinite(ev.cost)) ev.cost = kInf;
    return ev;
  }

 private:
  const std::vector<Prepared>& data_;
  const DamperFitOptions& o_;
  const Box& box_;
  std::size_t total_ = 0;
};

using State = LmState<Eigen::VectorXd, Evaluation>;

/// Levenberg-Marquardt iterations (lm.h), the Jacobian's columns on `threads` threads at the base
/// point's substeps. `on_iteration`: called after each iteration (may be empty).
void Iterate(State* s, const Problem& pb, int iterations, int threads, const std::function<void()>& on_iteration = {}) {
  std::vector<Workspace> ws(static_cast<std::size_t>(threads));
  std::vector<std::vector<double>> fnl(static_cast<std::size_t>(threads));
  LmIterate(
      s, pb.box(), iterations, [&](const Eigen::VectorXd& t) { return pb.Evaluate(t, nullptr, &ws[0], &fnl[0]); },
      [&](const Eigen::VectorXd& t, const Evaluation& base, int k) {
        return pb.Evaluate(t, &base, &ws[static_cast<std::size_t>(k)], &fnl[static_cast<std::size_t>(k)]);
      },
      [&](const Eigen::VectorXd& t) { return pb.Evaluate(t, nullptr, &ws[0], &fnl[0]); }, 1e-9, 1e-7, threads,
      on_iteration);
}

// Rough f ~ F_y sgn(x') + c x' + k x + b on the samples with `use`, weighted per record.
struct Rough {
  double Fy = 0.0, c = 0.0;
  std::size_t n = 0;
};
Rough RoughFit(const std::vector<Prepared>& data, const std::vector<std::vector<char>>& use) {
  Eigen::Matrix4d N = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  Rough r;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto& d = data[i];
    for (std::size_t k = 0; k < d.n; ++k) {
      if (!use[i][k]) continue;
      const double v = d.xdot[k];
      Eigen::Vector4d a(v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0), v, d.rec->y_mm[k], 1.0);
      N += d.weight * a * a.transpose();
      rhs += d.weight * d.rec->f_kN[k] * a;
      ++r.n;
    }
  }
  if (r.n < 8) return r;
  const Eigen::Vector4d sol = N.ldlt().solve(rhs);
  r.Fy = sol[0];
  r.c = sol[1];
  return r;
}

}  // namespace

std::span<const double> ControlInput(const io::RigRecord& rec, bool voltage) {
  const std::string where = rec.source.empty() ? "record" : rec.source;
  if (voltage) {
    if (rec.v_V.size() != rec.size())
      throw Error(where, "no voltage column v_V (the fit was asked for a voltage input)");
    return rec.v_V;
  }
  if (rec.i_A.size() != rec.size())
    throw Error(where, "no current column i_A (use the voltage input for a record with v_V only)");
  return rec.i_A;
}

std::vector<double> PredictSpencerForce(const models::MrDamperParams& params, const models::CurrentDriverParams& driver,
                                        ControlFilter filter, const io::RigRecord& rec, bool voltage, double cutoff_hz,
                                        double force_offset_kN) {
  params.Validate();
  Prepared d;
  d.rec = &rec;
  d.v = CommandForModel(rec, voltage).v;
  d.cutoff_hz = cutoff_hz > 0.0 ? cutoff_hz : VelocityCutoffHz(rec);
  d.xdot = SmoothVelocity(rec.y_mm, rec.dt_s, d.cutoff_hz);
  std::vector<double> f(rec.size(), kNaN);
  Workspace w;
  d.n = rec.size();
  std::vector<std::uint8_t> msteps;
  if (!SimulateNonlinear(params, driver, filter, d, true, &msteps, &w, f.data())) {
    for (std::size_t k = 0; k < f.size(); ++k)
      if (!std::isfinite(f[k])) {
        std::fill(f.begin() + static_cast<std::ptrdiff_t>(k), f.end(), kNaN);
        break;
      }
  }
  for (std::size_t k = 0; k < f.size(); ++k) f[k] += params.k1 * (rec.y_mm[k] - params.x0) + force_offset_kN;
  return f;
}

DamperRecordScore ScoreSpencer(const models::MrDamperParams& params, const models::CurrentDriverParams& driver,
                               ControlFilter filter, const io::RigRecord& rec, bool voltage, double cutoff_hz,
                               double force_offset_kN) {
  const double cutoff = cutoff_hz > 0.0 ? cutoff_hz : VelocityCutoffHz(rec);
  return ScoreForce(rec, PredictSpencerForce(params, driver, filter, rec, voltage, cutoff, force_offset_kN), cutoff);
}

namespace {

constexpr int kStartIterations = 8;  ///< LM iterations per start (DamperFitOptions::start_iterations unset)
constexpr int kMaxIterations = 150;  ///< ... for the best start (max_iterations unset)

/// What the records span: the largest |x| [mm] and |x'| [mm/s], the input's range [A or V].
struct Extent {
  double xmax = 0.0, vmax = 0.0, in_lo = kInf, in_hi = -kInf;
};

/// The records prepared for the fit (command, smoothed velocity, weight); checks them and the
/// input's range (variable and >= 0). Throws rths::Error naming the record or the reason.
std::vector<Prepared> PrepareRecords(const std::vector<io::RigRecord>& records, bool voltage, const DamperFitOptions& o,
                                     Extent* e, std::vector<std::string>* warnings) {
  std::vector<Prepared> data;
  for (const auto& rec : records) {
    CheckDamperColumns(rec);
    Prepared p;
    p.rec = &rec;
    auto command = CommandForModel(rec, voltage);
    if (!command.warning.empty()) warnings->push_back(command.warning);
    p.v = std::move(command.v);
    p.cutoff_hz = o.velocity_cutoff_hz > 0.0 ? o.velocity_cutoff_hz : VelocityCutoffHz(rec);
    p.xdot = SmoothVelocity(rec.y_mm, rec.dt_s, p.cutoff_hz);
    for (std::size_t k = 0; k < rec.size(); ++k) {
      e->vmax = std::max(e->vmax, std::abs(p.xdot[k]));
      e->xmax = std::max(e->xmax, std::abs(rec.y_mm[k]));
      e->in_lo = std::min(e->in_lo, p.v[k]);
      e->in_hi = std::max(e->in_hi, p.v[k]);
    }
    p.weight = ForceWeight(rec);
    p.n = rec.size();
    data.push_back(std::move(p));
  }
  if (!(e->vmax > 0.0)) throw Error("FitSpencer", "the displacement never moves: nothing to fit");
  const char* unit = voltage ? "V" : "A";
  if (!(e->in_hi - e->in_lo > 1e-6))
    throw Error("FitSpencer", fmt::format("the control input is constant ({} {}): its laws (Eqs. 35-39) cannot be "
                                          "fitted; fit at one current instead (--current)",
                                          e->in_lo, unit));
  return data;
}

/// The rough yield-force / viscous fits at the low and the high end of the input: over the
/// samples whose filtered input (eta of the starts) is in the lowest / highest tenth of its range.
std::pair<Rough, Rough> RoughEnds(const std::vector<Prepared>& data, const Extent& e, double fpeak,
                                  const DamperFitOptions& o) {
  models::CurrentDriverParams d0;
  if (o.filter == ControlFilter::kFirstOrder) {
    d0.kind = models::CurrentFilter::kFirstOrder;
    d0.eta_1_s = o.eta_start_1_s;
  }
  std::vector<std::vector<char>> low(data.size()), high(data.size());
  std::vector<double> u;
  for (std::size_t i = 0; i < data.size(); ++i) {
    FilteredInput(data[i].v, data[i].rec->dt_s, o.filter, d0, &u);
    low[i].resize(u.size());
    high[i].resize(u.size());
    for (std::size_t k = 0; k < u.size(); ++k) {
      low[i][k] = u[k] <= e.in_lo + 0.1 * (e.in_hi - e.in_lo);
      high[i][k] = u[k] >= e.in_hi - 0.1 * (e.in_hi - e.in_lo);
    }
  }
  auto sane = [&](Rough r) {
    if (!(r.Fy > 0.0)) r.Fy = 0.25 * fpeak;
    if (!(r.c > 0.0)) r.c = 0.1 * fpeak / e.vmax;
    return r;
  };
  return {sane(RoughFit(data, low)), sane(RoughFit(data, high))};
}

/// The starts (file comment): pre-yield travel at each end of the input range x c1/c0 from the
/// rough ends ra, rb, evaluated on pb (the first part of every record).
std::vector<State> Starts(const Rough& ra, const Rough& rb, const Extent& e, const Problem& pb,
                          const DamperFitOptions& o) {
  std::vector<State> starts;
  const std::pair<double, double> travels[] = {{0.1, 0.1}, {0.1, 0.5}, {0.5, 0.5}, {0.5, 2.0}, {2.0, 2.0}};
  for (const auto& [delta_a, delta_b] : travels) {
    for (double ratio : {1.0, 10.0}) {
      State s;
      s.theta.resize(pb.dim());
      const double rate = 2.0 / std::max(e.in_hi, 1e-6);
      const Rough* ends[2] = {&ra, &rb};
      for (int j = 0; j < 2; ++j) {
        const double delta = j == 0 ? delta_a : delta_b;
        const double zmax = o.A * delta, bg = 1.0 / (o.A * delta * delta);
        const double c0 = ends[j]->c * (1.0 + ratio) / ratio, c1 = ratio * c0;
        const double alpha = ends[j]->Fy / zmax * (c0 + c1) / c1;
        s.theta[0 + j] = std::log(alpha);
        s.theta[3 + j] = std::log(c0);
        s.theta[6 + j] = std::log(c1);
        s.theta[9 + j] = std::log(0.5 * bg);
        s.theta[12 + j] = std::log(0.5 * bg);
      }
      for (int l = 0; l < kLaws; ++l) s.theta[3 * l + 2] = std::log(rate);
      s.theta[kK0] = std::log(0.01 * rb.Fy / std::max(e.xmax, 1e-3));
      if (o.filter == ControlFilter::kFirstOrder) s.theta[kEta] = std::log(o.eta_start_1_s);
      s.theta = pb.box().Clamp(s.theta);
      Workspace w;
      std::vector<double> f;
      s.ev = pb.Evaluate(s.theta, nullptr, &w, &f);
      starts.push_back(std::move(s));
    }
  }
  return starts;
}

/// The start to continue on all the data: the best by its cost on the first part whose cost on
/// all of it (pb) is finite (a start may meet a stiffer stretch later in the records); its ev is
/// re-evaluated on all the data. -1 if none.
int BestOnAllData(std::vector<State>* starts, const Problem& pb) {
  std::vector<std::size_t> order(starts->size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return (*starts)[a].ev.cost < (*starts)[b].ev.cost; });
  for (std::size_t i : order) {
    if (!std::isfinite((*starts)[i].ev.cost)) break;
    Workspace w;
    std::vector<double> f;
    (*starts)[i].ev = pb.Evaluate((*starts)[i].theta, nullptr, &w, &f);
    if (std::isfinite((*starts)[i].ev.cost)) return static_cast<int>(i);
  }
  return -1;
}

/// The commands' design (fit_status.h "held"): the distinct levels if every record holds its
/// command constant (within 1e-6 of the input's range), else empty.
std::vector<double> ConstantLevels(const std::vector<Prepared>& data, const Extent& e) {
  const double tol = 1e-6 * std::max(e.in_hi - e.in_lo, 1e-12);
  std::vector<double> levels;
  for (const auto& d : data) {
    const auto [lo, hi] = std::minmax_element(d.v.begin(), d.v.end());
    if (*hi - *lo > tol) return {};
    const double level = 0.5 * (*lo + *hi);
    // One level per cluster within 1 % of the range.
    if (std::none_of(levels.begin(), levels.end(),
                     [&](double l) { return std::abs(l - level) <= 0.01 * (e.in_hi - e.in_lo); }))
      levels.push_back(level);
  }
  std::sort(levels.begin(), levels.end());
  return levels;
}

/// The box of the fit, with what the records cannot determine held (fit_status.h): eta when
/// every record holds its command constant (the filter never acts), the rates p_c when the
/// records hold two levels only (two points fix each law at those levels alone; p_c is then
/// held at 3 / (level_2 - level_1): 95 % of the change between them is made by the upper one).
/// Then the parameters the options hold (DamperFitOptions::hold), over the design's.
Box DesignBox(const std::vector<double>& levels, const DamperFitOptions& o, bool voltage) {
  Box box = MakeBox(Dim(o.filter));
  const char* unit = voltage ? "V" : "A";
  if (!levels.empty() && o.filter == ControlFilter::kFirstOrder)
    box.Hold(kEta, std::log(o.eta_start_1_s),
             "every record holds its command constant, so the filter's time constant never shows: the value of "
             "the starts");
  if (levels.size() == 2) {
    const double rate = 3.0 / (levels[1] - levels[0]);
    for (int l = 0; l < kLaws; ++l)
      box.Hold(3 * l + 2, std::log(std::clamp(rate, kFitRateLo, kFitRateHi)),
               fmt::format("the records hold two input levels, {:.4g} and {:.4g} {}, which fix each law there only: "
                           "between them the law is this assumption",
                           levels[0], levels[1], unit));
  }
  const int dim = Dim(o.filter);
  std::vector<std::string> names(kParamNames, kParamNames + dim);
  std::vector<double> lo, hi;
  for (int i = 0; i < dim; ++i) lo.push_back(LoBound(i)), hi.push_back(HiBound(i));
  for (const auto& h : o.hold)
    box.Hold(HeldIndex(h, names, lo, hi), std::log(h.second), fmt::format("held at {:g} by --hold", h.second));
  return box;
}

/// How the fit ended (fit_status.h) at theta.
FitStatus StatusAt(const State& s, const Box& box, int max_iterations) {
  FitStatus st;
  st.converged = s.converged;
  st.iterations = s.iterations;
  st.max_iterations = max_iterations;
  for (int i = 0; i < static_cast<int>(s.theta.size()); ++i) {
    ParameterStatus p = StatusOf(kParamNames[i], std::exp(s.theta[i]), LoBound(i), HiBound(i), ZeroFloor(i));
    if (box.Held(i)) {
      p.state = ParameterState::kHeld;
      p.why = box.held_why[static_cast<std::size_t>(i)];
    }
    st.parameters.push_back(std::move(p));
  }
  // A rate on a bound is irrelevant if its law's ends are equal, or both within 10 x the floor
  // (nil: the floors are far below any value that acts).
  for (int l = 0; l < kLaws; ++l) {
    auto& a = st.parameters[static_cast<std::size_t>(3 * l)];
    auto& b = st.parameters[static_cast<std::size_t>(3 * l + 1)];
    auto& c = st.parameters[static_cast<std::size_t>(3 * l + 2)];
    const bool flat = std::abs(s.theta[3 * l] - s.theta[3 * l + 1]) < 1e-3 ||
                      (a.value <= 10.0 * a.lo && b.value <= 10.0 * b.lo);
    if (c.state == ParameterState::kAtBound && flat) {
      c.state = ParameterState::kIrrelevant;
      c.why = fmt::format("{} = {:.3g} and {} = {:.3g}: the law is flat, so its rate changes nothing", a.name, a.value,
                          b.name, b.value);
    }
  }
  return st;
}

}  // namespace

bool UsesVoltage(const std::vector<io::RigRecord>& records, DamperInput input) {
  if (input == DamperInput::kAuto) return !records.empty() && records[0].i_A.empty();
  return input == DamperInput::kVoltage;
}

SpencerFitResult FitSpencer(const std::vector<io::RigRecord>& records, const DamperFitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!o.IsValid(&why)) throw Error("DamperFitOptions", why);
  if (records.empty()) throw Error("FitSpencer", "no records");
  const bool voltage = UsesVoltage(records, o.input);
  Extent e;
  SpencerFitResult res;
  const std::vector<Prepared> data = PrepareRecords(records, voltage, o, &e, &res.warnings);
  res.levels = ConstantLevels(data, e);
  const Box box = DesignBox(res.levels, o, voltage);
  const int threads = o.threads > 0 ? o.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const auto [ra, rb] = RoughEnds(data, e, PeakForce(records), o);
  // The starts run on the first part of every record (kStartShare of it, at least kStartMinS).
  std::vector<Prepared> part = data;
  for (auto& d : part)
    d.n = std::min(d.rec->size(), std::max(static_cast<std::size_t>(kStartShare * static_cast<double>(d.rec->size())),
                                           static_cast<std::size_t>(kStartMinS / d.rec->dt_s)));
  const Problem pb_part(part, o, box), pb(data, o, box);
  std::vector<State> starts = Starts(ra, rb, e, pb_part, o);
  const int start_iterations = o.start_iterations.value_or(kStartIterations);
  const int max_iterations = o.max_iterations.value_or(kMaxIterations);
  res.filter = o.filter;
  res.voltage = voltage;
  res.input_min = e.in_lo;
  res.input_max = e.in_hi;
  // Progress (DamperFitOptions::progress): whole-record iterations, a start's counting a quarter.
  const double work = 0.25 * static_cast<double>(starts.size() * static_cast<std::size_t>(start_iterations)) +
                      static_cast<double>(max_iterations);
  double done = 0.0;
  auto step = [&](double units, std::string_view what) {
    done += units;
    if (o.progress) o.progress(done, work, what);
  };
  bool any = false;
  for (auto& st : starts) {
    if (std::isfinite(st.ev.cost)) Iterate(&st, pb_part, start_iterations, threads, [&] { step(0.25, "starts"); });
    res.start_costs.push_back(st.ev.cost);
    any = any || std::isfinite(st.ev.cost);
  }
  if (!any) throw Error("FitSpencer", "no start gives a finite force prediction");
  const int best = BestOnAllData(&starts, pb);
  if (best < 0) throw Error("FitSpencer", "no start gives a finite force prediction on all the data");
  State& s = starts[static_cast<std::size_t>(best)];
  s.converged = false;
  done = 0.25 * static_cast<double>(starts.size() * static_cast<std::size_t>(start_iterations));
  Iterate(&s, pb, max_iterations, threads, [&] { step(1.0, "least squares on the whole record"); });
  if (o.progress) o.progress(work, work, "done");
  res.best_start = best;
  res.iterations = s.iterations;
  res.converged = s.converged;
  res.cost = s.ev.cost;
  res.params = ParamsOf(s.theta, o.A);
  res.params.k1 = s.ev.k1;
  res.params.x0 = s.ev.x0;
  res.force_offset_kN = s.ev.offset;
  res.driver = DriverOf(s.theta, o.filter);
  res.status = StatusAt(s, box, max_iterations);
  res.status.implausible = CheckPlausible(FittedValues(res.status, {{"k1", res.params.k1}}), o.A, voltage);
  for (const auto& d : data)
    res.records.push_back(
        ScoreSpencer(res.params, res.driver, o.filter, *d.rec, voltage, d.cutoff_hz, res.force_offset_kN));
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace rths::ident
