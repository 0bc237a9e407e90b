#include "piezobench/dsp/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <future>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <utility>

#include "fft.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/memory.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::dsp {

using Eigen::Index;

namespace {

const std::string kSource = "excitation";

void require(bool ok, const std::string& field, const std::string& expected, const std::string& found) {
  if (!ok) throw InputError(kSource, field, expected, found);
}

void require_rate(double fs) { require(std::isfinite(fs) && fs > 0.0, "sample_rate", "a finite rate > 0 Hz", format_number(fs, 10)); }

// Uniform in [0, 1) with 53 random bits (the top bits of one mt19937_64 draw).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// One standard normal pair (x, y) by Box-Muller, written out so that the numbers do not depend on
// the standard library's normal_distribution: x + i y is a circular complex Gaussian.
std::complex<double> gaussian_pair(std::mt19937_64& rng) {
  const double u1 = 1.0 - uniform01(rng);  // (0, 1]: log is finite
  const double u2 = uniform01(rng);
  return std::polar(std::sqrt(-2.0 * std::log(u1)), 2.0 * kPi * u2);
}

// Raised-cosine rise from 0 at t = 0 to 1 at t = ramp (1 beyond; 1 everywhere if ramp == 0).
double rise(double t, double ramp) {
  if (ramp <= 0.0 || t >= ramp) return 1.0;
  if (t <= 0.0) return 0.0;
  return 0.5 - 0.5 * std::cos(kPi * t / ramp);
}

// u = c + s v with the policy of `bounds`; fills u, scaled, scale, clipped. `c` may be an
// expression (a constant level costs no vector); v's storage becomes u.
template <typename Level>
void fit_to_bounds(const Eigen::MatrixBase<Level>& c, Eigen::VectorXd&& v, const VoltageBounds& bounds,
                   const std::string& level_field, Excitation& out) {
  bounds.validate();
  for (Index k = 0; k < c.size(); ++k) {
    if (c(k) < bounds.min || c(k) > bounds.max) {
      throw InputError(kSource, level_field, "a level inside [" + format_number(bounds.min, 10) + ", " + format_number(bounds.max, 10) + "] V",
                       format_number(c(k), 10) + " V");
    }
  }
  // Most signals lie inside: one vectorized pass shows it, and then u = c + v needs no clamp.
  const bool inside = c.size() > 0 && (c + v).maxCoeff() <= bounds.max && (c + v).minCoeff() >= bounds.min;
  double s = 1.0;
  for (Index k = 0; k < c.size() && !inside; ++k) {
    if (v(k) > 0.0 && c(k) + v(k) > bounds.max) s = std::min(s, (bounds.max - c(k)) / v(k));
    if (v(k) < 0.0 && c(k) + v(k) < bounds.min) s = std::min(s, (bounds.min - c(k)) / v(k));
  }
  if (s < 1.0 && bounds.policy == BoundsPolicy::kReject) {
    throw InputError(kSource, "amplitude",
                     "a signal inside [" + format_number(bounds.min, 10) + ", " + format_number(bounds.max, 10) + "] V",
                     "one that needs scaling by " + format_number(s, 10));
  }
  if (bounds.policy == BoundsPolicy::kClip) s = 1.0;
  out.scale = s;
  out.scaled = s < 1.0;
  v = c + s * v;  // coefficient-wise: in place is safe
  out.u = std::move(v);
  out.clipped = 0;
  for (Index k = 0; k < out.u.size() && !inside; ++k) {
    // For kScale the clamp only removes round-off of the product above; for kClip it is the policy.
    const double clamped = std::clamp(out.u(k), bounds.min, bounds.max);
    if (clamped != out.u(k)) {
      if (bounds.policy == BoundsPolicy::kClip) ++out.clipped;
      out.u(k) = clamped;
    }
  }
}

Index samples_for(double duration, double fs) { return static_cast<Index>(std::llround(duration * fs)); }

}  // namespace

std::string to_string(BoundsPolicy policy) {
  switch (policy) {
    case BoundsPolicy::kScale: return "scale";
    case BoundsPolicy::kClip: return "clip";
    case BoundsPolicy::kReject: return "reject";
  }
  return "unknown";
}

BoundsPolicy bounds_policy_from_string(const std::string& name) {
  if (name == "scale") return BoundsPolicy::kScale;
  if (name == "clip") return BoundsPolicy::kClip;
  if (name == "reject") return BoundsPolicy::kReject;
  throw InputError("", "bounds policy", "one of scale, clip, reject", "\"" + name + "\"");
}

