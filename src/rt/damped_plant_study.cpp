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

namespace {

// The model side of the study: the bench's linear u -> Vs with the continuous K0, its Pade form
// with the delay, and the root locus at the study's gains.
struct StudyModel {
  lti::StateSpace plant_vs, bench_model, controller;
  control::IffRootLocus locus;
};

StudyModel study_model(const DampedPlantStudyOptions& options, const bench::UnitTruth& unit, DampedPlantStudy& study) {
  StudyModel m;
  {
    const bench::VirtualBench reference(unit, options.bench, options.seed);
    const lti::StateSpace model = reference.linear_model();
    m.plant_vs = lti::select(model, {1}, {0});
    m.bench_model = lti::pade(model, options.pade_order);
    study.delay = reference.effective_delay();
    study.model = reference.model_name();
  }
  m.controller = lti::to_state_space(control::iff_controller(options.controller));
  control::IffLoopOptions loop_options;
  loop_options.pade_order = options.pade_order;
  // The optimum is looked for up to a bound (the automatic one follows every branch to its end,
  // several times the cost): 4 times the largest gain asked for, at least 1e6 (the report's optimum
  // is 2.8e5).
  const double gain_bound = std::max(1e6, 4.0 * *std::max_element(options.gains.begin(), options.gains.end()));
  loop_options.locus.gain_max = gain_bound;
  m.locus = control::iff_root_locus(m.plant_vs, m.controller, options.gains, loop_options);
  study.open_loop_pole = m.locus.resonance_pole;
  study.optimal_gain = m.locus.optimum.gain;
  if (!(m.locus.optimum.gain < gain_bound * (1.0 - 1e-6))) {
    throw NumericalError("damped-plant study", "the damping of the resonance branch still grows at the search bound g = " +
                         format_number(gain_bound) + "; no optimum below it", false);
  }
  study.max_damping = m.locus.optimum.damping;
  return m;
}

// The excitation and the samples of each run: settle, the analysed periods, the ramp out.
struct StudyExcitation {
  Eigen::Index first = 0, analysed = 0, ramp_out = 0;  // samples
  dsp::Excitation excitation;
};

// Band-limited noise, either one period of nfft samples played cyclically (periodic) or one
// record as long as the run (the default: random from segment to segment).
StudyExcitation study_excitation(const DampedPlantStudyOptions& options) {
  const double fs = options.bench.sample_rate;
  const long periods = static_cast<long>(std::floor(options.duration * fs / static_cast<double>(options.nfft)));
  const long settle_periods = static_cast<long>(std::ceil(options.settle * fs / static_cast<double>(options.nfft)));
  StudyExcitation e;
  e.analysed = periods * options.nfft;
  e.first = settle_periods * options.nfft;
  e.ramp_out = static_cast<Eigen::Index>(std::ceil(options.limits.ramp_out * fs));
  dsp::NoiseOptions noise;
  noise.sample_rate = fs;
  noise.samples = options.periodic ? options.nfft : e.first + e.analysed + e.ramp_out;
  noise.f_low = options.f_low;
  noise.f_high = options.f_high;
  noise.rms = options.excitation_rms;
  noise.seed = options.seed;
  dsp::VoltageBounds bounds;
  bounds.min = options.limits.u_min();
  bounds.max = options.limits.u_max();
  e.excitation = dsp::band_limited_noise(noise, bounds);
  return e;
}

// The loop closed at gain g on a virtual bench (seed + i), in lockstep; the FRF u' -> d_e of the
// analysed periods.
dsp::FrfEstimate run_at_gain(const DampedPlantStudyOptions& options, const bench::UnitTruth& unit, std::size_t i,
                             const StudyExcitation& e, LoopReport& report) {
  const double fs = options.bench.sample_rate;
  VirtualBenchBackend backend(unit, options.bench, options.seed + i);
  LoopOptions lo;
  lo.realtime = false;
  lo.gain = options.gains[i];
  lo.controller = true;
  lo.controller_params = options.controller;
  lo.discrete = options.discrete;
  lo.limits = options.limits;
  lo.excitation = e.excitation.u;
  lo.keep_log = true;
  // Settle, the analysed periods, the ramp out.
  lo.duration = static_cast<double>(e.first + e.analysed + e.ramp_out) / fs;
  Loop loop(backend, lo);
  loop.start();
  while (loop.cycle()) {
  }
  report = loop.finish();
  const io::TimeSeries& log = loop.log();

  // Row k of the log: u'[k] and the instruments read at t = k Ts, before u[k] is applied (the
  // convention of the bench's own records, for which linear_model()'s delay holds).
  const Eigen::VectorXd u = log.channel("u_prime").segment(e.first, e.analysed);
  const Eigen::VectorXd de = log.channel("de").segment(e.first, e.analysed);
  dsp::WelchOptions welch;
  welch.window = options.periodic ? dsp::WindowType::kRectangular : dsp::WindowType::kHannPeriodic;
  welch.nfft = options.nfft;
  welch.overlap = options.periodic ? 0.0 : 0.5;
  welch.detrend = dsp::Detrend::kLinear;
  welch.threads = 1;
  return dsp::estimate_frf(dsp::channel("u_prime", u), {dsp::channel("de", de)}, fs, welch, kSource);
}

// The lines of a band (excited ones only), rad/s, and the FRF there with the delay removed (h)
// and as measured (raw).
struct BandLines {
  lti::Vector omega;
  lti::CVector h, raw;
};

bool in_study_band(double f, double fmin, double fmax, const DampedPlantStudyOptions& options) {
  return f >= fmin && f <= fmax && f >= options.f_low && f <= options.f_high;
}

BandLines band_lines(const dsp::FrfEstimate& est, double fmin, double fmax, const DampedPlantStudyOptions& options, double delay) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < est.frf.freq_Hz.size(); ++k) {
    if (in_study_band(est.frf.freq_Hz(k), fmin, fmax, options)) rows.push_back(k);
  }
  if (rows.size() < 8) {
    throw InputError(kSource, "fit band", "at least 8 excited frequency lines in [" + format_number(fmin) + ", " +
                                              format_number(fmax) + "] Hz",
                     std::to_string(rows.size()) + " lines");
  }
  BandLines b;
  b.omega.resize(static_cast<Eigen::Index>(rows.size()));
  b.h.resize(b.omega.size());
  b.raw.resize(b.omega.size());
  for (Eigen::Index j = 0; j < b.omega.size(); ++j) {
    const Eigen::Index k = rows[static_cast<std::size_t>(j)];
    b.omega(j) = kTwoPi * est.frf.freq_Hz(k);
    b.raw(j) = est.frf.H[0](k);
    b.h(j) = b.raw(j) * (options.remove_delay ? std::polar(1.0, b.omega(j) * delay) : lti::Complex(1.0));
  }
  return b;
}

