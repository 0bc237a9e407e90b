#include "piezobench/rt/damped_plant_study.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "piezobench/control/iff.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/excitation.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/virtual_backend.hpp"
#include "util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::rt {
namespace {

const std::string kSource = "damped-plant study";

}  // namespace

void DampedPlantStudyOptions::validate() const {
  if (gains.empty()) throw InputError(kSource, "gains", "at least one gain", "an empty list");
  for (double g : gains) {
    if (!(std::isfinite(g) && g >= 0.0)) throw InputError(kSource, "gains", "finite gains >= 0", format_number(g));
  }
  detail::require_positive(duration, "duration", kSource);
  detail::require_nonnegative(settle, "settle", kSource);
  detail::require_positive(excitation_rms, "excitation_rms", kSource);
  detail::require_nonnegative(f_low, "f_low", kSource);
  const double nyquist = bench.sample_rate / 2.0;
  if (!(std::isfinite(f_high) && f_high > f_low && f_high <= nyquist)) {
    throw InputError(kSource, "f_high", "a frequency in (f_low, " + format_number(nyquist) + "] Hz", format_number(f_high));
  }
  auto band = [](double lo, double hi, const char* lo_field, const char* hi_field) {
    detail::require_positive(lo, lo_field, kSource);
    if (!(std::isfinite(hi) && hi > lo)) {
      throw InputError(kSource, hi_field, std::string("a frequency above ") + lo_field + " = " + format_number(lo) + " Hz",
                       format_number(hi));
    }
  };
  band(fit_fmin, fit_fmax, "fit_fmin", "fit_fmax");
  band(resonance_fmin, resonance_fmax, "resonance_fmin", "resonance_fmax");
  band(second_order_fmin, second_order_fmax, "second_order_fmin", "second_order_fmax");
  if (fit_order < 2 || fit_order > 40) throw InputError(kSource, "fit_order", "an integer in 2..40", std::to_string(fit_order));
  if (nfft < 16) throw InputError(kSource, "nfft", "at least 16 samples", std::to_string(nfft));
  if (duration * bench.sample_rate < static_cast<double>(nfft)) {
    throw InputError(kSource, "duration", "at least one period of nfft = " + std::to_string(nfft) + " samples",
                     format_number(duration) + " s");
  }
  detail::require_positive(tolerance, "tolerance", kSource);
  if (pade_order < 1 || pade_order > 20) throw InputError(kSource, "pade_order", "1..20", std::to_string(pade_order));
  bench.validate();
  limits.validate();
}

