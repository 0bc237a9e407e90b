#include "piezobench/campaign/twin.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "piezobench/lti/rlocus.hpp"
#include "piezobench/metrology/stroke.hpp"

namespace piezobench::campaign {

namespace {

using Eigen::Index;
using Eigen::VectorXd;

constexpr std::uint64_t kTwinSeed = 1;
// The creep states of the hysteresis fit: the bench's (bench/nonlinear.hpp, Creep).
const std::vector<double> kCreepTimeConstants = {5.0, 50.0, 500.0};
// Trial creep coefficients of the calibrations (per decade): the figure is linear in them.
constexpr double kTrialLoadCreep = 0.3;
constexpr double kTrialVoltageCreep = 0.02;

double db(std::complex<double> ratio) { return 20.0 * std::log10(std::abs(ratio)); }

// --------------------------------------------------------------------------- the FRF refinement

// The measured points the model is refined on: per output, the indices in the band with enough
// coherence.
struct FrfPoints {
  VectorXd freq_Hz;
  std::vector<std::vector<Index>> used;  // [output de, Vs] -> indices into freq_Hz
  std::vector<Eigen::VectorXcd> data;    // measured H at those points
};

FrfPoints frf_points(const dsp::Frf& frf, const TwinOptions& o) {
  FrfPoints p;
  p.freq_Hz = frf.freq_Hz;
  for (const char* name : {"de", "Vs"}) {
    const Index out = frf.output_index(name);
    std::vector<Index> idx;
    for (Index k = 0; k < frf.freq_Hz.size(); ++k) {
      const double f = frf.freq_Hz(k);
      const bool coherent = frf.coherence.empty() || frf.coherence[static_cast<std::size_t>(out)](k) >= o.min_coherence;
      if (f >= o.fmin_Hz && f <= o.fmax_Hz && coherent) idx.push_back(k);
    }
    Eigen::VectorXcd h(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) h(static_cast<Index>(i)) = frf.H[static_cast<std::size_t>(out)](idx[i]);
    p.used.push_back(std::move(idx));
    p.data.push_back(std::move(h));
  }
  return p;
}

TwinFrfError frf_error(const dsp::Frf& model, const FrfPoints& p, std::size_t output) {
  TwinFrfError e;
  std::vector<double> errors;
  for (std::size_t i = 0; i < p.used[output].size(); ++i) {
    errors.push_back(std::abs(db(model.H[output](p.used[output][i]) / p.data[output](static_cast<Index>(i)))));
  }
  e.points = static_cast<long>(errors.size());
  if (errors.empty()) return e;
  e.max_dB = *std::max_element(errors.begin(), errors.end());
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
  e.median_dB = errors[errors.size() / 2];
  return e;
}

// The refined parameters: logarithms of k1, ka (ke = ratio ka, the tuning's), |ga|, |gs| and of
// one scale of the three dampers (their split, which the FRFs hardly see, stays the tuning's), the
// delay in 100 us and the ground resistance in Ohm (its magnitude).
struct Refinement {
  double ke_ratio = 2.0;
  double ga_sign = -1.0, gs_sign = 1.0;
  apa::TwoDofParams tuned;
  [[nodiscard]] VectorXd pack(const bench::Twin& t) const {
    const apa::TwoDofParams& p = t.unit.model;
    VectorXd x(7);
    x << std::log(p.k1), std::log(p.ka), 0.0, std::log(std::abs(p.ga)), std::log(std::abs(p.gs)), t.options.delay / 1e-4,
        t.options.ground_resistance;
    return x;
  }
  void unpack(const VectorXd& x, bench::Twin& t) const {
    apa::TwoDofParams& p = t.unit.model;
    p.k1 = std::exp(x(0));
    p.ka = std::exp(x(1));
    p.ke = ke_ratio * p.ka;
    const double damping = std::exp(x(2));
    p.c1 = damping * tuned.c1;
    p.ca = damping * tuned.ca;
    p.ce = damping * tuned.ce;
    p.ga = ga_sign * std::exp(x(3));
    p.gs = gs_sign * std::exp(x(4));
    t.options.delay = std::max(0.0, x(5) * 1e-4);
    t.options.ground_resistance = std::abs(x(6));
  }
};

void refine_model(bench::Twin& twin, const FrfPoints& p) {
  Refinement r;
  r.ke_ratio = twin.unit.model.ke / twin.unit.model.ka;
  r.ga_sign = twin.unit.model.ga < 0.0 ? -1.0 : 1.0;
  r.gs_sign = twin.unit.model.gs < 0.0 ? -1.0 : 1.0;
  r.tuned = twin.unit.model;
  const Index n_de = static_cast<Index>(p.used[0].size()), n_vs = static_cast<Index>(p.used[1].size());
  const double w_de = 1.0 / std::sqrt(std::max<Index>(n_de, 1)), w_vs = 1.0 / std::sqrt(std::max<Index>(n_vs, 1));
  const auto residual = [&](const VectorXd& x) {
    bench::Twin t = twin;
    r.unpack(x, t);
    VectorXd res(2 * (n_de + n_vs));
    try {
      const dsp::Frf m = bench_frf(t.unit, t.options, p.freq_Hz);
      Index row = 0;
      for (std::size_t o = 0; o < 2; ++o) {
        const double w = o == 0 ? w_de : w_vs;
        for (std::size_t i = 0; i < p.used[o].size(); ++i) {
          const std::complex<double> e = m.H[o](p.used[o][i]) / p.data[o](static_cast<Index>(i)) - 1.0;
          res(row++) = w * e.real();
          res(row++) = w * e.imag();
        }
      }
    } catch (const Error&) {
      res.setConstant(std::numeric_limits<double>::quiet_NaN());  // an invalid trial step: rejected
    }
    return res;
  };
  core::LmOptions lm;
  lm.max_iterations = 60;
  lm.cost_tolerance = 1e-10;
  const core::LmResult result = core::levenberg_marquardt(residual, r.pack(twin), lm);
  if (result.cost < result.initial_cost) r.unpack(result.x, twin);
}

// --------------------------------------------------------------------------- hysteresis and creep

ident::HysteresisFitOptions twin_hysteresis_options(double amplitude) {
  ident::HysteresisFitOptions o;
  for (std::size_t i = 1; i <= bench::kMaxPlayOperators; ++i) {
    o.thresholds.push_back(amplitude * static_cast<double>(i) / static_cast<double>(bench::kMaxPlayOperators));
  }
  o.creep_time_constants = kCreepTimeConstants;
  return o;
}

double creep_sum(const ident::HysteresisFit& f) {
  double s = 0.0;
  for (const double c : f.model.creep_coefficients) s += c;
  return s;
}

ident::HysteresisFit fit_record(const VectorXd& va, const VectorXd& de, double fs, const ident::HysteresisFitOptions& o) {
  return ident::fit_hysteresis({va.data(), static_cast<std::size_t>(va.size())}, {de.data(), static_cast<std::size_t>(de.size())}, fs, o);
}

io::TimeSeries simulate_twin(const bench::Twin& t, bench::Experiment e, std::optional<double> amplitude) {
  bench::ExperimentOptions eo;
  eo.bench = t.options;
  eo.amplitude = amplitude;
  return bench::simulate(e, t.unit, eo, kTwinSeed);
}

VectorXd column(const io::TimeSeries& ts, const std::string& name) {
  const auto it = std::find(ts.names.begin(), ts.names.end(), name);
  if (it == ts.names.end()) throw InputError(ts.source.empty() ? "record" : ts.source, name, "a channel " + name, "none");
  return ts.data.col(it - ts.names.begin());
}

// The x in [0, hi] at which a figure linear in x, f(0) = f0 and f(trial) = f1, takes `target`.
double linear_calibration(double target, double f0, double f1, double trial, double hi) {
  if (!(std::abs(f1 - f0) > 0.0)) return 0.0;
  return std::clamp(trial * (target - f0) / (f1 - f0), 0.0, hi);
}

// The play operators and the voltage creep from the hysteresis records, by indirect inference:
// the twin's own record of each experiment, fitted the same way (ident::fit_hysteresis, 8
// operators on the grid of the largest amplitude, creep states), must give the weights and the
// creep the unit's record gives. A fit of a bench record is biased (the load creep and the dynamics
// also open the loop), so the twin's parameters are corrected by the difference until the fits
// agree: a weight by the mean difference over the records whose amplitude turns its operator (the
// 20 V record fixes the 10 V operator better than the 80 V one does), the voltage creep through
// its slope from a trial run.
struct HysteresisTarget {
  double amplitude = 0.0;
  ident::HysteresisFit fit;
};

void identify_hysteresis(const Campaign& c, const UnitSpec& u, const UnitAnalysis& a, bench::Twin& twin, TwinBuild& out) {
  if (!a.hysteresis_model) {
    out.notes.push_back("no hysteresis record: the twin has no hysteresis (no play operators) and no voltage creep");
    twin.unit.hysteresis_scale = 0.0;
    return;
  }
  const ident::HysteresisFitOptions o = twin_hysteresis_options(a.hysteresis_model->amplitude);
  std::vector<HysteresisTarget> targets;
  for (std::size_t j = 0; j < u.hysteresis.size() && j < a.hysteresis.size(); ++j) {
    const Record r = load_record(c, u, u.hysteresis[j], Experiment::kHysteresis);
    targets.push_back({a.hysteresis[j].result.amplitude, fit_record(r.channel("Va"), r.channel("de"), r.ts.sample_rate, o)});
  }
  const auto fit_twin = [&](const bench::Twin& t, double amplitude) {
    const io::TimeSeries ts = simulate_twin(t, bench::Experiment::kHysteresis, amplitude);
    return fit_record(column(ts, "Va"), column(ts, "de"), ts.sample_rate, o);
  };
  const HysteresisTarget& largest = *std::max_element(targets.begin(), targets.end(), [](const auto& x, const auto& y) { return x.amplitude < y.amplitude; });
  twin.unit.hysteresis_thresholds = o.thresholds;
  twin.unit.hysteresis_weights = largest.fit.model.hysteresis.weights;
  twin.unit.creep_coefficient = 0.0;
  bench::Twin trial = twin;
  trial.unit.creep_coefficient = kTrialVoltageCreep;
  const double creep_slope = (creep_sum(fit_twin(trial, largest.amplitude)) - creep_sum(fit_twin(twin, largest.amplitude))) / kTrialVoltageCreep;
  const std::size_t n = o.thresholds.size();
  for (int iteration = 0; iteration < 6; ++iteration) {
    std::vector<double> sum(n, 0.0), count(n, 0.0);
    double creep_error = 0.0;
    for (const HysteresisTarget& t : targets) {
      const ident::HysteresisFit got = fit_twin(twin, t.amplitude);
      for (std::size_t i = 0; i < n; ++i) {
        if (o.thresholds[i] >= 0.99 * t.amplitude && &t != &largest) continue;  // not turned in that record
        sum[i] += t.fit.model.hysteresis.weights[i] - got.model.hysteresis.weights[i];
        count[i] += 1.0;
      }
      creep_error += (creep_sum(t.fit) - creep_sum(got)) / static_cast<double>(targets.size());
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = count[i] > 0.0 ? sum[i] / count[i] : 0.0;
      twin.unit.hysteresis_weights[i] = std::max(0.0, twin.unit.hysteresis_weights[i] + d);
      worst = std::max(worst, std::abs(d));
    }
    if (creep_slope > 0.0) twin.unit.creep_coefficient = std::clamp(twin.unit.creep_coefficient + creep_error / creep_slope, 0.0, 0.5);
    if (worst <= 1e-3 * *std::max_element(largest.fit.model.hysteresis.weights.begin(), largest.fit.model.hysteresis.weights.end())) break;
  }
}

double stiffness_creep(const io::TimeSeries& ts, double gravity) {
  const VectorXd de = column(ts, "de"), mass = column(ts, "added_mass");
  const VectorXd weight = mass * gravity;
  return ident::fit_creep({weight.data(), static_cast<std::size_t>(weight.size())}, {de.data(), static_cast<std::size_t>(de.size())},
                          ts.sample_rate)
      .creep_per_decade;
}

// The load creep: the stiffness record's creep per decade, reproduced by the twin's own record.
void calibrate_load_creep(const Campaign& c, const UnitAnalysis& a, bench::Twin& twin, TwinBuild& out) {
  if (!a.stiffness_analysis || !a.stiffness_analysis->creep) {
    out.notes.push_back("no stiffness record with a creep fit: the twin has no load creep");
    return;
  }
  const double target = a.stiffness_analysis->creep->creep_per_decade;
  const auto creep_of = [&](double coefficient) {
    bench::Twin t = twin;
    t.unit.load_creep_coefficient = coefficient;
    t.options.added_mass = c.bench.added_mass;
    t.options.gravity = c.bench.gravity;
    return stiffness_creep(simulate_twin(t, bench::Experiment::kStiffness, std::nullopt), c.bench.gravity);
  };
  twin.unit.load_creep_coefficient = linear_calibration(target, creep_of(0.0), creep_of(kTrialLoadCreep), kTrialLoadCreep, 0.9);
  out.unit_creep_per_decade = target;
  out.twin_creep_per_decade = creep_of(twin.unit.load_creep_coefficient);
}

// --------------------------------------------------------------------------- noise

struct QuietSegment {
  VectorXd x;
  double sample_rate = 0.0;
  std::string source;
};

// The longest run of samples from the start of the record over which the held channels (u, Va,
// added_mass, u_prime: whichever the record has) keep their first value.
Index quiet_length(const io::TimeSeries& ts, const std::map<std::string, std::string>& names) {
  Index end = ts.data.rows();
  for (const char* role : {"u", "Va", "added_mass", "u_prime"}) {
    const auto n = names.count(role) ? names.at(role) : std::string(role);
    const auto it = std::find(ts.names.begin(), ts.names.end(), n);
    if (it == ts.names.end()) continue;
    const VectorXd v = ts.data.col(it - ts.names.begin());
    const double tol = std::string(role) == "Va" ? 0.05 : 1e-9 + 1e-6 * v.cwiseAbs().maxCoeff();
    Index k = 0;
    while (k < end && std::abs(v(k) - v(0)) <= tol) ++k;
    end = k;
  }
  return end;
}

// `limit` (samples, 0 = none): where the record stops being quiet for a reason no channel shows.
void collect_quiet(const io::TimeSeries& ts, const std::string& label, const std::map<std::string, std::string>& names, double min_s,
                   std::map<std::string, QuietSegment>& best, Index limit = 0) {
  const Index n = limit > 0 ? std::min(limit, quiet_length(ts, names)) : quiet_length(ts, names);
  if (static_cast<double>(n) / ts.sample_rate < min_s) return;
  for (const char* role : {"de", "Vs"}) {
    const std::string name = names.count(role) ? names.at(role) : std::string(role);
    const auto it = std::find(ts.names.begin(), ts.names.end(), name);
    if (it == ts.names.end()) continue;
    QuietSegment& b = best[role];
    if (b.x.size() >= n) continue;
    b.x = ts.data.col(it - ts.names.begin()).head(n);
    b.sample_rate = ts.sample_rate;
    b.source = fmt::format("{} [0, {:.3g}] s", label, static_cast<double>(n) / ts.sample_rate);
  }
}

TwinNoise channel_noise(const std::string& role, const std::map<std::string, QuietSegment>& quiet, double lsb, double fallback) {
  TwinNoise out;
  out.channel = role;
  out.white_rms = fallback;
  const auto it = quiet.find(role);
  if (it == quiet.end()) return out;
  const QuietSpectrum s = quiet_spectrum(it->second.x, it->second.sample_rate);
  out.measured = true;
  out.source = it->second.source;
  out.seconds = static_cast<double>(it->second.x.size()) / it->second.sample_rate;
  out.measured_rms = std::sqrt(s.median_level * it->second.sample_rate / 2.0);
  out.white_rms = std::sqrt(std::max(0.0, out.measured_rms * out.measured_rms - lsb * lsb / 12.0));
  // 30 log-spaced lines of the measured spectrum, for the file.
  for (int i = 0; i < 30; ++i) {
    const double f = std::exp(std::log(2.0) + (std::log(0.4 * it->second.sample_rate) - std::log(2.0)) * i / 29.0);
    Index k = 0;
    (s.freq_Hz.array() - f).abs().minCoeff(&k);
    if (!out.spectrum.freq_Hz.empty() && out.spectrum.freq_Hz.back() == s.freq_Hz(k)) continue;
    out.spectrum.freq_Hz.push_back(s.freq_Hz(k));
    out.spectrum.psd.push_back(s.psd(k));
  }
  return out;
}

void measure_noise(const Campaign& c, const UnitSpec& u, const UnitAnalysis& a, const TwinOptions& o, bench::Twin& twin, TwinBuild& out) {
  std::map<std::string, QuietSegment> quiet;
  for (const auto& file : o.quiet) collect_quiet(io::read_timeseries(file), file.string(), c.channels, o.min_quiet_s, quiet);
  if (u.stiffness && a.stiffness_analysis) {
    // Before the mass goes on (the analysis's t_on; 0.1 s earlier: the operator's ramp).
    const Record r = load_record(c, u, *u.stiffness, Experiment::kStiffness);
    const auto limit = static_cast<Index>(std::max(0.0, a.stiffness_analysis->result.t_on - 0.1) * r.ts.sample_rate);
    if (limit > 0) collect_quiet(r.ts, u.stiffness->given, u.stiffness->channels, o.min_quiet_s, quiet, limit);
  }
  if (u.frf) collect_quiet(load_record(c, u, *u.frf, Experiment::kFrf).ts, u.frf->given, u.frf->channels, o.min_quiet_s, quiet);
  const bench::BenchOptions& b = twin.options;
  out.de_noise = channel_noise("de", quiet, b.encoder_resolution, b.encoder_noise);
  out.vs_noise = channel_noise("Vs", quiet, 2.0 * b.adc_range / std::ldexp(1.0, b.adc_bits), b.vs_noise);
  for (const TwinNoise* n : {&out.de_noise, &out.vs_noise}) {
    if (!n->measured) out.notes.push_back(fmt::format("no quiet segment of {} (give --quiet FILE): the bench's default noise is kept", n->channel));
  }
  twin.options.encoder_noise = out.de_noise.white_rms;
  twin.options.vs_noise = out.vs_noise.white_rms;
  twin.de_noise = out.de_noise.spectrum;
  twin.vs_noise = out.vs_noise.spectrum;
}

// --------------------------------------------------------------------------- the first twin

bench::Twin tuned_twin(const Campaign& c, const UnitAnalysis& a) {
  bench::Twin t;
  t.name = a.name;
  t.unit.id = a.id;
  t.unit.model = a.model_2dof->tuning.params;
  t.unit.model.m = c.bench.suspended_mass;
  t.unit.capacitance_sensor = capacitance_sensor_of(a).value_or(t.unit.capacitance_sensor);
  t.unit.capacitance_actuator = capacitance_actuator_of(a).value_or(t.unit.capacitance_actuator);
  t.unit.creep_coefficient = 0.0;
  t.unit.load_creep_coefficient = 0.0;
  t.options.amplifier_gain = c.bench.amplifier_gain;
  t.options.suspended_mass = c.bench.suspended_mass;
  t.options.added_mass = c.bench.added_mass;
  t.options.gravity = c.bench.gravity;
  t.options.delay = a.model_2dof->bench.delay;
  const std::optional<double> corner = a.frf_analysis ? a.frf_analysis->hpf.corner_Hz : std::nullopt;
  // Without a measured corner nor a resistor in [bench], the sensor stack's only shunt is the ADC's
  // input resistance (the twin file's hpf_resistance_ohm is that shunt): no invented high-pass.
  if (corner) t.options.hpf_resistance = 1.0 / (kTwoPi * *corner * t.unit.capacitance_sensor);
  else t.options.hpf_resistance = c.bench.hpf_resistance.value_or(t.options.adc_input_resistance);
  // The zero's side: the ground return's resistance (refined below) starts at the bench's, or
  // small (not 0: the refinement takes its magnitude, whose derivative vanishes there).
  const bool nmp = a.frf_analysis && a.frf_analysis->zero_is_nonminimum_phase.value_or(false);
  t.options.ground_resistance = nmp ? bench::BenchOptions{}.ground_resistance : 0.05;
  t.options.sample_rate = frf_of(a) ? frf_of(a)->provenance.sample_rate : t.options.sample_rate;
  if (!(t.options.sample_rate > 0.0)) t.options.sample_rate = bench::BenchOptions{}.sample_rate;
  return t;
}

void check_twin(const UnitAnalysis& a, const TwinOptions& o, TwinBuild& out) {
  for (const HysteresisLoop& h : a.hysteresis) {
    TwinHysteresisCheck chk;
    chk.amplitude = h.result.amplitude;
    chk.unit_width = h.result.relative_width;
    const io::TimeSeries ts = simulate_twin(out.twin, bench::Experiment::kHysteresis, h.result.amplitude);
    chk.twin_width = metrology::analyze_hysteresis(column(ts, "Va"), column(ts, "de")).relative_width;
    out.hysteresis.push_back(chk);
    if (chk.unit_width > 0.01 && std::abs(chk.twin_width / chk.unit_width - 1.0) > o.max_width_error) {
      out.quality.add_problem(
          fmt::format("hysteresis width at {} V: twin {} %, unit {} %", format_number(chk.amplitude, 3),
                      format_number_fixed(100.0 * chk.twin_width, 2), format_number_fixed(100.0 * chk.unit_width, 2)));
    }
  }
  for (const auto& [name, e] : {std::pair{"u -> d_e", out.de}, std::pair{"u -> Vs", out.vs}}) {
    if (e.points == 0)
      out.quality.add_problem(
          fmt::format("{}: no FRF point with coherence >= {} in the band", name, format_number(o.min_coherence)));
    if (e.max_dB > o.max_frf_error_dB)
      out.quality.add_problem(fmt::format("{}: FRF error up to {} dB", name, format_number_fixed(e.max_dB, 2)));
  }
  if (out.iff_optimal_gain_unit && std::abs(out.iff_optimal_gain / *out.iff_optimal_gain_unit - 1.0) > o.max_iff_error) {
    out.quality.add_problem(fmt::format("IFF optimum: twin g = {}, unit's fitted plant g = {}",
                                        format_number(out.iff_optimal_gain, 4),
                                        format_number(*out.iff_optimal_gain_unit, 4)));
  }
  out.quality.advise("check the records the twin was built from (coherence, amplitudes), or build the twin from longer records");
}

std::pair<double, double> iff_optimum(const lti::StateSpace& plant, double resonance, const control::IffControllerParams& controller) {
  control::IffLoopOptions lo;
  lo.resonance = resonance;
  const lti::StateSpace loop = control::iff_open_loop(plant, lti::to_state_space(control::iff_controller(controller)), lo);
  const lti::StateSpace states = plant.has_delay() ? lti::pade(plant, lo.pade_order) : plant;
  const lti::CVector poles = lti::poles(states);
  Index best = -1;
  for (Index i = 0; i < poles.size(); ++i) {
    if (poles(i).imag() <= 0.0) continue;
    if (best < 0 || std::abs(std::abs(poles(i)) - resonance) < std::abs(std::abs(poles(best)) - resonance)) best = i;
  }
  if (best < 0) throw NumericalError("IFF optimum", "the plant has no complex pole", false);
  const lti::BranchOptimum opt = lti::max_damping_on_branch(loop, poles(best));
  return {opt.gain, opt.damping};
}

}  // namespace

void TwinOptions::validate() const {
  const std::string s = "twin options";
  if (!(min_coherence >= 0.0 && min_coherence < 1.0)) throw InputError(s, "min_coherence", "a coherence in [0, 1)", fmt::format("{}", min_coherence));
  if (!(fmin_Hz > 0.0 && fmax_Hz > fmin_Hz && std::isfinite(fmax_Hz))) {
    throw InputError(s, "fmax_Hz", "a band 0 < fmin < fmax", fmt::format("[{}, {}] Hz", fmin_Hz, fmax_Hz));
  }
  if (!(min_quiet_s > 0.0 && std::isfinite(min_quiet_s))) throw InputError(s, "min_quiet_s", "a duration > 0 s", fmt::format("{}", min_quiet_s));
  if (!(max_frf_error_dB > 0.0 && max_width_error > 0.0 && max_iff_error > 0.0)) {
    throw InputError(s, "max_frf_error_dB", "limits > 0", fmt::format("{}, {}, {}", max_frf_error_dB, max_width_error, max_iff_error));
  }
}

dsp::Frf bench_frf(const bench::UnitTruth& unit, const bench::BenchOptions& options, const VectorXd& freq_Hz) {
  const bench::VirtualBench b(unit, options, kTwinSeed);
  const lti::FrequencyResponse r = lti::freqresp(b.linear_model(), kTwoPi * freq_Hz);
  dsp::Frf f;
  f.freq_Hz = freq_Hz;
  f.input = "u";
  f.outputs = {"de", "Vs"};
  f.H = {r.channel(0, 0), r.channel(1, 0)};
  return f;
}

std::pair<double, double> bench_iff_optimum(const bench::UnitTruth& unit, const bench::BenchOptions& options,
                                            const control::IffControllerParams& controller) {
  const bench::VirtualBench b(unit, options, kTwinSeed);
  const apa::TwoDofParams& p = unit.model;
  const double k_tot = p.k1 + p.ka * p.ke / (p.ka + p.ke);
  return iff_optimum(lti::select(b.linear_model(), {1}, {0}), std::sqrt(k_tot / options.suspended_mass), controller);
}

QuietSpectrum quiet_spectrum(const VectorXd& x, double sample_rate) {
  const Index n = x.size();
  if (n < 64) throw InputError("quiet segment", "samples", "at least 64 samples", std::to_string(n));
  dsp::WelchOptions w;
  w.nfft = std::min<Index>(static_cast<Index>(std::llround(sample_rate)), n / 4);
  w.detrend = dsp::Detrend::kLinear;
  w.threads = 1;
  QuietSpectrum s;
  s.psd = dsp::welch_psd(x, sample_rate, w);
  s.freq_Hz = VectorXd::LinSpaced(s.psd.size(), 0.0, sample_rate * static_cast<double>(s.psd.size() - 1) / static_cast<double>(w.nfft));
  std::vector<double> band;
  for (Index k = 0; k < s.psd.size(); ++k) {
    if (s.freq_Hz(k) >= 2.0 && s.freq_Hz(k) <= 0.4 * sample_rate) band.push_back(s.psd(k));
  }
  if (band.empty()) throw InputError("quiet segment", "samples", "a segment long enough to resolve 2 Hz", std::to_string(n));
  std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2), band.end());
  s.median_level = band[band.size() / 2];
  return s;
}