// The model's pole at the point's gain (upper half plane).
void set_model_pole(DampedPlantPoint& p, const control::IffRootLocus& locus, std::size_t i) {
  p.model_pole = locus.locus.poles[i](locus.resonance_branch);
  if (p.model_pole.imag() < 0.0) p.model_pole = std::conj(p.model_pole);
  const lti::PoleInfo info = lti::pole_info(p.model_pole);
  p.model_frequency_Hz = info.natural_frequency / kTwoPi;
  p.model_damping = info.damping;
}

// Identified pole: vector fit, then the dominant complex pair in the resonance band; the mean
// coherence over the fit band.
void identify_pole(DampedPlantPoint& p, const BandLines& fit, const dsp::FrfEstimate& est, const DampedPlantStudyOptions& options) {
  ident::DominantPoleOptions dpo;
  dpo.fit.order = options.fit_order;
  dpo.omega_min = kTwoPi * options.resonance_fmin;
  dpo.omega_max = kTwoPi * options.resonance_fmax;
  const ident::DominantPole dominant = ident::dominant_pole(fit.omega, fit.h, dpo);
  p.identified_pole = dominant.pole;
  const ident::VectorFittingResult& vf = dominant.fit;
  const lti::PoleInfo id = lti::pole_info(p.identified_pole);
  p.identified_frequency_Hz = id.natural_frequency / kTwoPi;
  p.identified_damping = id.damping;
  p.fit_relative_rms_error = vf.relative_rms_error;
  p.relative_error = std::abs(p.identified_pole - p.model_pole) / std::abs(p.model_pole);
  double coherence = 0.0;
  for (Eigen::Index k = 0; k < est.frf.freq_Hz.size(); ++k) {
    if (in_study_band(est.frf.freq_Hz(k), options.fit_fmin, options.fit_fmax, options)) {
      coherence += est.frf.coherence[0](k) / static_cast<double>(fit.omega.size());
    }
  }
  p.mean_coherence = coherence;
}