DampedPlantStudy run_damped_plant_study(const DampedPlantStudyOptions& options) {
  options.validate();
  const bench::UnitTruth unit = bench::batch_unit(options.unit, options.seed);
  const double fs = options.bench.sample_rate;

  // The model's root locus at the same gains: the bench's linear u -> Vs with the continuous K0.
  DampedPlantStudy study;
  lti::StateSpace plant_vs, bench_model;
  {
    const bench::VirtualBench reference(unit, options.bench, options.seed);
    const lti::StateSpace model = reference.linear_model();
    plant_vs = lti::select(model, {1}, {0});
    bench_model = lti::pade(model, options.pade_order);
    study.delay = reference.effective_delay();
    study.model = reference.model_name();
  }
  const lti::StateSpace controller = lti::to_state_space(control::iff_controller(options.controller));
  control::IffLoopOptions loop_options;
  loop_options.pade_order = options.pade_order;
  // The optimum is looked for up to a bound (the automatic one follows every branch to its end,
  // several times the cost): 4 times the largest gain asked for, at least 1e6 (the report's optimum
  // is 2.8e5).
  const double gain_bound = std::max(1e6, 4.0 * *std::max_element(options.gains.begin(), options.gains.end()));
  loop_options.locus.gain_max = gain_bound;
  const control::IffRootLocus locus = control::iff_root_locus(plant_vs, controller, options.gains, loop_options);
  study.open_loop_pole = locus.resonance_pole;
  study.optimal_gain = locus.optimum.gain;
  if (!(locus.optimum.gain < gain_bound * (1.0 - 1e-6))) {
    throw NumericalError("damped-plant study", "the damping of the resonance branch still grows at the search bound g = " +
                         format_number(gain_bound) + "; no optimum below it", false);
  }
  study.max_damping = locus.optimum.damping;

  // The excitation: band-limited noise, either one period of nfft samples played cyclically
  // (periodic) or one record as long as the run (the default: random from segment to segment).
  const long periods = static_cast<long>(std::floor(options.duration * fs / static_cast<double>(options.nfft)));
  const long settle_periods = static_cast<long>(std::ceil(options.settle * fs / static_cast<double>(options.nfft)));
  const Eigen::Index analysed = periods * options.nfft;
  const Eigen::Index first = settle_periods * options.nfft;
  const Eigen::Index ramp_out = static_cast<Eigen::Index>(std::ceil(options.limits.ramp_out * fs));
  dsp::NoiseOptions noise;
  noise.sample_rate = fs;
  noise.samples = options.periodic ? options.nfft : first + analysed + ramp_out;
  noise.f_low = options.f_low;
  noise.f_high = options.f_high;
  noise.rms = options.excitation_rms;
  noise.seed = options.seed;
  dsp::VoltageBounds bounds;
  bounds.min = options.limits.u_min();
  bounds.max = options.limits.u_max();
  const dsp::Excitation excitation = dsp::band_limited_noise(noise, bounds);

  for (std::size_t i = 0; i < options.gains.size(); ++i) {
    const double g = options.gains[i];
    VirtualBenchBackend backend(unit, options.bench, options.seed + i);
    LoopOptions lo;
    lo.realtime = false;
    lo.gain = g;
    lo.controller = true;
    lo.controller_params = options.controller;
    lo.discrete = options.discrete;
    lo.limits = options.limits;
    lo.excitation = excitation.u;
    lo.keep_log = true;
    // Settle, the analysed periods, the ramp out.
    lo.duration = static_cast<double>(first + analysed + ramp_out) / fs;
    Loop loop(backend, lo);
    loop.start();
    while (loop.cycle()) {
    }
    const LoopReport report = loop.finish();
    const io::TimeSeries& log = loop.log();

    // Row k of the log: u'[k] and the instruments read at t = k Ts, before u[k] is applied (the
    // convention of the bench's own records, for which linear_model()'s delay holds).
    const Eigen::VectorXd u = log.channel("u_prime").segment(first, analysed);
    const Eigen::VectorXd de = log.channel("de").segment(first, analysed);
    dsp::WelchOptions welch;
    welch.window = options.periodic ? dsp::WindowType::kRectangular : dsp::WindowType::kHannPeriodic;
    welch.nfft = options.nfft;
    welch.overlap = options.periodic ? 0.0 : 0.5;
    welch.detrend = dsp::Detrend::kLinear;
    welch.threads = 1;
    const dsp::FrfEstimate est =
        dsp::estimate_frf(dsp::channel("u_prime", u), {dsp::channel("de", de)}, fs, welch, kSource);

    // The lines of a band (excited ones only), rad/s, and the FRF there with the delay removed.
    auto lines = [&](double fmin, double fmax, lti::Vector& omega, lti::CVector& h, lti::CVector& raw) {
      std::vector<Eigen::Index> rows;
      for (Eigen::Index k = 0; k < est.frf.freq_Hz.size(); ++k) {
        const double f = est.frf.freq_Hz(k);
        if (f >= fmin && f <= fmax && f >= options.f_low && f <= options.f_high) rows.push_back(k);
      }
      if (rows.size() < 8) {
        throw InputError(kSource, "fit band", "at least 8 excited frequency lines in [" + format_number(fmin) + ", " +
                                                  format_number(fmax) + "] Hz",
                         std::to_string(rows.size()) + " lines");
      }
      omega.resize(static_cast<Eigen::Index>(rows.size()));
      h.resize(omega.size());
      raw.resize(omega.size());
      for (Eigen::Index j = 0; j < omega.size(); ++j) {
        const Eigen::Index k = rows[static_cast<std::size_t>(j)];
        omega(j) = kTwoPi * est.frf.freq_Hz(k);
        raw(j) = est.frf.H[0](k);
        h(j) = raw(j) * (options.remove_delay ? std::polar(1.0, omega(j) * study.delay) : lti::Complex(1.0));
      }
    };

    DampedPlantPoint p;
    p.gain = g;
    p.model_pole = locus.locus.poles[i](locus.resonance_branch);
    if (p.model_pole.imag() < 0.0) p.model_pole = std::conj(p.model_pole);
    const lti::PoleInfo info = lti::pole_info(p.model_pole);
    p.model_frequency_Hz = info.natural_frequency / kTwoPi;
    p.model_damping = info.damping;

    // Identified pole: vector fit, then the dominant complex pair in the resonance band.
    lti::Vector omega;
    lti::CVector h, raw;
    lines(options.fit_fmin, options.fit_fmax, omega, h, raw);
    ident::DominantPoleOptions dpo;
    dpo.fit.order = options.fit_order;
    dpo.omega_min = kTwoPi * options.resonance_fmin;
    dpo.omega_max = kTwoPi * options.resonance_fmax;
    const ident::DominantPole dominant = ident::dominant_pole(omega, h, dpo);
    p.identified_pole = dominant.pole;
    const ident::VectorFittingResult& vf = dominant.fit;
    const lti::PoleInfo id = lti::pole_info(p.identified_pole);
    p.identified_frequency_Hz = id.natural_frequency / kTwoPi;
    p.identified_damping = id.damping;
    p.fit_relative_rms_error = vf.relative_rms_error;
    p.relative_error = std::abs(p.identified_pole - p.model_pole) / std::abs(p.model_pole);
    double coherence = 0.0;
    for (Eigen::Index k = 0; k < est.frf.freq_Hz.size(); ++k) {
      const double f = est.frf.freq_Hz(k);
      if (f >= options.fit_fmin && f <= options.fit_fmax && f >= options.f_low && f <= options.f_high) {
        coherence += est.frf.coherence[0](k) / static_cast<double>(omega.size());
      }
    }
    p.mean_coherence = coherence;

    // The measured FRF against the model's damped plant (delay included in both).
    {
      const lti::StateSpace k_g = lti::scale(controller, g);
      const lti::StateSpace closed = lti::feedback(bench_model, k_g, {0}, {1}, lti::FeedbackSign::kPositive);
      const lti::CVector hm = lti::freqresp(lti::select(closed, {0}, {0}), omega).channel(0, 0);
      p.frf_model_relative_rms = (raw - hm).norm() / hm.norm();
    }

    // The report's second-order fit.
    lti::Vector omega2;
    lti::CVector h2, raw2;
    lines(options.second_order_fmin, options.second_order_fmax, omega2, h2, raw2);
    ident::SecondOrderFitOptions so;
    so.method = ident::SecondOrderMethod::kVectorFitting;
    const ident::SecondOrderFit fit = ident::fit_second_order(omega2, h2, so);
    p.second_order_pole = fit.poles(0).imag() >= 0.0 ? fit.poles(0) : fit.poles(1);
    p.second_order_frequency_Hz = fit.frequency_Hz();
    p.second_order_damping = fit.damping;
    p.second_order_rms_error = fit.relative_rms_error;
    p.second_order_relative_error = std::abs(p.second_order_pole - p.model_pole) / std::abs(p.model_pole);

    p.clamped_samples = report.clamped_samples;
    p.slew_limited_samples = report.slew_limited_samples;
    p.safe_state_events = report.safe_state_events;
    study.points.push_back(p);
  }

  study.max_relative_error = 0.0;
  for (const auto& p : study.points) study.max_relative_error = std::max(study.max_relative_error, p.relative_error);
  study.within_tolerance = study.max_relative_error <= options.tolerance;
  // Damping against gain, for the gains up to the optimum, sorted by gain.
  std::vector<const DampedPlantPoint*> rising;
  for (const auto& p : study.points) {
    if (p.gain <= study.optimal_gain) rising.push_back(&p);
  }
  std::sort(rising.begin(), rising.end(), [](const auto* a, const auto* b) { return a->gain < b->gain; });
  study.damping_increases_to_optimum = rising.size() >= 2;
  for (std::size_t k = 1; k < rising.size(); ++k) {
    if (rising[k]->gain > rising[k - 1]->gain && !(rising[k]->identified_damping > rising[k - 1]->identified_damping)) {
      study.damping_increases_to_optimum = false;
    }
  }
  return study;
}

}  // namespace piezobench::rt
