#include "piezobench/campaign/unit_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "piezobench/apa/tuning.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/timestamp.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/ident/actuator_frf.hpp"
#include "piezobench/ident/added_mass.hpp"
#include "piezobench/ident/damped_plant.hpp"
#include "piezobench/ident/flexible_modes.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/ident/hysteresis_model_choice.hpp"
#include "piezobench/ident/low_frequency_high_pass.hpp"
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/interface_flatness.hpp"
#include "piezobench/metrology/stiffness.hpp"
#include "piezobench/metrology/stroke.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using Eigen::Index;
using Eigen::VectorXd;

// ------------------------------------------------------------------------------------ records

bool Record::has(const std::string& role) const {
  const auto it = spec.channels.find(role);
  return it != spec.channels.end() && std::find(ts.names.begin(), ts.names.end(), it->second) != ts.names.end();
}

VectorXd Record::channel(const std::string& role) const { return ts.channel(spec.channels.at(role)); }

VectorXd Record::time() const {
  if (ts.t.size() == ts.samples()) return ts.t;
  return VectorXd::LinSpaced(ts.samples(), 0.0, static_cast<double>(ts.samples() - 1) / ts.sample_rate);
}

namespace {

Record read_record(const Campaign& campaign, const FileSpec& spec, Experiment experiment) {
  const std::string source = campaign.file.string();
  io::ReadOptions read;
  read.fs = spec.sample_rate;
  // Point lists and LCR readings have no time base: one "sample" per point or reading.
  const bool readings = experiment == Experiment::kCapacitance || experiment == Experiment::kFlatness;
  if (readings && read.fs == 0.0) read.fs = 1.0;
  for (const auto& [role, unit] : spec.units) read.units[spec.channels.at(role)] = unit;
  for (const auto& role : required_roles(experiment)) read.channels.push_back(spec.channels.at(role));
  std::vector<std::string> optional;
  for (const auto& role : optional_roles(experiment)) {
    const bool must = std::find(spec.explicit_roles.begin(), spec.explicit_roles.end(), role) != spec.explicit_roles.end();
    (must ? read.channels : optional).push_back(spec.channels.at(role));
  }
  auto wrap = [&](const InputError& e) {
    std::vector<std::string> wanted = read.channels;
    return InputError(source, spec.key,
                      fmt::format("a readable {} record '{}' with the channels {}", to_string(experiment), spec.given,
                                  fmt::join(wanted, ", ")),
                      e.what());
  };
  Record r;
  r.spec = spec;
  try {
    if (!optional.empty()) {
      // Optional channels are read when the file has them.
      io::ReadOptions all = read;
      all.channels.insert(all.channels.end(), optional.begin(), optional.end());
      try {
        r.ts = io::read_timeseries(spec.path, all);
        return r;
      } catch (const InputError&) {
        // fall through: without the optional channels (a real problem shows again below)
      }
    }
    r.ts = io::read_timeseries(spec.path, read);
  } catch (const InputError& e) {
    try {
      // LCR readings are one sample per channel, which read_timeseries refuses in a .mat file.
      if (experiment == Experiment::kCapacitance) {
        if (std::optional<io::TimeSeries> lcr = io::read_mat_readings(spec.path, read.channels)) {
          r.ts = std::move(*lcr);
          return r;
        }
      }
    } catch (const InputError&) {
      // NaN readings and the like: the reader's message below
    }
    throw wrap(e);
  }
  return r;
}

// The settings.experiment values of the records a campaign experiment takes (bench/experiments.hpp).
std::vector<std::string> recorded_kinds(Experiment e) {
  switch (e) {
    case Experiment::kFlatness: return {"flatness"};
    case Experiment::kCapacitance: return {"capacitance"};
    case Experiment::kStroke: return {"stroke"};
    case Experiment::kHysteresis: return {"hysteresis"};
    case Experiment::kStiffness:
    case Experiment::kStiffnessOpen: return {"stiffness"};
    case Experiment::kFrf:
    case Experiment::kFrfNoResistor: return {"frf-noise", "frf-sweep"};
    case Experiment::kIff: return {"iff"};
    case Experiment::kHammer: return {"hammer"};
    case Experiment::kTracking: return {"tracking"};
  }
  return {};
}

// What a record says about itself (the settings piezobench's writers record: unit, serial,
// experiment, bench, recorded_at) against the campaign entry that names it: a record of another
// unit, serial, kind or bench, or taken outside the campaign's time window, is refused, naming
// both (issue 35: unit 1's files given for unit 3 made the defective unit pass with unit 1's
// numbers). A record without these settings (another tool's) is taken as given.
void check_provenance(const Campaign& campaign, const UnitSpec& unit, const FileSpec& spec, Experiment experiment,
                      const io::TimeSeries& ts) {
  const std::string source = campaign.file.string();
  const auto text = [&](const char* key) -> std::optional<std::string> {
    const auto it = ts.settings.find(key);
    if (it == ts.settings.end() || !std::holds_alternative<std::string>(it->second)) return std::nullopt;
    return std::get<std::string>(it->second);
  };
  if (const auto it = ts.settings.find("unit"); it != ts.settings.end() && std::holds_alternative<double>(it->second)) {
    const double recorded = std::get<double>(it->second);
    if (recorded != static_cast<double>(unit.id)) {
      throw InputError(source, spec.key, fmt::format("a record of unit {} ({}.id)", unit.id, unit.key),
                       fmt::format("'{}', a record of unit {:g} (its settings.unit)", spec.given, recorded));
    }
  }
  if (const auto serial = text("serial"); serial && unit.serial && *serial != *unit.serial) {
    throw InputError(source, spec.key, fmt::format("a record of serial '{}' ({}.serial)", *unit.serial, unit.key),
                     fmt::format("'{}', a record of serial '{}' (its settings.serial)", spec.given, *serial));
  }
  if (const auto kind = text("experiment")) {
    const std::vector<std::string> kinds = recorded_kinds(experiment);
    if (std::find(kinds.begin(), kinds.end(), *kind) == kinds.end()) {
      throw InputError(source, spec.key, fmt::format("a {} record ({})", to_string(experiment), fmt::join(kinds, " or ")),
                       fmt::format("'{}', a {} record (its settings.experiment)", spec.given, *kind));
    }
  }
  const BenchConstants& bench = campaign.bench;
  if (const auto name = text("bench"); name && !bench.name.empty() && *name != bench.name) {
    throw InputError(source, spec.key, fmt::format("a record of bench '{}' (bench.name)", bench.name),
                     fmt::format("'{}', a record of bench '{}' (its settings.bench)", spec.given, *name));
  }
  if (bench.recorded_from_s || bench.recorded_until_s) {
    const std::string window = fmt::format("from {} until {}", bench.recorded_from_s ? utc_timestamp(*bench.recorded_from_s) : "any time",
                                           bench.recorded_until_s ? utc_timestamp(*bench.recorded_until_s) : "any time");
    if (const auto at = text("recorded_at")) {
      const std::optional<long long> t = parse_utc_timestamp(*at);
      if (!t || (bench.recorded_from_s && *t < *bench.recorded_from_s) || (bench.recorded_until_s && *t > *bench.recorded_until_s)) {
        throw InputError(source, spec.key, fmt::format("a record taken {} (bench.recorded_from/recorded_until)", window),
                         fmt::format("'{}', recorded at '{}' (its settings.recorded_at)", spec.given, *at));
      }
    }
  }
}

}  // namespace

