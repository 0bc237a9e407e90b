#include "piezobench/lti/rlocus.hpp"

#include <algorithm>
#include <cassert>
#include <iterator>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <numbers>
#include <sstream>
#include <string>

#include "check.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/minimize.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/freqresp.hpp"

namespace piezobench::lti {
namespace {

void check_loop(const StateSpace& open_loop, const std::string& source) {
  open_loop.validate(source);
  if (open_loop.inputs() != 1 || open_loop.outputs() != 1) {
    throw InputError(source, "open_loop", "a SISO loop (1 input, 1 output)",
                     std::to_string(open_loop.inputs()) + " inputs, " + std::to_string(open_loop.outputs()) +
                         " outputs");
  }
  if (open_loop.has_delay()) {
    throw InputError(source, "open_loop", "a loop without delays (approximate them with lti::pade first)",
                     "input/output delays");
  }
}

// Closed-loop poles of a checked loop: eig(A - k B (1 + k D)^-1 C).
CVector poles_at(const StateSpace& loop, double gain) {
  const double d = loop.D(0, 0);
  const double den = 1.0 + gain * d;
  if (std::abs(den) <= 4.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::abs(gain * d))) {
    throw NumericalError("rlocus", "1 + k D = 0 at k = " + format_number(gain, 10) + ": the closed loop is not proper",
                         /*retry_may_help=*/true);
  }
  StateSpace cl = loop;
  cl.A = loop.A - (gain / den) * loop.B * loop.C;
  return poles(cl);
}

// Minimum-cost perfect assignment on a square cost matrix (Hungarian algorithm with potentials,
// Kuhn 1955 / Munkres 1957, O(n^3)). Returns column[row].
std::vector<Index> hungarian(const Matrix& cost) {
  const Index n = cost.rows();
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based potentials u (rows) and v (columns); match[j] = row assigned to column j (0 = none).
  std::vector<double> u(static_cast<size_t>(n) + 1, 0.0);
  std::vector<double> v(static_cast<size_t>(n) + 1, 0.0);
  std::vector<Index> match(static_cast<size_t>(n) + 1, 0);
  std::vector<Index> way(static_cast<size_t>(n) + 1, 0);
  for (Index i = 1; i <= n; ++i) {
    match[0] = i;
    Index j0 = 0;
    std::vector<double> minv(static_cast<size_t>(n) + 1, inf);
    std::vector<char> used(static_cast<size_t>(n) + 1, 0);
    do {
      used[static_cast<size_t>(j0)] = 1;
      const Index i0 = match[static_cast<size_t>(j0)];
      double delta = inf;
      Index j1 = 0;
      for (Index j = 1; j <= n; ++j) {
        if (used[static_cast<size_t>(j)] != 0) continue;
        const double cur = cost(i0 - 1, j - 1) - u[static_cast<size_t>(i0)] - v[static_cast<size_t>(j)];
        if (cur < minv[static_cast<size_t>(j)]) {
          minv[static_cast<size_t>(j)] = cur;
          way[static_cast<size_t>(j)] = j0;
        }
        if (minv[static_cast<size_t>(j)] < delta) {
          delta = minv[static_cast<size_t>(j)];
          j1 = j;
        }
      }
      assert(j1 != 0);
      for (Index j = 0; j <= n; ++j) {
        if (used[static_cast<size_t>(j)] != 0) {
          u[static_cast<size_t>(match[static_cast<size_t>(j)])] += delta;
          v[static_cast<size_t>(j)] -= delta;
        } else {
          minv[static_cast<size_t>(j)] -= delta;
        }
      }
      j0 = j1;
    } while (match[static_cast<size_t>(j0)] != 0);
    do {
      const Index j1 = way[static_cast<size_t>(j0)];
      match[static_cast<size_t>(j0)] = match[static_cast<size_t>(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<Index> column(static_cast<size_t>(n), 0);
  for (Index j = 1; j <= n; ++j) column[static_cast<size_t>(match[static_cast<size_t>(j)] - 1)] = j - 1;
  return column;
}

// `next` reordered so that entry b continues entry b of `previous` (minimum total displacement).
CVector match_to(const CVector& previous, const CVector& next) {
  const Index n = previous.size();
  assert(next.size() == n);
  if (n <= 1) return next;
  Matrix cost(n, n);
  for (Index i = 0; i < n; ++i) {
    for (Index j = 0; j < n; ++j) cost(i, j) = std::abs(previous(i) - next(j));
  }
  if (!cost.allFinite()) {
    throw NumericalError("rlocus", "non-finite closed-loop poles while matching branches", /*retry_may_help=*/false);
  }
  const std::vector<Index> col = hungarian(cost);
  CVector out(n);
  for (Index i = 0; i < n; ++i) out(i) = next(col[static_cast<size_t>(i)]);
  return out;
}

// Damping ratio of a pole, continuous or discrete (mapped by s = log(z)/Ts as MATLAB's damp).
double damping_of(Complex p, double ts) {
  const Complex s = ts > 0.0 ? std::log(p) / ts : p;
  const double mag = std::abs(s);
  if (mag == 0.0) return -1.0;
  return -s.real() / mag;
}

// Scales used by the automatic grid, from the open-loop poles and zeros.
struct LoopScales {
  double smallest = 1.0;   // smallest nonzero |pole| or |zero| (1 when all vanish)
  double largest = 1.0;    // largest |pole| or |zero| (at least `smallest`)
  CVector zeros;           // finite open-loop zeros
};

LoopScales loop_scales(const StateSpace& loop, const CVector& open_poles) {
  LoopScales sc;
  sc.zeros = zeros(loop);
  double smallest = std::numeric_limits<double>::infinity();
  double largest = 0.0;
  auto visit = [&](const CVector& v) {
    for (Index i = 0; i < v.size(); ++i) {
      const double m = std::abs(v(i));
      if (m > 0.0) smallest = std::min(smallest, m);
      largest = std::max(largest, m);
    }
  };
  visit(open_poles);
  visit(sc.zeros);
  sc.smallest = std::isfinite(smallest) ? smallest : 1.0;
  sc.largest = std::max(largest, sc.smallest);
  return sc;
}

// Largest move of any matched pole, relative to its scale |p| + smallest.
double relative_move(const CVector& from, const CVector& to, double smallest) {
  double worst = 0.0;
  for (Index i = 0; i < from.size(); ++i) {
    worst = std::max(worst, std::abs(to(i) - from(i)) / (std::abs(from(i)) + smallest));
  }
  return worst;
}

// A closed-loop pole at `distance` from the open-loop zero z has reached it: within settle_fraction
// of the zero's scale |z| + smallest.
bool reached_zero(double distance, Complex z, const LoopScales& sc, double settle_fraction) {
  return distance <= settle_fraction * (std::abs(z) + sc.smallest);
}

// Every open-loop zero has a closed-loop pole within settle_fraction of its scale, and every other
// pole has gone beyond largest / settle_fraction (on its way to infinity along an asymptote).
bool settled(const CVector& poles_k, const LoopScales& sc, double settle_fraction) {
  const Index n = poles_k.size();
  std::vector<char> used(static_cast<size_t>(n), 0);
  for (Index j = 0; j < sc.zeros.size(); ++j) {
    Index best = -1;
    double best_dist = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < n; ++i) {
      if (used[static_cast<size_t>(i)] != 0) continue;
      const double dist = std::abs(poles_k(i) - sc.zeros(j));
      if (dist < best_dist) {
        best_dist = dist;
        best = i;
      }
    }
    if (best < 0 || !reached_zero(best_dist, sc.zeros(j), sc, settle_fraction)) return false;
    used[static_cast<size_t>(best)] = 1;
  }
  const double far = sc.largest / settle_fraction;
  for (Index i = 0; i < n; ++i) {
    if (used[static_cast<size_t>(i)] == 0 && std::abs(poles_k(i)) < far) return false;
  }
  return true;
}

// A first nonzero gain of the right order: a small fraction of 1 / max |L| over the band of the
// open-loop dynamics (the bisection of rlocus_auto then shrinks it as needed).
double first_gain(const StateSpace& loop, const LoopScales& sc) {
  double peak = 0.0;
  const FrequencyResponseEvaluator eval(loop);
  constexpr int kPoints = 60;
  for (int i = 0; i < kPoints; ++i) {
    const double t = static_cast<double>(i) / (kPoints - 1);
    Complex point;
    if (loop.is_discrete()) {
      point = std::polar(1.0, std::numbers::pi * std::pow(1e-4, 1.0 - t));
    } else {
      const double lo = sc.smallest / 10.0;
      const double hi = sc.largest * 10.0;
      point = Complex(0.0, lo * std::pow(hi / lo, t));
    }
    try {
      peak = std::max(peak, std::abs(eval.evaluate(point)(0, 0)));
    } catch (const NumericalError&) {
      // A pole on the imaginary axis (unit circle) at this point: skip it.
    }
  }
  if (!(peak > 0.0) || !std::isfinite(peak)) return 1e-6;
  return 1e-3 / peak;
}

}  // namespace

void RootLocusOptions::validate() const {
  if (!std::isfinite(gain_min) || gain_min < 0.0) {
    throw InputError("rlocus", "gain_min", "a finite gain >= 0", format_number(gain_min, 10));
  }
  if (!std::isfinite(gain_max) || gain_max < 0.0 || (gain_max > 0.0 && gain_max <= gain_min)) {
    throw InputError("rlocus", "gain_max", "0 (automatic) or a finite gain above gain_min = " + format_number(gain_min, 10),
                     format_number(gain_max, 10));
  }
  if (!std::isfinite(max_relative_step) || max_relative_step <= 0.0 || max_relative_step > 1.0) {
    throw InputError("rlocus", "max_relative_step", "a fraction in (0, 1]", format_number(max_relative_step, 10));
  }
  if (!std::isfinite(settle_fraction) || settle_fraction <= 0.0 || settle_fraction >= 1.0) {
    throw InputError("rlocus", "settle_fraction", "a fraction in (0, 1)", format_number(settle_fraction, 10));
  }
  if (max_points < 2) throw InputError("rlocus", "max_points", "a count >= 2", std::to_string(max_points));
  if (max_order < 1) throw InputError("rlocus", "max_order", "a count >= 1", std::to_string(max_order));
  if (!std::isfinite(max_work) || max_work <= 0.0) throw InputError("rlocus", "max_work", "a finite budget > 0", format_number(max_work, 10));
}

CVector closed_loop_poles(const StateSpace& open_loop, double gain) {
  check_loop(open_loop, "closed_loop_poles");
  if (!std::isfinite(gain)) throw InputError("closed_loop_poles", "gain", "a finite gain", format_number(gain, 10));
  return poles_at(open_loop, gain);
}

RootLocus rlocus(const StateSpace& open_loop, const std::vector<double>& gains) {
  check_loop(open_loop, "rlocus");
  for (size_t i = 0; i < gains.size(); ++i) {
    if (!std::isfinite(gains[i])) {
      throw InputError("rlocus", "gains[" + std::to_string(i) + "]", "a finite gain", format_number(gains[i], 10));
    }
  }
  RootLocus rl;
  rl.gains = gains;
  rl.poles.reserve(gains.size());
  for (size_t i = 0; i < gains.size(); ++i) {
    CVector p = poles_at(open_loop, gains[i]);
    if (i > 0) p = match_to(rl.poles.back(), p);
    rl.poles.push_back(std::move(p));
  }
  return rl;
}

namespace {

// The index of the pole of `poles` nearest to p: the branch that starts at the open-loop pole p
// (locus_grid watches it, max_damping_on_branch follows it; both find it the same way).
Index branch_of(const CVector& poles, Complex p) {
  Index branch = 0;
  (poles.array() - p).abs().minCoeff(&branch);
  return branch;
}

// True once the branch `b` has settled: within settle_fraction of an open-loop zero, or gone
// beyond largest / settle_fraction (towards an asymptote).
bool branch_settled(const CVector& poles_k, Index b, const LoopScales& sc, double settle_fraction) {
  const Complex p = poles_k(b);
  for (Index j = 0; j < sc.zeros.size(); ++j) {
    if (reached_zero(std::abs(p - sc.zeros(j)), sc.zeros(j), sc, settle_fraction)) return true;
  }
  return std::abs(p) >= sc.largest / settle_fraction;
}

// rlocus_auto's grid. With `watch` (the open-loop pole of one branch), the automatic end comes when
// that branch has settled, whatever the others do (max_damping_on_branch follows one branch; a
// pole leaving for infinity can take thousands of grid points to pass largest / settle_fraction).
RootLocus locus_grid(const StateSpace& open_loop, const RootLocusOptions& options, std::optional<Complex> watch) {
  options.validate();
  const Index n = open_loop.states();
  if (n > options.max_order) {
    throw InputError("rlocus", "loop order", "at most max_order = " + std::to_string(options.max_order) + " states",
                     std::to_string(n) + " states");
  }
  // Eigenvalue problems this grid may solve (rejected steps included).
  const double n3 = std::max(1.0, static_cast<double>(n) * static_cast<double>(n) * static_cast<double>(n));
  const double max_evaluations = std::max(16.0, std::floor(options.max_work / n3));
  double evaluations = 1.0;
  RootLocus rl;
  const bool automatic = options.gain_max == 0.0;
  CVector current = poles_at(open_loop, options.gain_min);
  rl.gains.push_back(options.gain_min);
  rl.poles.push_back(current);
  if (open_loop.states() == 0) {
    // No poles to follow: the locus is empty at every gain.
    if (!automatic) {
      rl.gains.push_back(options.gain_max);
      rl.poles.push_back(current);
    }
    return rl;
  }
  const LoopScales sc = loop_scales(open_loop, poles(open_loop));
  const Index watched = watch ? branch_of(current, *watch) : -1;
  const auto done = [&](const CVector& p) {
    return watched >= 0 ? branch_settled(p, watched, sc, options.settle_fraction) : settled(p, sc, options.settle_fraction);
  };
  // 1 + k D vanishes at k = -1/D when D < 0: the locus stops just before it (poles leave for
  // infinity there).
  double hard_limit = std::numeric_limits<double>::infinity();
  const double d = open_loop.D(0, 0);
  if (d < 0.0) hard_limit = (-1.0 / d) * (1.0 - 1e-9);
  const double last = automatic ? hard_limit : std::min(options.gain_max, hard_limit);

  double k = options.gain_min;
  double k_first = std::min(first_gain(open_loop, sc), std::isfinite(last) ? last : 1e300);
  double ratio = 1.5;  // next gain = k * ratio once k > 0
  constexpr double kMaxRatio = 10.0;
  constexpr double kMinRatio = 1.0 + 1e-12;
  while (static_cast<int>(rl.gains.size()) < options.max_points) {
    if (k >= last) break;
    if (automatic && k > 0.0 && done(current)) break;
    double next = k == 0.0 ? k_first : k * ratio;
    next = std::min(next, last);
    if (++evaluations > max_evaluations) {
      throw NumericalError("rlocus", "the adaptive gain grid needed more than " + format_number(max_evaluations, 10) +
                           " eigenvalue problems of order " + std::to_string(n) + " (max_work = " + format_number(options.max_work, 10) +
                           "); it reached gain " + format_number(k, 10),
                           /*retry_may_help=*/true);
    }
    const CVector candidate = match_to(current, poles_at(open_loop, next));
    const double move = relative_move(current, candidate, sc.smallest);
    if (move > options.max_relative_step) {
      // Too far: bisect (geometrically once k > 0) unless the step cannot shrink any more, e.g.
      // exactly at a breakaway point where poles move as sqrt(dk).
      if (k == 0.0 && k_first > 1e-300) {
        k_first /= 4.0;
        continue;
      }
      if (k > 0.0 && next > k * kMinRatio) {
        ratio = std::sqrt(std::min(ratio, next / k));
        continue;
      }
    }
    k = next;
    current = candidate;
    rl.gains.push_back(k);
    rl.poles.push_back(current);
    if (move < options.max_relative_step / 4.0) ratio = std::min(ratio * ratio, kMaxRatio);
  }
  return rl;
}

}  // namespace

RootLocus rlocus_auto(const StateSpace& open_loop, const RootLocusOptions& options) {
  check_loop(open_loop, "rlocus_auto");
  return locus_grid(open_loop, options, std::nullopt);
}

BranchOptimum max_damping_on_branch(const StateSpace& open_loop, Complex start_pole,
                                    const RootLocusOptions& options) {
  check_loop(open_loop, "max_damping_on_branch");
  if (!std::isfinite(start_pole.real()) || !std::isfinite(start_pole.imag())) {
    throw InputError("max_damping_on_branch", "start_pole", "a finite complex number", "a non-finite value");
  }
  if (open_loop.states() == 0) {
    throw InputError("max_damping_on_branch", "open_loop", "a loop with at least one pole", "no states");
  }
  RootLocusOptions opts = options;
  opts.gain_min = 0.0;  // the branch is identified by its open-loop pole
  const RootLocus rl = locus_grid(open_loop, opts, start_pole);
  const double ts = open_loop.sample_time;
  const Index branch = branch_of(rl.poles.front(), start_pole);

  size_t best = 0;
  for (size_t i = 1; i < rl.gains.size(); ++i) {
    if (damping_of(rl.poles[i](branch), ts) > damping_of(rl.poles[best](branch), ts)) best = i;
  }
  BranchOptimum out;
  out.gain = rl.gains[best];
  out.pole = rl.poles[best](branch);
  out.damping = damping_of(out.pole, ts);
  if (rl.gains.size() < 2) return out;

  // Tracked evaluations: every gain seen so far with its matched pole set. A new gain is matched
  // against the nearest tracked one, which lies within one grid step (moves of at most
  // max_relative_step), so the branch index keeps its meaning while the search narrows.
  std::map<double, CVector> tracked;
  for (size_t i = 0; i < rl.gains.size(); ++i) tracked.emplace(rl.gains[i], rl.poles[i]);
  auto branch_pole = [&](double gain) -> Complex {
    auto it = tracked.lower_bound(gain);
    if (it != tracked.end() && it->first == gain) return it->second(branch);
    auto nearest = it;
    if (it == tracked.end() || (it != tracked.begin() && gain - std::prev(it)->first < it->first - gain)) {
      nearest = std::prev(it);
    }
    CVector p = match_to(nearest->second, poles_at(open_loop, gain));
    const Complex result = p(branch);
    tracked.emplace(gain, std::move(p));
    return result;
  };

  const double lo = rl.gains[best == 0 ? 0 : best - 1];
  const double hi = rl.gains[std::min(best + 1, rl.gains.size() - 1)];
  // Golden-section search for the maximum of the damping ratio on [lo, hi]; on log(gain) when the
  // bracket is away from 0 (the grid is geometric there), on the gain itself otherwise.
  const bool use_log = lo > 0.0;
  auto to_gain = [&](double t) { return use_log ? std::exp(t) : t; };
  constexpr double kGainTolerance = 1e-6;
  core::GoldenSectionOptions golden;
  golden.tolerance = use_log ? kGainTolerance : kGainTolerance * std::max(hi, std::numeric_limits<double>::min());
  if (hi > lo) {
    const core::ScalarMinimum m = core::golden_section_minimize(
        [&](double t) { return -damping_of(branch_pole(to_gain(t)), ts); }, use_log ? std::log(lo) : lo,
        use_log ? std::log(hi) : hi, golden);
    const double g = to_gain(m.x);
    const Complex p = branch_pole(g);
    const double z = damping_of(p, ts);
    if (z > out.damping) {
      out.gain = g;
      out.pole = p;
      out.damping = z;
    }
  }
  return out;
}

}  // namespace piezobench::lti