// The report's second-order fit of the damped plant.
void fit_report_second_order(DampedPlantPoint& p, const BandLines& band) {
  ident::SecondOrderFitOptions so;
  so.method = ident::SecondOrderMethod::kVectorFitting;
  const ident::SecondOrderFit fit = ident::fit_second_order(band.omega, band.h, so);
  p.second_order_pole = fit.poles(0).imag() >= 0.0 ? fit.poles(0) : fit.poles(1);
  p.second_order_frequency_Hz = fit.frequency_Hz();
  p.second_order_damping = fit.damping;
  p.second_order_rms_error = fit.relative_rms_error;
  p.second_order_relative_error = std::abs(p.second_order_pole - p.model_pole) / std::abs(p.model_pole);
}

// One gain: the measured damped plant against the model's.
DampedPlantPoint study_point(const DampedPlantStudyOptions& options, const bench::UnitTruth& unit, std::size_t i,
                             const StudyExcitation& e, const StudyModel& m, double delay) {
  const double g = options.gains[i];
  LoopReport report;
  const dsp::FrfEstimate est = run_at_gain(options, unit, i, e, report);
  DampedPlantPoint p;
  p.gain = g;
  set_model_pole(p, m.locus, i);
  const BandLines fit = band_lines(est, options.fit_fmin, options.fit_fmax, options, delay);
  identify_pole(p, fit, est, options);
  // The measured FRF against the model's damped plant (delay included in both).
  {
    const lti::StateSpace k_g = lti::scale(m.controller, g);
    const lti::StateSpace closed = lti::feedback(m.bench_model, k_g, {0}, {1}, lti::FeedbackSign::kPositive);
    const lti::CVector hm = lti::freqresp(lti::select(closed, {0}, {0}), fit.omega).channel(0, 0);
    p.frf_model_relative_rms = (fit.raw - hm).norm() / hm.norm();
  }
  fit_report_second_order(p, band_lines(est, options.second_order_fmin, options.second_order_fmax, options, delay));
  p.clamped_samples = report.clamped_samples;
  p.slew_limited_samples = report.slew_limited_samples;
  p.safe_state_events = report.safe_state_events;
  return p;
}

// The largest pole error against the tolerance, and whether the damping rises with the gain up
// to the optimum (the gains up to the optimum, sorted by gain).
void summarize_study(DampedPlantStudy& study, double tolerance) {
  study.max_relative_error = 0.0;
  for (const auto& p : study.points) study.max_relative_error = std::max(study.max_relative_error, p.relative_error);
  study.within_tolerance = study.max_relative_error <= tolerance;
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
}

}  // namespace

DampedPlantStudy run_damped_plant_study(const DampedPlantStudyOptions& options) {
  options.validate();
  const bench::UnitTruth unit = bench::batch_unit(options.unit, options.seed);
  DampedPlantStudy study;
  const StudyModel model = study_model(options, unit, study);
  const StudyExcitation excitation = study_excitation(options);
  for (std::size_t i = 0; i < options.gains.size(); ++i) {
    study.points.push_back(study_point(options, unit, i, excitation, model, study.delay));
  }
  summarize_study(study, options.tolerance);
  return study;
}

}  // namespace piezobench::rt
