#include "piezobench/metrology/stiffness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "check.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::metrology {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

void StaticStiffnessOptions::validate() const {
  const std::string src = "static stiffness options";
  detail::require_finite_positive(added_mass, src, "added_mass", "kg");
  detail::require_finite_positive(gravity, src, "gravity", "m/s^2");
  detail::require_finite_positive(settle_s, src, "settle_s", "s");
  detail::require_finite_nonnegative(t_on, src, "t_on", "s");
  detail::require_finite_nonnegative(t_off, src, "t_off", "s");
  if ((t_on > 0.0) != (t_off > 0.0) || (t_on > 0.0 && t_off <= t_on)) {
    throw InputError(src, "t_off", "both event times 0 (detect) or 0 < t_on < t_off",
                     fmt::format("t_on {} s, t_off {} s", format_number(t_on), format_number(t_off)));
  }
  auto window = [&](const std::array<double, 2>& w, const char* field) {
    if (!(std::isfinite(w[0]) && std::isfinite(w[1]) && w[0] < w[1])) {
      throw InputError(src, field, "a window [from, to) with from < to (s)", fmt::format("[{}, {}]", format_number(w[0]), format_number(w[1])));
    }
  };
  window(before_s, "before_s");
  window(loaded_s, "loaded_s");
  window(after_s, "after_s");
  if (before_s[1] > 0.0) throw InputError(src, "before_s", "a window before t_on (to <= 0)", format_number(before_s[1]));
  if (loaded_s[1] > 0.0) throw InputError(src, "loaded_s", "a window before t_off (to <= 0)", format_number(loaded_s[1]));
  if (after_s[0] < 0.0) throw InputError(src, "after_s", "a window after t_off (from >= 0)", format_number(after_s[0]));
  detail::require_finite_positive(min_time_constant, src, "min_time_constant", "s");
  if (!(std::isfinite(max_time_constant) && max_time_constant > min_time_constant)) {
    throw InputError(src, "max_time_constant", "a time > min_time_constant", format_number(max_time_constant));
  }
}