Record load_record(const Campaign& campaign, const UnitSpec& unit, const FileSpec& spec, Experiment experiment) {
  Record r = read_record(campaign, spec, experiment);
  check_provenance(campaign, unit, spec, experiment, r.ts);
  return r;
}

long frf_segment_length(const AnalysisSettings& settings, long samples, double fs) {
  if (settings.nfft > 0) return settings.nfft;
  return static_cast<long>(dsp::segment_length_for_record(samples, fs));
}

namespace {

// ------------------------------------------------------------------------------------ helpers

// At most `points` samples of x (every k-th).
std::vector<double> thin(const VectorXd& x, Index points = 1500) {
  const Index step = std::max<Index>(1, (x.size() + points - 1) / points);
  std::vector<double> out;
  for (Index i = 0; i < x.size(); i += step) out.push_back(x(i));
  return out;
}

RecordProvenance provenance(const Record& r, const std::vector<std::string>& roles) {
  RecordProvenance p;
  p.file = r.spec.given;
  p.key = r.spec.key;
  for (const auto& role : roles) {
    if (r.has(role)) p.channels.emplace_back(role, r.spec.channels.at(role));
  }
  p.samples = static_cast<long>(r.ts.samples());
  p.sample_rate_Hz = r.ts.sample_rate;
  return p;
}

dsp::Frf estimate_record_frf(const Record& r, const std::string& input, const std::vector<std::string>& outputs,
               const AnalysisSettings& settings, long nfft) {
  // The settings `frf` uses too (mean removed per segment, H1), with the campaign's window and overlap.
  dsp::WelchOptions w = dsp::welch_options_for_record(r.ts.samples(), r.ts.sample_rate);
  w.window = settings.window;
  w.nfft = nfft;
  w.overlap = settings.overlap;
  w.threads = 1;  // the pipeline parallelizes over units
  const VectorXd in = r.channel(input);
  std::vector<VectorXd> outs;
  for (const auto& o : outputs) outs.push_back(r.channel(o));
  std::vector<dsp::Channel> out_channels;
  for (std::size_t i = 0; i < outputs.size(); ++i) out_channels.push_back(dsp::channel(outputs[i], outs[i]));
  dsp::FrfEstimate e = dsp::estimate_frf(dsp::channel(input, in), out_channels, r.ts.sample_rate, w, r.spec.given);
  return std::move(e.frf);
}

void record_failure(UnitAnalysis& u, const std::string& what, const Error& e) {
  u.failed.push_back(what + ": " + e.what());
}

// ------------------------------------------------------------------------------------ analyses

// The probe points' flatness (metrology::analyze_flatness) with the record's provenance and curves.
FlatnessAnalysis flatness(const Campaign& c, const Record& r) {
  const VectorXd x = r.channel("x"), y = r.channel("y"), z = r.channel("z");
  Eigen::Matrix3Xd p(3, x.size());
  p.row(0) = x.transpose();
  p.row(1) = y.transpose();
  p.row(2) = z.transpose();
  metrology::FlatnessAnalysisOptions o;
  o.method = c.specs.flatness_method;
  o.source = c.file.string();
  o.field = r.spec.key;
  const metrology::FlatnessAnalysisResult a = metrology::analyze_flatness(p, r.has("interface") ? r.channel("interface") : VectorXd(), o);
  FlatnessAnalysis out;
  out.method = a.method;
  out.flatness = a.flatness_m;
  out.least_squares = a.least_squares_m;
  out.minimum_zone = a.minimum_zone_m;
  out.points = a.points;
  for (const metrology::InterfaceFlatness& i : a.per_interface) out.per_interface.push_back({i.id, i.least_squares_m});
  out.probe_accuracy = c.bench.probe_accuracy;
  out.provenance = provenance(r, {"x", "y", "z", "interface"});
  out.deviation = thin(a.deviations_m);
  out.probe_xy = Curve{thin(x), thin(y)};
  return out;
}

CapacitanceAnalysis capacitance(const Campaign& c, const UnitSpec& spec) {
  CapacitanceAnalysis out;
  if (spec.capacitance) {
    const Record r = load_record(c, spec, *spec.capacitance, Experiment::kCapacitance);
    const VectorXd cs = r.channel("C_sensor"), ca = r.channel("C_actuator");
    out.sensor = cs.mean();
    out.actuator = ca.mean();
    out.readings = static_cast<long>(cs.size());
    const auto scatter = [](const VectorXd& x) {
      return x.size() > 1 ? std::sqrt((x.array() - x.mean()).square().sum() / static_cast<double>(x.size() - 1)) : 0.0;
    };
    out.sensor_scatter = scatter(cs);
    out.actuator_scatter = scatter(ca);
    out.provenance = provenance(r, {"C_sensor", "C_actuator"});
    for (const auto& [v, role] : {std::pair{out.sensor, "C_sensor"}, std::pair{out.actuator, "C_actuator"}}) {
      if (!(v > 0.0)) {
        throw InputError(c.file.string(), spec.capacitance->key, fmt::format("a positive capacitance reading ({} in {})", role, spec.capacitance->given),
                         fmt::format("{} F", v));
      }
    }
  } else {
    out.sensor = *spec.capacitance_sensor;
    out.actuator = *spec.capacitance_actuator;
    out.key = spec.key + ".capacitance_uF";
  }
  return out;
}

StrokeAnalysis stroke(const Campaign& c, const Record& r) {
  const VectorXd va = r.channel("Va"), de = r.channel("de");
  StrokeAnalysis out;
  out.result = metrology::analyze_stroke(va, de, r.ts.sample_rate, {}, c.file.string() + ": " + r.spec.key);
  out.provenance = provenance(r, {"Va", "de"});
  out.de_vs_va = {thin(va), thin(de)};
  return out;
}

// The hysteresis model of the largest-amplitude record (ident::identify_hysteresis_model: the plain
// PI and, when the steady loop is asymmetric, Kuhnen's modified PI too, the better one kept); the
// loop's figures are those of the steady loop `loop` analysed (between its first and last maxima).
HysteresisModelFit fit_hysteresis_model(const Record& r, const metrology::HysteresisResult& loop) {
  const VectorXd va = r.channel("Va"), de = r.channel("de");
  const std::span<const double> v(va.data(), static_cast<std::size_t>(va.size())), d(de.data(), static_cast<std::size_t>(de.size()));
  ident::HysteresisModelChoiceOptions o;
  o.steady_first_sample = static_cast<long>(loop.first_sample);
  o.steady_samples = static_cast<long>(loop.samples);
  o.asymmetry_limit = kHysteresisAsymmetryLimit;
  o.dead_zones = kCampaignDeadZones;
  ident::HysteresisModelChoice m = ident::identify_hysteresis_model(v, d, r.ts.sample_rate, o);
  HysteresisModelFit out;
  out.fit = std::move(m.fit);
  out.alternative = std::move(m.alternative);
  out.alternative_error = std::move(m.alternative_error);  // results.json and the report say why
  out.asymmetry = m.asymmetry;
  out.width = m.width;
  out.model_width = m.model_width;
  out.amplitude = loop.amplitude;
  out.provenance = provenance(r, {"Va", "de"});
  out.loop = {thin(va, 1200), thin(de, 1200)};
  out.model_loop = {out.loop.x, thin(Eigen::Map<const VectorXd>(m.predicted_m.data(), va.size()), 1200)};
  return out;
}

// The tracking record: its figures recomputed from the samples over the record's windows.
TrackingAnalysis analyze_tracking(const Record& r) {
  const bench::TrackingLayout l = bench::tracking_layout(r.ts);
  const VectorXd c = r.channel("c"), open = r.channel("de_open"), ff = r.channel("de_ff");
  TrackingAnalysis out;
  const auto window = [&](Index begin, Index end, bench::TrackingFigures& f, Curve& curve_open, Curve& curve_ff) {
    const auto n = static_cast<std::size_t>(end - begin);
    f = bench::tracking_figures({c.data() + begin, n}, {open.data() + begin, n}, {ff.data() + begin, n}, l.target_slope, l.target_intercept);
    const VectorXd x = c.segment(begin, end - begin);
    curve_open = {thin(x, 800), thin(VectorXd(open.segment(begin, end - begin)), 800)};
    curve_ff = {curve_open.x, thin(VectorXd(ff.segment(begin, end - begin)), 800)};
  };
  window(l.sine_begin, l.sine_end, out.sine, out.sine_open, out.sine_ff);
  window(l.triangle_begin, l.triangle_end, out.triangle, out.triangle_open, out.triangle_ff);
  out.amplitude = l.amplitude;
  if (const auto it = r.ts.settings.find("feedforward"); it != r.ts.settings.end() && std::holds_alternative<std::string>(it->second)) {
    out.feedforward = std::get<std::string>(it->second);
  }
  if (const auto it = r.ts.settings.find("clamped_samples"); it != r.ts.settings.end() && std::holds_alternative<double>(it->second)) {
    out.clamped_samples = std::get<double>(it->second);
  }
  out.provenance = provenance(r, {"c", "de_open", "de_ff"});
  return out;
}

std::vector<HysteresisLoop> hysteresis(const Campaign& c, const std::vector<Record>& records) {
  std::vector<HysteresisLoop> out;
  for (const Record& r : records) {
    const VectorXd va = r.channel("Va"), de = r.channel("de");
    HysteresisLoop h;
    h.result = metrology::analyze_hysteresis(va, de, {}, c.file.string() + ": " + r.spec.key);
    h.provenance = provenance(r, {"Va", "de"});
    // The loop: the part of the record the analysis used (between the first and last maxima).
    h.loop = {thin(va.segment(h.result.first_sample, h.result.samples), 1200),
              thin(de.segment(h.result.first_sample, h.result.samples), 1200)};
    out.push_back(std::move(h));
  }
  return out;
}

// The added-mass test (report section 2.2; ident::analyze_added_mass): with the stacks on the
// amplifier and the resistor (k1, k2; k_sc = k1) or with every stack open (k_oc); the same readings
// and creep fit either way.
StiffnessAnalysis stiffness(const Campaign& c, const Record& r, UnitAnalysis& u, const std::string& what) {
  const VectorXd t = r.time();
  const VectorXd de = r.channel("de");
  ident::AddedMassOptions o;
  o.stiffness.added_mass = c.bench.added_mass;
  o.stiffness.gravity = c.bench.gravity;
  o.source = c.file.string() + ": " + r.spec.key;
  ident::AddedMassAnalysis a = ident::analyze_added_mass(t, de, r.has("added_mass") ? r.channel("added_mass") : VectorXd(), r.ts.sample_rate, o);
  for (const auto& f : a.failed) u.failed.push_back(what + ": " + f);
  StiffnessAnalysis out;
  out.options = o.stiffness;
  out.result = std::move(a.stiffness);
  out.mass_log = a.mass_log;
  out.creep = std::move(a.creep);
  out.provenance = provenance(r, {"de", "added_mass"});
  const std::vector<double> tt = thin(t);
  out.de = {tt, thin(de)};
  out.fit = {tt, thin(out.result.fit)};
  out.result.fit.resize(0);
  return out;
}

// The tuned 2-DoF model (report section 3) with the fitted measurement chain (apa/tuning.hpp).
void tune_model(const Campaign& c, UnitAnalysis& u) {
  try {
    apa::TuningOptions t;
    t.mass = c.bench.suspended_mass;
    t.bench.amplifier_gain = c.bench.amplifier_gain;
    if (iff_plant_of(u)) t.bench.hpf_resistance = c.bench.hpf_resistance.value_or(0.0);
    t.fmin_Hz = c.analysis.fmin_Hz;
    t.fmax_Hz = c.analysis.fmax_Hz;
    t.min_coherence = 0.5;
    t.window_resolution = c.analysis.window_resolution;
    const apa::TwoDofTuning tuned = apa::tune_two_dof_measured(*frf_of(u), t, de_plant_of(u), iff_plant_of(u));
    u.model_2dof = Model2DofFit{tuned, tuned.bench, t.fmin_Hz, t.fmax_Hz};
  } catch (const NumericalError& e) {
    record_failure(u, "2-DoF tuning", e);
  }
}

// The FRFs u -> [d_e, Vs] (ident::analyze_actuator_frf with the campaign's band, fit order and
// bench), the stiffness from the resonance k = m_sus w^2, and the tuned 2-DoF model.
void analyze_frf(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  const long nfft = frf_segment_length(a, static_cast<long>(r.ts.samples()), r.ts.sample_rate);
  dsp::Frf frf = estimate_record_frf(r, "u", {"de", "Vs"}, a, nfft);
  ident::ActuatorFrfOptions o;
  o.fmin_Hz = a.fmin_Hz;
  o.fmax_Hz = a.fmax_Hz;
  o.hpf_fmax_Hz = a.hpf_fmax_Hz;
  o.fit_order = a.fit_order;
  o.min_coherence = 0.5;
  o.hpf_resistance_ohm = c.bench.hpf_resistance;
  o.sensor_capacitance_F = capacitance_sensor_of(u);
  o.suspended_mass_kg = c.bench.suspended_mass;
  o.window_resolution = a.window_resolution;
  o.source = c.file.string();
  o.field = r.spec.key;
  ident::ActuatorFrfResult result = ident::analyze_actuator_frf(frf, o);
  for (auto& f : result.failed) u.failed.push_back(std::move(f));
  for (auto& w : result.warnings) u.warnings.push_back(std::move(w));
  FrfAnalysis out;
  static_cast<ident::ActuatorFrfAnalysis&>(out) = std::move(result.analysis);
  out.provenance = provenance(r, {"u", "de", "Vs"});
  out.provenance.input = "u";
  out.provenance.outputs = {"de", "Vs"};
  out.frf = std::move(frf);
  if (result.resonance_rad_s) out.k_resonance = metrology::stiffness_from_resonance(c.bench.suspended_mass, *result.resonance_rad_s, o.source);
  u.frf_analysis = std::move(out);
  tune_model(c, u);
}

// The low-frequency u -> Vs with or without the resistor across the sensor stack (report section
// 2.5, Figure 2.7): Welch with segments of half the record (the lowest lines matter here), then
// ident::fit_low_frequency_high_pass below hpf_fmax_Hz (a corner it finds not observable is an
// upper bound, not a number).
LowFrequencyVs analyze_low_frequency_vs(const Campaign& c, const Record& r) {
  const AnalysisSettings& a = c.analysis;
  long nfft = static_cast<long>(r.ts.samples()) / 2;
  nfft -= nfft % 2;
  LowFrequencyVs out;
  out.frf = estimate_record_frf(r, "u", {"Vs"}, a, std::max(256L, nfft));
  out.provenance = provenance(r, {"u", "Vs"});
  ident::LowFrequencyHighPassOptions o;
  o.output = "Vs";
  o.fmax_Hz = a.hpf_fmax_Hz;
  o.source = c.file.string() + ": " + r.spec.key;
  const ident::LowFrequencyHighPass h = ident::fit_low_frequency_high_pass(out.frf, o);
  out.lowest_line_Hz = h.lowest_line_Hz;
  out.fmax_Hz = h.fmax_Hz;
  out.fitted_corner_Hz = h.corner_Hz;
  out.relative_rms_error = h.relative_rms_error;
  out.points = h.points;
  out.observable = h.observable;
  return out;
}

std::vector<DampedPlant> analyze_damped_plants(const Campaign& c, const std::vector<Record>& records, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  std::vector<DampedPlant> out;
  // The loop does not change the delay of d_e: the open-loop u -> d_e fit's is removed first.
  const double delay = de_plant_of(u) ? std::max(0.0, de_plant_of(u)->delay) : 0.0;
  for (const Record& r : records) {
    double gain = r.spec.gain;
    if (gain == 0.0) {
      const auto it = r.ts.settings.find("gain");
      if (it != r.ts.settings.end() && std::holds_alternative<double>(it->second)) gain = std::get<double>(it->second);
    }
    if (!(std::isfinite(gain) && gain >= 0.0) || (gain == 0.0 && r.ts.settings.count("gain") == 0)) {
      throw InputError(c.file.string(), r.spec.key + ".gain",
                       fmt::format("the controller gain of '{}' (gain = ... in the campaign, or a `gain` setting in the file)", r.spec.given),
                       "none");
    }
    const long nfft = frf_segment_length(a, static_cast<long>(r.ts.samples()), r.ts.sample_rate);
    DampedPlant d;
    d.gain = gain;
    d.file = r.spec.given;
    d.provenance = provenance(r, {"u_prime", "de"});
    d.frf = estimate_record_frf(r, "u_prime", {"de"}, a, nfft);
    ident::DampedPlantOptions o;
    o.fmin_Hz = a.damped_fmin_Hz;
    o.fmax_Hz = a.damped_fmax_Hz;
    o.delay_s = delay;
    o.fit_order = a.fit_order;
    o.source = c.file.string();
    o.field = r.spec.key;
    ident::DampedPlantAnalysis p = ident::analyze_damped_plant(d.frf, o);
    for (const auto& f : p.failed) u.failed.push_back(fmt::format("damped plant g = {}: {}", gain, f));
    d.identified = std::move(p.dominant);
    d.identified_order = p.dominant_fit_order;
    d.second_order = std::move(p.second_order);  // its failure: left out of results.json (null)
    d.delay_removed = p.delay_removed_s;
    d.fmin_Hz = p.fmin_Hz;
    d.fmax_Hz = p.fmax_Hz;
    out.push_back(std::move(d));
  }
  std::stable_sort(out.begin(), out.end(), [](const DampedPlant& x, const DampedPlant& y) { return x.gain < y.gain; });
  return out;
}

// The hammer test F -> v (Welch with 1 s segments) and its modes (ident::identify_flexible_modes).
FlexibleModes hammer(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  const long nfft = std::min<long>(std::lround(r.ts.sample_rate), static_cast<long>(r.ts.samples()) / 2);
  FlexibleModes out;
  out.frf = estimate_record_frf(r, "F", {"v"}, a, nfft);
  out.provenance = provenance(r, {"F", "v"});
  out.welch = out.frf.provenance;
  ident::FlexibleModeOptions o;
  o.output = "v";
  o.fmin_Hz = a.hammer_fmin_Hz;
  o.fmax_Hz = a.hammer_fmax_Hz;
  o.source = c.file.string() + ": " + r.spec.key;
  const ident::FlexibleModeAnalysis m = ident::identify_flexible_modes(out.frf, o);
  for (const auto& f : m.failed) u.failed.push_back("hammer " + f);
  for (const auto& p : m.peak_picking) out.peak_picking.push_back({p.frequency_Hz(), p.damping, 0});
  for (const auto& l : m.lscf) out.lscf.push_back({l.frequency_Hz(), l.damping, l.stable_orders});
  return out;
}

}  // namespace