std::string to_string(MultisinePhases phases) { return phases == MultisinePhases::kSchroeder ? "schroeder" : "random"; }

MultisinePhases multisine_phases_from_string(const std::string& name) {
  if (name == "schroeder") return MultisinePhases::kSchroeder;
  if (name == "random") return MultisinePhases::kRandom;
  throw InputError("", "phases", "one of schroeder, random", "\"" + name + "\"");
}

std::string to_string(SweepType type) { return type == SweepType::kLinear ? "linear" : "log"; }

SweepType sweep_type_from_string(const std::string& name) {
  if (name == "linear") return SweepType::kLinear;
  if (name == "log") return SweepType::kLogarithmic;
  throw InputError("", "sweep", "one of linear, log", "\"" + name + "\"");
}

void VoltageBounds::validate() const {
  if (!(std::isfinite(min) && std::isfinite(max) && min < max)) {
    throw InputError(kSource, "bounds", "finite min < max", "[" + format_number(min, 10) + ", " + format_number(max, 10) + "] V");
  }
}

// ---------------------------------------------------------------------------------------------
// Band-limited noise

void NoiseOptions::validate() const {
  require_rate(sample_rate);
  require(samples >= 2, "samples", ">= 2", std::to_string(samples));
  require(std::isfinite(f_low) && f_low >= 0.0, "f_low", ">= 0 Hz", format_number(f_low, 10));
  require(std::isfinite(f_high) && f_high > f_low && f_high <= 0.5 * sample_rate, "f_high",
          "in (f_low, sample_rate / 2] = (" + format_number(f_low, 10) + ", " + format_number(0.5 * sample_rate, 10) + "] Hz", format_number(f_high, 10));
  require(std::isfinite(rms) && rms > 0.0, "rms", "> 0 V", format_number(rms, 10));
  require(std::isfinite(offset), "offset", "a finite voltage", format_number(offset, 10));
  const double df = sample_rate / static_cast<double>(samples);
  const auto first = static_cast<Index>(std::max(1.0, std::ceil(f_low / df)));
  const auto last = static_cast<Index>(std::floor(f_high / df));
  require(first <= last, "f_high", "a band containing at least one line of spacing " + format_number(df, 10) + " Hz",
          "[" + format_number(f_low, 10) + ", " + format_number(f_high, 10) + "] Hz");
}