namespace {

struct Fit {
  VectorXd coef;  // d0, D_on, c_on, D_off, c_off
  double sse = std::numeric_limits<double>::infinity();
  Index used = 0;
};

// The log creep term log10(1 + s / tau) at s >= 0 after the event (log, not log10: the fit below
// evaluates it some 10 million times per record, and glibc's log is the faster one).
double creep_term(double s, double inv_tau) {
  constexpr double kInvLn10 = 0.43429448190325182765;
  return std::log(1.0 + s * inv_tau) * kInvLn10;
}

// Model columns at time t (log creep with time constant tau).
void basis_row(double t, double t_on, double t_off, double tau, double* row) {
  const double on = t >= t_on ? 1.0 : 0.0;
  const double off = t >= t_off ? 1.0 : 0.0;
  row[0] = 1.0;
  row[1] = on;
  row[2] = on * creep_term(std::max(0.0, t - t_on), 1.0 / tau);
  row[3] = off;
  row[4] = off * creep_term(std::max(0.0, t - t_off), 1.0 / tau);
}

// The record's rows split by the model's pieces (before t_on: [1 0 0 0 0]; from t_on: [1 1 a 0 0];
// from t_off: [1 1 a 1 b], with a, b the log creep terms) and the sums that do not depend on tau:
// per time constant only a and b are evaluated and summed, no row of five columns and no rank
// update (the grid below fits 43 time constants on records of a few hundred thousand samples).
struct CreepRows {
  std::vector<double> s_on, d_on;          // rows in [t_on, t_off): t - t_on, de
  std::vector<double> s_on2, s_off, d_off;  // rows from t_off: t - t_on, t - t_off, de
  // de is taken about its mean over the rows (added back to the offset d0): b'b - b'A x then
  // cancels far less. On the demo's records the creep times picked from these sums agree with
  // those picked from exact residual sums to 1e-8; without the centring they differed by more.
  double mean = 0.0;
  double n = 0.0, sum_d = 0.0, sum_dd = 0.0, sum_d_on = 0.0, sum_d_off = 0.0;
};

CreepRows split_rows(const Eigen::Ref<const VectorXd>& t, const Eigen::Ref<const VectorXd>& de, const std::vector<Index>& rows,
                     double t_on, double t_off) {
  CreepRows c;
  for (const Index k : rows) c.mean += de(k);
  c.mean /= static_cast<double>(rows.size());
  for (const Index k : rows) {
    const double tk = t(k), d = de(k) - c.mean;
    c.n += 1.0;
    c.sum_d += d;
    c.sum_dd += d * d;
    if (tk >= t_off) {
      c.s_on2.push_back(tk - t_on);
      c.s_off.push_back(tk - t_off);
      c.d_off.push_back(d);
      c.sum_d_on += d;
      c.sum_d_off += d;
    } else if (tk >= t_on) {
      c.s_on.push_back(tk - t_on);
      c.d_on.push_back(d);
      c.sum_d_on += d;
    }
  }
  return c;
}

// Least squares of the creep model over `rows` through its 5 x 5 normal equations. The columns are
// of order 1, so the normal equations lose nothing that matters here; the residual is summed
// directly when `exact_sse` (else b'b - b'A x, ample for comparing time constants).
Fit fit_creep(const Eigen::Ref<const VectorXd>& t, const Eigen::Ref<const VectorXd>& de, const std::vector<Index>& rows,
              const CreepRows& c, double t_on, double t_off, double tau, const std::string& source, bool exact_sse = false) {
  const double inv_tau = 1.0 / tau;
  double sa = 0.0, saa = 0.0, sad = 0.0;                              // a over the rows from t_on
  double sa2 = 0.0, sb = 0.0, sbb = 0.0, sab = 0.0, sbd = 0.0;        // a and b over the rows from t_off
  for (std::size_t i = 0; i < c.s_on.size(); ++i) {
    const double a = creep_term(c.s_on[i], inv_tau);
    sa += a;
    saa += a * a;
    sad += a * c.d_on[i];
  }
  for (std::size_t i = 0; i < c.s_off.size(); ++i) {
    const double a = creep_term(c.s_on2[i], inv_tau);
    const double b = creep_term(c.s_off[i], inv_tau);
    sa2 += a;
    saa += a * a;
    sad += a * c.d_off[i];
    sb += b;
    sbb += b * b;
    sab += a * b;
    sbd += b * c.d_off[i];
  }
  sa += sa2;
  const double n_on = static_cast<double>(c.s_on.size() + c.s_off.size());
  const double n_off = static_cast<double>(c.s_off.size());
  Eigen::Matrix<double, 5, 5> ata;
  ata << c.n, n_on, sa, n_off, sb,  //
      n_on, n_on, sa, n_off, sb,    //
      sa, sa, saa, sa2, sab,        //
      n_off, n_off, sa2, n_off, sb, //
      sb, sb, sab, sb, sbb;
  Eigen::Matrix<double, 5, 1> atb;
  atb << c.sum_d, c.sum_d_on, sad, c.sum_d_off, sbd;
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 5, 5>> qr(ata);
  if (qr.rank() < 5) {
    throw NumericalError("static stiffness (" + source + ")", "the creep model is singular on this record", false);
  }
  const Eigen::Matrix<double, 5, 1> x = qr.solve(atb);
  Fit f;
  f.coef = x;
  f.coef(0) += c.mean;
  f.used = static_cast<Index>(rows.size());
  if (exact_sse) {
    f.sse = 0.0;
    Eigen::Matrix<double, 5, 1> row;
    for (const Index k : rows) {
      basis_row(t(k), t_on, t_off, tau, row.data());
      const double r = row.dot(f.coef) - de(k);
      f.sse += r * r;
    }
  } else {
    f.sse = std::max(0.0, c.sum_dd - atb.dot(x));
  }
  return f;
}

double window_mean(const Eigen::Ref<const VectorXd>& t, const Eigen::Ref<const VectorXd>& de, double from, double to) {
  double s = 0.0;
  Index n = 0;
  for (Index k = 0; k < t.size(); ++k) {
    if (t(k) >= from && t(k) < to) {
      s += de(k);
      ++n;
    }
  }
  return n > 0 ? s / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
}

using Signal = Eigen::Ref<const VectorXd>;

void check_stiffness_record(const Signal& t, const Signal& de, const Signal& mass_log, const std::string& source) {
  detail::require_signal(t, source, "t", 10);
  detail::require_signal(de, source, "de", 10);
  detail::require_same_length(t.size(), de.size(), source, "de");
  if (mass_log.size() > 0) {
    detail::require_signal(mass_log, source, "added_mass", 10);
    detail::require_same_length(t.size(), mass_log.size(), source, "added_mass");
  }
  for (Index k = 1; k < t.size(); ++k) {
    if (!(t(k) > t(k - 1))) {
      throw InputError(source, "t", "strictly increasing times", fmt::format("t[{}] = {} after {}", k, t(k), t(k - 1)));
    }
  }
}

// t_on and t_off from the mass log: the first sample above 1 % of the mass, the first below 99 %
// after the full load.
void events_from_mass_log(const Signal& t, const Signal& mass_log, const std::string& source, StaticStiffnessResult& r) {
  const Index n = t.size();
  const double top = mass_log.maxCoeff();
  if (!(top > 0.0)) throw InputError(source, "added_mass", "a log showing the mass put on (> 0 kg)", "no mass");
  Index on = 0;
  while (on < n && !(mass_log(on) > 0.01 * top)) ++on;
  Index off = on;
  while (off < n && !(mass_log(off) >= 0.99 * top)) ++off;  // fully loaded
  while (off < n && mass_log(off) >= 0.99 * top) ++off;     // then unloading starts
  if (on == 0 || off >= n) {
    throw InputError(source, "added_mass", "a log with the mass put on after the start and taken off before the end",
                     on == 0 ? "the mass on from the first sample" : "the mass never taken off");
  }
  r.t_on = 0.5 * (t(on - 1) + t(on));
  r.t_off = 0.5 * (t(off - 1) + t(off));
}

// t_on and t_off from the deflection: the two largest changes over settle_s, opposite in sign.
void events_from_deflection(const Signal& t, const Signal& de, double settle_s, double dt, const std::string& source,
                            StaticStiffnessResult& r) {
  const Index n = t.size();
  const Index w = std::max<Index>(1, static_cast<Index>(std::lround(settle_s / dt)));
  if (n <= w + 1) throw InputError(source, "de", "a record longer than settle_s", fmt::format("{} samples", n));
  Index kmin = 0, kmax = 0;
  for (Index k = 0; k + w < n; ++k) {
    const double g = de(k + w) - de(k);
    if (g < de(kmin + w) - de(kmin)) kmin = k;
    if (g > de(kmax + w) - de(kmax)) kmax = k;
  }
  // The mass starts moving at the event: the first sample of the window that has left the
  // level before it (mean over the preceding w/5 samples) by 2 % of the change over the window.
  auto start_of_motion = [&](Index k0) {
    const Index m = std::max<Index>(1, w / 5);
    const Index from = std::max<Index>(0, k0 - m);
    const double level = de.segment(from, k0 - from + 1).mean();
    const double change = de(k0 + w) - level;
    Index k = k0 + 1;
    while (k < k0 + w && std::abs(de(k) - level) <= 0.02 * std::abs(change)) ++k;
    return k;
  };
  const Index a = start_of_motion(std::min(kmin, kmax));
  const Index b = start_of_motion(std::max(kmin, kmax));
  if (b - a <= w) throw InputError(source, "de", "two separate steps (mass on, mass off)", "no second step");
  r.t_on = 0.5 * (t(a - 1) + t(a));
  r.t_off = 0.5 * (t(b - 1) + t(b));
}

// Every window and the settling times inside the record, in order.
void check_windows(const Signal& t, const StaticStiffnessResult& r, const StaticStiffnessOptions& options, double dt,
                   const std::string& source) {
  const Index n = t.size();
  const double settle = options.settle_s;
  auto inside = [&](double from, double to, const char* field, const char* what) {
    if (from < t(0) || to > t(n - 1) + dt) {
      throw InputError(source, field, fmt::format("the {} window [{}, {}) s inside the record [{}, {}] s", what, format_number(from), format_number(to), format_number(t(0)), format_number(t(n - 1))),
                       "a window outside the record");
    }
  };
  inside(r.t_on + options.before_s[0], r.t_on + options.before_s[1], "t_on", "reading-before");
  inside(r.t_off + options.loaded_s[0], r.t_off + options.loaded_s[1], "t_off", "loaded-reading");
  inside(r.t_off + options.after_s[0], r.t_off + options.after_s[1], "t_off", "reading-after");
  if (r.t_off + options.loaded_s[0] < r.t_on + settle) {
    throw InputError(source, "t_off", fmt::format("the loaded-reading window after t_on + settle_s = {} s", format_number(r.t_on + settle)),
                     fmt::format("a window from {} s", format_number(r.t_off + options.loaded_s[0])));
  }
  if (t(n - 1) < r.t_off + settle + 0.5) {
    throw InputError(source, "t_off", fmt::format("at least settle_s + 0.5 s = {} s of record after the mass is taken off", format_number(settle + 0.5)),
                     fmt::format("{} s", format_number(t(n - 1) - r.t_off)));
  }
}

constexpr int kGrid = 41;       // time constants, log-spaced
constexpr int kCoarseStep = 4;  // every 4th grid point first (0.4 decade with the default grid)

// The index of the smallest misfit on the grid, lowest index on a tie, as a search of all kGrid
// points would find it, evaluating fewer: every kCoarseStep-th point first; when those fall then
// rise (one minimum), only the points between the best one's coarse neighbours are added, else the
// whole grid is. Each record's fit costs a logarithm per sample and grid point (the demo's largest
// analysis cost), and this evaluates 18 of the 41 points on a misfit with one minimum. `sse`
// receives the misfits, NaN where not evaluated.
template <class Misfit>
int best_grid_point(const Misfit& misfit, std::vector<double>& sse) {
  sse.assign(kGrid, std::numeric_limits<double>::quiet_NaN());
  const auto at = [&](int i) {
    auto& v = sse[static_cast<std::size_t>(i)];
    if (std::isnan(v)) v = misfit(i);
    return v;
  };
  int coarse_best = 0;
  for (int i = 0; i < kGrid; i += kCoarseStep) {
    if (at(i) < at(coarse_best)) coarse_best = i;
  }
  bool one_minimum = true;
  for (int i = kCoarseStep; i < kGrid; i += kCoarseStep) {
    const bool rises = at(i) > at(i - kCoarseStep);
    const bool before_best = i <= coarse_best;
    if (rises == before_best && at(i) != at(i - kCoarseStep)) one_minimum = false;
  }
  const int from = one_minimum ? std::max(0, coarse_best - kCoarseStep + 1) : 0;
  const int to = one_minimum ? std::min(kGrid - 1, coarse_best + kCoarseStep - 1) : kGrid - 1;
  int best = from;
  for (int i = from; i <= to; ++i) {
    if (at(i) < at(best)) best = i;
  }
  if (best > 0) at(best - 1);  // the parabola's neighbours
  if (best < kGrid - 1) at(best + 1);
  return best;
}

// The creep model fitted to the rows outside the settling times: a grid over log10(tau), then a
// parabola through the best point and its neighbours (kept when it does better than the grid).
// Sets r's creep time constant, deflections, creeps, rms residual and fit.
void fit_creep_model(const Signal& t, const Signal& de, const StaticStiffnessOptions& options, const std::string& source,
                     StaticStiffnessResult& r) {
  const Index n = t.size();
  const double settle = options.settle_s;
  std::vector<Index> rows;
  for (Index k = 0; k < n; ++k) {
    const double tk = t(k);
    const bool settling = (tk >= r.t_on && tk < r.t_on + settle) || (tk >= r.t_off && tk < r.t_off + settle);
    if (!settling) rows.push_back(k);
  }
  const CreepRows split = split_rows(t, de, rows, r.t_on, r.t_off);
  const double l0 = std::log10(options.min_time_constant);
  const double l1 = std::log10(options.max_time_constant);
  const auto grid_sse = [&](int i) {
    return fit_creep(t, de, rows, split, r.t_on, r.t_off, std::pow(10.0, l0 + (l1 - l0) * i / (kGrid - 1)), source).sse;
  };
  std::vector<double> sse;
  const int best = best_grid_point(grid_sse, sse);
  const double h = (l1 - l0) / (kGrid - 1);
  double lbest = l0 + h * best;
  if (best > 0 && best < kGrid - 1) {
    const double ym = sse[static_cast<std::size_t>(best - 1)];
    const double y0 = sse[static_cast<std::size_t>(best)];
    const double yp = sse[static_cast<std::size_t>(best + 1)];
    const double denom = ym - 2.0 * y0 + yp;
    if (denom > 0.0) lbest += 0.5 * h * (ym - yp) / denom;
  }
  Fit f = fit_creep(t, de, rows, split, r.t_on, r.t_off, std::pow(10.0, lbest), source, true);
  const Fit at_grid = fit_creep(t, de, rows, split, r.t_on, r.t_off, std::pow(10.0, l0 + h * best), source, true);
  if (at_grid.sse < f.sse) {
    f = at_grid;
    lbest = l0 + h * best;
  }
  r.creep_time_constant = std::pow(10.0, lbest);
  r.deflection_on = f.coef(1);
  r.creep_on = f.coef(2);
  r.deflection_off = f.coef(3);
  r.creep_off = f.coef(4);
  r.rms_residual = std::sqrt(f.sse / static_cast<double>(f.used));
  r.fit.resize(n);
  double row[5];
  for (Index k = 0; k < n; ++k) {
    basis_row(t(k), r.t_on, r.t_off, r.creep_time_constant, row);
    r.fit(k) = 0.0;
    for (int j = 0; j < 5; ++j) r.fit(k) += row[j] * f.coef(j);
  }
}

// The stiffnesses: elastic from the fitted deflections, k1 and k2 from the reading windows.
void stiffnesses(const Signal& t, const Signal& de, const StaticStiffnessOptions& options, const std::string& source,
                 StaticStiffnessResult& r) {
  const double weight = options.added_mass * options.gravity;
  if (r.deflection_on == 0.0 || r.deflection_off == 0.0) {
    throw InputError(source, "de", "a deflection when the mass is put on and taken off", "none");
  }
  r.k_elastic_on = weight / std::abs(r.deflection_on);
  r.k_elastic_off = weight / std::abs(r.deflection_off);
  r.d_before = window_mean(t, de, r.t_on + options.before_s[0], r.t_on + options.before_s[1]);
  r.d_loaded = window_mean(t, de, r.t_off + options.loaded_s[0], r.t_off + options.loaded_s[1]);
  r.d_after = window_mean(t, de, r.t_off + options.after_s[0], r.t_off + options.after_s[1]);
  if (!std::isfinite(r.d_before) || !std::isfinite(r.d_loaded) || !std::isfinite(r.d_after)) {
    throw InputError(source, "t", "samples inside every reading window", "an empty window");
  }
  if (r.d_before == r.d_loaded || r.d_after == r.d_loaded) {
    throw InputError(source, "de", "a deflection under the added mass", "none");
  }
  r.k1 = weight / std::abs(r.d_before - r.d_loaded);
  r.k2 = weight / std::abs(r.d_after - r.d_loaded);
}

}  // namespace