namespace {

// Every analysis of the unit; `current` is the file entry being read or analysed (for the report of
// a unit that cannot be analysed). InputError as analyze_unit's contract used to be.
void analyze_measurements(const Campaign& c, const UnitSpec& spec, const Log& log, UnitAnalysis& u, const FileSpec*& current) {
  auto say = [&](const std::string& what, const FileSpec& f) {
    current = &f;
    if (log) log(fmt::format("{}: {} ({})", spec.name, what, f.given));
  };
  if (spec.flatness) {
    say("flatness", *spec.flatness);
    u.flatness_analysis = flatness(c, load_record(c, spec, *spec.flatness, Experiment::kFlatness));
  }
  if (spec.has(Experiment::kCapacitance)) {
    current = spec.capacitance ? &*spec.capacitance : nullptr;
    u.capacitance_analysis = capacitance(c, spec);
  }
  if (spec.stroke) {
    say("stroke", *spec.stroke);
    u.stroke_analysis = stroke(c, load_record(c, spec, *spec.stroke, Experiment::kStroke));
  }
  if (!spec.hysteresis.empty()) {
    std::vector<Record> records;
    for (const auto& f : spec.hysteresis) {
      say("hysteresis", f);
      records.push_back(load_record(c, spec, f, Experiment::kHysteresis));
    }
    u.hysteresis = hysteresis(c, records);  // in the records' order
    std::size_t largest = 0;
    for (std::size_t i = 1; i < records.size(); ++i) {
      if (records[i].channel("Va").maxCoeff() - records[i].channel("Va").minCoeff() >
          records[largest].channel("Va").maxCoeff() - records[largest].channel("Va").minCoeff()) {
        largest = i;
      }
    }
    try {
      u.hysteresis_model = fit_hysteresis_model(records[largest], u.hysteresis[largest].result);
    } catch (const NumericalError& e) {
      record_failure(u, "hysteresis model", e);
    }
    std::stable_sort(u.hysteresis.begin(), u.hysteresis.end(),
                     [](const HysteresisLoop& a, const HysteresisLoop& b) { return a.result.amplitude < b.result.amplitude; });
  }
  if (spec.tracking) {
    say("tracking without and with the hysteresis feedforward", *spec.tracking);
    u.tracking = analyze_tracking(load_record(c, spec, *spec.tracking, Experiment::kTracking));
  }
  if (spec.stiffness) {
    say("static stiffness", *spec.stiffness);
    try {
      u.stiffness_analysis = stiffness(c, load_record(c, spec, *spec.stiffness, Experiment::kStiffness), u, "static stiffness");
    } catch (const NumericalError& e) {
      record_failure(u, "static stiffness", e);
    }
  }
  if (spec.stiffness_open) {
    say("static stiffness, stacks open", *spec.stiffness_open);
    try {
      u.stiffness_open_analysis = stiffness(c, load_record(c, spec, *spec.stiffness_open, Experiment::kStiffnessOpen), u,
                                            "static stiffness, stacks open");
    } catch (const NumericalError& e) {
      record_failure(u, "static stiffness, stacks open", e);
    }
  }
  std::optional<Record> frf_record;
  if (spec.frf) {
    say("FRFs u -> d_e, Vs", *spec.frf);
    frf_record = load_record(c, spec, *spec.frf, Experiment::kFrf);
    analyze_frf(c, *frf_record, u);
  }
  if (spec.frf_no_resistor) {
    say("u -> Vs without the resistor", *spec.frf_no_resistor);
    try {
      ResistorComparison rc;
      if (frf_record) rc.with_resistor = analyze_low_frequency_vs(c, *frf_record);
      rc.without_resistor = analyze_low_frequency_vs(c, load_record(c, spec, *spec.frf_no_resistor, Experiment::kFrfNoResistor));
      u.resistor = std::move(rc);
    } catch (const NumericalError& e) {
      record_failure(u, "high-pass corner with and without the resistor", e);
    }
  }
  frf_record.reset();
  if (!spec.iff.empty()) {
    std::vector<Record> records;
    for (const auto& f : spec.iff) {
      say("IFF damped plant", f);
      records.push_back(load_record(c, spec, f, Experiment::kIff));
    }
    u.damped = analyze_damped_plants(c, records, u);
  }
  if (spec.hammer) {
    say("hammer test", *spec.hammer);
    u.flexible_modes = hammer(c, load_record(c, spec, *spec.hammer, Experiment::kHammer), u);
  }
}

}  // namespace

UnitAnalysis analyze_unit(const Campaign& c, const UnitSpec& spec, const Log& log) {
  UnitAnalysis u;
  u.id = spec.id;
  u.name = spec.name;
  for (const Experiment e : all_experiments()) {
    if (!spec.has(e)) u.not_measured.push_back(to_string(e));
  }
  const FileSpec* current = nullptr;
  try {
    analyze_measurements(c, spec, log, u, current);
  } catch (const InputError& e) {
    // The unit is left out as a whole (its other results too): the batch is then the batch without it.
    UnitAnalysis bad;
    bad.id = spec.id;
    bad.name = spec.name;
    bad.not_measured = std::move(u.not_measured);
    bad.not_analysed = NotAnalysed{current ? current->given : "", current ? current->key : e.field(), e.what()};
    if (log) log(fmt::format("{}: NOT ANALYSED: {}", spec.name, e.what()));
    return bad;
  }
  return u;
}

}  // namespace piezobench::campaign