Excitation band_limited_noise(const NoiseOptions& options, const VoltageBounds& bounds) {
  options.validate();
  const Index n = options.samples;
  const double df = options.sample_rate / static_cast<double>(n);
  // Lines inside the band (DC excluded, Nyquist allowed), decided in integer bins.
  const auto first = static_cast<Index>(std::max(1.0, std::ceil(options.f_low / df)));
  const auto last = std::min(static_cast<Index>(std::floor(options.f_high / df)), n / 2);

  // The band's DFT lines are drawn directly, as the DFT of white Gaussian noise has them: on each
  // line 0 < k < n/2 independent real and imaginary parts of equal variance (n/2 for unit white
  // noise), on the Nyquist line k = n/2 (n even) a real part of twice that variance; then one
  // inverse transform. The common factor sqrt(n/2) is left out: the rms is set exactly below.
  // The inverse plan is made on another thread while the lines are drawn.
  std::future<void> plan = detail::plan_in_background(n, detail::PlanDirections::kInverse);
  std::mt19937_64 rng(options.seed);
  const Index bins = n / 2 + 1;
  detail::FftwBuffer<std::complex<double>> spectrum(bins, detail::BufferInit::kNone);
  std::fill(spectrum.data(), spectrum.data() + first, std::complex<double>(0.0));
  for (Index k = first; k <= last; ++k) spectrum[k] = gaussian_pair(rng);
  std::fill(spectrum.data() + last + 1, spectrum.data() + bins, std::complex<double>(0.0));
  if (n % 2 == 0 && last == n / 2) spectrum[last] = std::sqrt(2.0) * spectrum[last].real();
  plan.get();
  detail::FftwBuffer<double> samples(n, detail::BufferInit::kNone);
  detail::RealInverseFft(n).execute(spectrum.data(), samples.data());
  // Exactly the requested rms (the mean is zero: no DC line).
  const Eigen::Map<const Eigen::VectorXd> raw(samples.data(), n);
  const double raw_rms = std::sqrt(raw.squaredNorm() / static_cast<double>(n));
  Eigen::VectorXd v(n);
  core::advise_huge_pages(v.data(), static_cast<std::size_t>(n) * sizeof(double));
  v = (raw_rms > 0.0 ? options.rms / raw_rms : 1.0) * raw;

  Excitation out;
  out.sample_rate = options.sample_rate;
  out.kind = "noise";
  out.seed = options.seed;
  out.lines_Hz.resize(2);
  out.lines_Hz << static_cast<double>(first) * df, static_cast<double>(last) * df;
  fit_to_bounds(Eigen::VectorXd::Constant(n, options.offset), std::move(v), bounds, "offset", out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Multisine

void MultisineOptions::validate() const {
  require_rate(sample_rate);
  require(period_samples >= 2, "period_samples", ">= 2", std::to_string(period_samples));
  require(periods >= 1, "periods", ">= 1", std::to_string(periods));
  require(!lines_Hz.empty(), "lines_Hz", "at least one line", "none");
  require(amplitudes.empty() || amplitudes.size() == lines_Hz.size(), "amplitudes",
          "none or one per line (" + std::to_string(lines_Hz.size()) + ")", std::to_string(amplitudes.size()));
  require(std::isfinite(rms) && rms > 0.0, "rms", "> 0 V", format_number(rms, 10));
  require(std::isfinite(offset), "offset", "a finite voltage", format_number(offset, 10));
  const double df = sample_rate / static_cast<double>(period_samples);
  std::vector<Index> bins;
  for (double f : lines_Hz) {
    const double k = f / df;
    const double kr = std::round(k);
    require(std::isfinite(f) && std::abs(k - kr) <= 1e-9 * std::max(1.0, kr) && kr >= 1.0 &&
                2.0 * kr < static_cast<double>(period_samples),
            "lines_Hz", "multiples of sample_rate / period_samples = " + format_number(df, 10) + " Hz below sample_rate / 2",
            format_number(f, 10) + " Hz");
    bins.push_back(static_cast<Index>(kr));
  }
  std::sort(bins.begin(), bins.end());
  require(std::adjacent_find(bins.begin(), bins.end()) == bins.end(), "lines_Hz", "distinct lines",
          "a line given twice");
  double total = 0.0;
  for (double a : amplitudes) {
    require(std::isfinite(a) && a >= 0.0, "amplitudes", "finite values >= 0", format_number(a, 10));
    total += a;
  }
  require(amplitudes.empty() || total > 0.0, "amplitudes", "at least one > 0", "all zero");
}

Eigen::VectorXd multisine_phases(const MultisineOptions& options) {
  options.validate();
  const auto lines = static_cast<Index>(options.lines_Hz.size());
  Eigen::VectorXd phi(lines);
  if (options.phases == MultisinePhases::kRandom) {
    std::mt19937_64 rng(options.seed);
    for (Index k = 0; k < lines; ++k) phi(k) = 2.0 * kPi * uniform01(rng);
    return phi;
  }
  // Schroeder (1970), eq. (11): with relative powers p_l, phi_k = phi_1 - 2 pi sum_{l<k} (k - l) p_l,
  // taken in the order the lines are given (the formula assumes increasing frequency).
  Eigen::VectorXd p(lines);
  for (Index k = 0; k < lines; ++k) {
    const double a = options.amplitudes.empty() ? 1.0 : options.amplitudes[static_cast<std::size_t>(k)];
    p(k) = a * a;
  }
  p /= p.sum();
  for (Index k = 0; k < lines; ++k) {
    double sum = 0.0;
    for (Index l = 0; l < k; ++l) sum += static_cast<double>(k - l) * p(l);
    phi(k) = std::remainder(-2.0 * kPi * sum, 2.0 * kPi);
  }
  return phi;
}

Excitation multisine(const MultisineOptions& options, const VoltageBounds& bounds) {
  const Eigen::VectorXd phi = multisine_phases(options);  // validates
  const Index n = options.period_samples;
  const double df = options.sample_rate / static_cast<double>(n);
  const auto lines = static_cast<Index>(options.lines_Hz.size());

  // One period from its spectrum: line k at bin m has DFT coefficient (N/2) A e^{i phi}.
  Eigen::VectorXcd spectrum = Eigen::VectorXcd::Zero(n / 2 + 1);
  double power = 0.0;
  for (Index k = 0; k < lines; ++k) {
    const double a = options.amplitudes.empty() ? 1.0 : options.amplitudes[static_cast<std::size_t>(k)];
    const auto m = static_cast<Index>(std::round(options.lines_Hz[static_cast<std::size_t>(k)] / df));
    spectrum(m) = std::polar(0.5 * static_cast<double>(n) * a, phi(k));
    power += 0.5 * a * a;
  }
  const Eigen::VectorXd period = detail::irfft(spectrum, n) * (options.rms / std::sqrt(power));
  Eigen::VectorXd v(n * options.periods);  // becomes u
  core::advise_huge_pages(v.data(), static_cast<std::size_t>(v.size()) * sizeof(double));
  for (Index p = 0; p < options.periods; ++p) v.segment(p * n, n) = period;

  Excitation out;
  out.sample_rate = options.sample_rate;
  out.kind = "multisine-" + to_string(options.phases);
  out.seed = options.phases == MultisinePhases::kRandom ? options.seed : 0;
  out.lines_Hz = Eigen::Map<const Eigen::VectorXd>(options.lines_Hz.data(), lines);
  fit_to_bounds(Eigen::VectorXd::Constant(v.size(), options.offset), std::move(v), bounds, "offset", out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Sweeps

void SweepOptions::validate() const {
  require_rate(sample_rate);
  require(std::isfinite(duration) && duration > 0.0 && samples_for(duration, sample_rate) >= 2, "duration",
          "> 0 s and at least 2 samples", format_number(duration, 10) + " s");
  const double nyquist = 0.5 * sample_rate;
  const double lowest = type == SweepType::kLinear ? 0.0 : std::numeric_limits<double>::min();
  require(std::isfinite(f_start) && f_start >= lowest && f_start <= nyquist, "f_start",
          std::string(type == SweepType::kLinear ? "in [0, " : "in (0, ") + format_number(nyquist, 10) + "] Hz", format_number(f_start, 10));
  require(std::isfinite(f_end) && f_end >= lowest && f_end <= nyquist, "f_end",
          std::string(type == SweepType::kLinear ? "in [0, " : "in (0, ") + format_number(nyquist, 10) + "] Hz", format_number(f_end, 10));
  require(type == SweepType::kLinear || f_start != f_end, "f_end", "different from f_start for a log sweep", format_number(f_end, 10));
  require(std::isfinite(amplitude) && amplitude >= 0.0, "amplitude", ">= 0 V", format_number(amplitude, 10));
  require(std::isfinite(offset), "offset", "a finite voltage", format_number(offset, 10));
  require(std::isfinite(ramp_time) && ramp_time >= 0.0 && 2.0 * ramp_time <= duration, "ramp_time",
          "in [0, duration / 2]", format_number(ramp_time, 10) + " s");
}

double sweep_frequency(const SweepOptions& o, double t) {
  if (o.type == SweepType::kLinear) return o.f_start + (o.f_end - o.f_start) * t / o.duration;
  return o.f_start * std::exp(t * std::log(o.f_end / o.f_start) / o.duration);
}

Excitation sine_sweep(const SweepOptions& options, const VoltageBounds& bounds) {
  options.validate();
  const Index n = samples_for(options.duration, options.sample_rate);
  const double T = options.duration;
  const double f0 = options.f_start;
  const double f1 = options.f_end;
  Eigen::VectorXd v(n);  // becomes u
  core::advise_huge_pages(v.data(), static_cast<std::size_t>(n) * sizeof(double));
  for (Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / options.sample_rate;
    double phase = 0.0;
    if (options.type == SweepType::kLinear) {
      phase = 2.0 * kPi * (f0 * t + (f1 - f0) * t * t / (2.0 * T));
    } else {
      const double r = std::log(f1 / f0);
      phase = 2.0 * kPi * f0 * T / r * std::expm1(t * r / T);
    }
    const double envelope = rise(t, options.ramp_time) * rise(T - t, options.ramp_time);
    v(k) = options.amplitude * envelope * std::sin(phase);
  }
  Excitation out;
  out.sample_rate = options.sample_rate;
  out.kind = "sweep-" + to_string(options.type);
  fit_to_bounds(Eigen::VectorXd::Constant(n, options.offset), std::move(v), bounds, "offset", out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Quasi-static offset sine

void OffsetSineOptions::validate() const {
  require_rate(sample_rate);
  require(std::isfinite(rest), "rest", "a finite voltage", format_number(rest, 10));
  require(std::isfinite(offset), "offset", "a finite voltage", format_number(offset, 10));
  require(std::isfinite(amplitude) && amplitude >= 0.0, "amplitude", ">= 0 V", format_number(amplitude, 10));
  require(std::isfinite(frequency) && frequency > 0.0 && frequency < 0.5 * sample_rate, "frequency",
          "in (0, " + format_number(0.5 * sample_rate, 10) + ") Hz", format_number(frequency, 10));
  require(std::isfinite(cycles) && cycles > 0.0, "cycles", "> 0", format_number(cycles, 10));
  require(std::isfinite(ramp_time) && ramp_time >= 0.0, "ramp_time", ">= 0 s", format_number(ramp_time, 10));
}

Excitation offset_sine(const OffsetSineOptions& options, const VoltageBounds& bounds) {
  options.validate();
  const double tr = options.ramp_time;
  const double tc = options.cycles / options.frequency;
  const double total = 2.0 * tr + tc;
  const Index n = samples_for(total, options.sample_rate) + 1;  // includes the final rest sample
  Eigen::VectorXd c(n);
  Eigen::VectorXd v(n);
  for (Index k = 0; k < n; ++k) {
    const double t = std::min(static_cast<double>(k) / options.sample_rate, total);
    const double e = rise(t, tr) * rise(total - t, tr);
    c(k) = options.rest + e * (options.offset - options.rest);
    v(k) = e * options.amplitude * std::sin(2.0 * kPi * options.frequency * (t - tr));
  }
  // The offset itself must be reachable: c passes through it when the ramp is done.
  bounds.validate();
  if (options.offset < bounds.min || options.offset > bounds.max) {
    throw InputError(kSource, "offset", "a level inside [" + format_number(bounds.min, 10) + ", " + format_number(bounds.max, 10) + "] V",
                     format_number(options.offset, 10) + " V");
  }
  Excitation out;
  out.sample_rate = options.sample_rate;
  out.kind = "offset-sine";
  out.lines_Hz = Eigen::VectorXd::Constant(1, options.frequency);
  fit_to_bounds(c, std::move(v), bounds, "rest", out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Steps with ramps

void StepOptions::validate() const {
  require_rate(sample_rate);
  require(std::isfinite(rest), "rest", "a finite voltage", format_number(rest, 10));
  require(!levels.empty(), "levels", "at least one level", "none");
  for (double l : levels) require(std::isfinite(l), "levels", "finite voltages", format_number(l, 10));
  require(std::isfinite(hold_time) && hold_time > 0.0, "hold_time", "> 0 s", format_number(hold_time, 10));
  require(std::isfinite(ramp_time) && ramp_time >= 0.0, "ramp_time", ">= 0 s", format_number(ramp_time, 10));
}

Excitation steps(const StepOptions& options, const VoltageBounds& bounds) {
  options.validate();
  // Breakpoints (sample index, value) of a piecewise-linear staircase; times rounded to samples
  // so every hold has exactly the same length.
  const Index hold = std::max<Index>(1, samples_for(options.hold_time, options.sample_rate));
  const Index ramp = samples_for(options.ramp_time, options.sample_rate);
  std::vector<double> targets = options.levels;
  targets.push_back(options.rest);
  const auto pieces = static_cast<Index>(targets.size());
  const Index n = hold + pieces * (ramp + hold);
  Eigen::VectorXd stair(n);
  Index k = 0;
  double level = options.rest;
  for (Index i = 0; i < hold; ++i) stair(k++) = level;
  for (double target : targets) {
    // Linear ramp: samples 1..ramp of the segment from `level` to `target` (the last one is target).
    for (Index i = 1; i <= ramp; ++i) {
      stair(k++) = level + (target - level) * static_cast<double>(i) / static_cast<double>(ramp);
    }
    for (Index i = 0; i < hold; ++i) stair(k++) = target;
    level = target;
  }
  Excitation out;
  out.sample_rate = options.sample_rate;
  out.kind = "steps";
  const auto c = Eigen::VectorXd::Constant(n, options.rest);
  fit_to_bounds(c, stair - c, bounds, "rest", out);
  return out;
}

}  // namespace piezobench::dsp