StaticStiffnessResult static_stiffness(const Eigen::Ref<const VectorXd>& t, const Eigen::Ref<const VectorXd>& de,
                                       const Eigen::Ref<const VectorXd>& mass_log, const StaticStiffnessOptions& options,
                                       const std::string& source) {
  options.validate();
  check_stiffness_record(t, de, mass_log, source);
  const Index n = t.size();
  const double dt = (t(n - 1) - t(0)) / static_cast<double>(n - 1);
  StaticStiffnessResult r;
  if (options.t_on > 0.0) {
    r.t_on = options.t_on;
    r.t_off = options.t_off;
  } else if (mass_log.size() > 0) {
    events_from_mass_log(t, mass_log, source, r);
  } else {
    events_from_deflection(t, de, options.settle_s, dt, source, r);
  }
  check_windows(t, r, options, dt, source);
  fit_creep_model(t, de, options, source, r);
  stiffnesses(t, de, options, source, r);
  return r;
}

double stiffness_from_resonance(double mass, double resonance_rad_s, const std::string& source) {
  detail::require_finite_positive(mass, source, "mass", "kg");
  detail::require_finite_positive(resonance_rad_s, source, "resonance", "rad/s");
  return mass * resonance_rad_s * resonance_rad_s;
}

}  // namespace piezobench::metrology