TwinBuild build_twin(const Campaign& campaign, const UnitSpec& unit, const TwinOptions& options, const Log& log) {
  options.validate();
  const auto start = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& line) {
    if (log) log(line);
  };
  if (!unit.frf) throw InputError(campaign.file.string(), unit.key + ".frf", "an FRF record (the twin's model is tuned to it)", "none");
  say(fmt::format("twin of {}: the campaign's analyses", unit.name));
  const UnitAnalysis a = analyze_unit(campaign, unit);
  if (!a.model_2dof || !frf_of(a)) {
    throw InputError(campaign.file.string(), unit.key + ".frf", "an FRF the 2-DoF model can be tuned to",
                     a.failed.empty() ? std::string("no tuned model") : a.failed.front());
  }
  TwinBuild out;
  out.twin = tuned_twin(campaign, a);
  const FrfPoints points = frf_points(*frf_of(a), options);
  out.de_tuned = frf_error(bench_frf(out.twin.unit, out.twin.options, points.freq_Hz), points, 0);
  out.vs_tuned = frf_error(bench_frf(out.twin.unit, out.twin.options, points.freq_Hz), points, 1);
  say("twin: refining the model on the twin bench's FRF");
  refine_model(out.twin, points);
  const dsp::Frf model = bench_frf(out.twin.unit, out.twin.options, points.freq_Hz);
  out.de = frf_error(model, points, 0);
  out.vs = frf_error(model, points, 1);
  say("twin: hysteresis and creep");
  calibrate_load_creep(campaign, a, out.twin, out);
  identify_hysteresis(campaign, unit, a, out.twin, out);
  say("twin: noise of the quiet segments");
  measure_noise(campaign, unit, a, options, out.twin, out);
  const auto [gain, damping] = bench_iff_optimum(out.twin.unit, out.twin.options, campaign.analysis.controller);
  out.iff_optimal_gain = gain;
  out.iff_max_damping = damping;
  if (const ident::IffPlantFit* plant = iff_plant_of(a)) {
    out.iff_optimal_gain_unit = iff_optimum(lti::to_state_space(plant->transfer_function()), plant->wp,
                                            campaign.analysis.controller).first;
  }
  for (const auto& [experiment, spec] : {std::pair{"frf", unit.frf}, std::pair{"stiffness", unit.stiffness}, std::pair{"capacitance", unit.capacitance}}) {
    if (spec) out.twin.sources.emplace_back(experiment, spec->given);
  }
  for (const auto& h : unit.hysteresis) out.twin.sources.emplace_back(h.key, h.given);
  for (const auto& q : options.quiet) out.twin.sources.emplace_back("quiet", q.string());
  out.twin.validate();
  say("twin: checking it against the unit");
  check_twin(a, options, out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace piezobench::campaign
