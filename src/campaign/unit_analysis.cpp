#include "piezobench/campaign/unit_analysis.hpp"

#include <fmt/format.h>
#include <matio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include "piezobench/apa/tuning.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/modal.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/flatness.hpp"
#include "piezobench/metrology/stiffness.hpp"
#include "piezobench/metrology/stroke.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using Eigen::Index;
using Eigen::VectorXd;
using nlohmann::json;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

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

// LCR readings are one sample per channel, which the time-series readers refuse in a .mat file
// (a record has 2 samples or more): read them as real numeric scalars or vectors through matio.
// Returns false when the file is not a .mat file or lacks a channel (the reader's message is then
// the one to show).
bool read_readings_mat(const fs::path& file, const std::vector<std::string>& channels, io::TimeSeries& out) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext != ".mat") return false;
  mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
  if (mat == nullptr) return false;
  std::vector<VectorXd> values;
  bool ok = true;
  for (const auto& name : channels) {
    matvar_t* v = Mat_VarRead(mat, name.c_str());
    ok = v != nullptr && v->class_type == MAT_C_DOUBLE && !v->isComplex && v->data != nullptr && v->rank == 2 &&
         (v->dims[0] == 1 || v->dims[1] == 1) && v->dims[0] * v->dims[1] >= 1;
    if (ok) {
      const auto n = static_cast<Index>(v->dims[0] * v->dims[1]);
      values.push_back(Eigen::Map<const VectorXd>(static_cast<const double*>(v->data), n));
    }
    if (v != nullptr) Mat_VarFree(v);
    if (!ok) break;
  }
  Mat_Close(mat);
  if (!ok) return false;
  const Index n = values.front().size();
  if (std::any_of(values.begin(), values.end(), [&](const VectorXd& v) { return v.size() != n; })) return false;
  out.names = channels;
  out.data.resize(n, static_cast<Index>(channels.size()));
  for (std::size_t j = 0; j < values.size(); ++j) out.data.col(static_cast<Index>(j)) = values[j];
  out.sample_rate = 1.0;
  out.source = file.string();
  out.validate();
  return true;
}

}  // namespace

Record load_record(const Campaign& campaign, const FileSpec& spec, Experiment experiment) {
  const std::string source = campaign.file.string();
  io::ReadOptions read;
  read.fs = spec.sample_rate;
  // Point lists and LCR readings have no time base: one "sample" per point or reading.
  const bool readings = experiment == Experiment::kCapacitance || experiment == Experiment::kFlatness;
  if (readings && read.fs == 0.0) read.fs = 1.0;
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
      if (experiment == Experiment::kCapacitance && read_readings_mat(spec.path, read.channels, r.ts)) return r;
    } catch (const InputError&) {
      // NaN readings and the like: the reader's message below
    }
    throw wrap(e);
  }
  return r;
}

long frf_segment_length(const AnalysisSettings& settings, long samples, double fs) {
  if (settings.nfft > 0) return settings.nfft;
  const long four_seconds = std::lround(4.0 * fs);
  return std::max<long>(256, std::min<long>(four_seconds, samples / 4));
}

namespace {

// ------------------------------------------------------------------------------------ helpers

json num(double v) { return io::to_json(v); }
json opt(const std::optional<double>& v, double scale = 1.0) { return v ? num(*v * scale) : json(nullptr); }

// At most `points` samples of x (every k-th).
json thin(const VectorXd& x, Index points = 1500) {
  const Index step = std::max<Index>(1, (x.size() + points - 1) / points);
  json out = json::array();
  for (Index i = 0; i < x.size(); i += step) out.push_back(std::isfinite(x(i)) ? json(x(i)) : json(nullptr));
  return out;
}

// Phases in degrees, unwrapped along the list (no 360 deg jumps between neighbours).
json unwrapped_degrees(const std::vector<std::complex<double>>& h) {
  json out = json::array();
  double prev = 0.0, offset = 0.0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double p = std::arg(h[i]) * 180.0 / std::numbers::pi;
    if (i > 0) {
      while (p + offset - prev > 180.0) offset -= 360.0;
      while (p + offset - prev < -180.0) offset += 360.0;
    }
    prev = p + offset;
    out.push_back(prev);
  }
  return out;
}

// Indices of a frequency grid thinned to ~`points` log-spaced values inside [fmin, fmax].
std::vector<Index> log_indices(const VectorXd& f, double fmin, double fmax, int points = 400) {
  std::vector<Index> idx;
  double next = fmin;
  const double ratio = std::pow(fmax / fmin, 1.0 / points);
  for (Index k = 0; k < f.size(); ++k) {
    if (f(k) < fmin || f(k) > fmax) continue;
    if (f(k) >= next) {
      idx.push_back(k);
      next = f(k) * ratio;
    }
  }
  return idx;
}

json provenance(const Record& r, const std::vector<std::string>& roles) {
  json ch = json::object();
  for (const auto& role : roles) {
    if (r.has(role)) ch[role] = r.spec.channels.at(role);
  }
  return {{"file", r.spec.given}, {"key", r.spec.key}, {"channels", ch}, {"samples", r.ts.samples()},
          {"sample_rate_Hz", r.ts.sample_rate}};
}

json welch_provenance(const dsp::Frf& frf) {
  const auto& p = frf.provenance;
  return {{"estimator", p.estimator}, {"window", p.window}, {"nfft", p.nfft}, {"overlap", p.overlap},
          {"detrend", p.detrend},     {"averages", p.averages}, {"resolution_Hz", p.sample_rate / static_cast<double>(p.nfft)}};
}

dsp::Frf welch(const Record& r, const std::string& input, const std::vector<std::string>& outputs,
               const AnalysisSettings& settings, long nfft) {
  dsp::WelchOptions w;
  w.window = settings.window;
  w.nfft = nfft;
  w.overlap = settings.overlap;
  w.detrend = dsp::Detrend::kMean;  // a linear trend removal per segment would distort the lowest bins
  w.estimator = dsp::FrfEstimator::kH1;
  w.threads = 1;  // the pipeline parallelizes over units
  const VectorXd in = r.channel(input);
  std::vector<VectorXd> outs;
  for (const auto& o : outputs) outs.push_back(r.channel(o));
  std::vector<dsp::Channel> out_channels;
  for (std::size_t i = 0; i < outputs.size(); ++i) out_channels.push_back(dsp::channel(outputs[i], outs[i]));
  dsp::FrfEstimate e = dsp::estimate_frf(dsp::channel(input, in), out_channels, r.ts.sample_rate, w, r.spec.given);
  return std::move(e.frf);
}

struct Band {
  VectorXd omega;
  Eigen::VectorXcd h;
  VectorXd coherence;
};

Band band(const dsp::Frf& frf, Index output, double fmin, double fmax, double min_coherence = 0.0) {
  std::vector<Index> keep;
  for (Index k = 0; k < frf.freq_hz.size(); ++k) {
    const double f = frf.freq_hz(k);
    if (f <= 0.0 || f < fmin || (fmax > 0.0 && f > fmax)) continue;
    const auto& coh = frf.coherence[static_cast<std::size_t>(output)];
    if (coh.size() > 0 && coh(k) < min_coherence) continue;
    keep.push_back(k);
  }
  Band b;
  b.omega.resize(static_cast<Index>(keep.size()));
  b.h.resize(static_cast<Index>(keep.size()));
  b.coherence.resize(static_cast<Index>(keep.size()));
  for (std::size_t i = 0; i < keep.size(); ++i) {
    const auto j = static_cast<Index>(i);
    b.omega(j) = kTwoPi * frf.freq_hz(keep[i]);
    b.h(j) = frf.H[static_cast<std::size_t>(output)](keep[i]);
    const auto& coh = frf.coherence[static_cast<std::size_t>(output)];
    b.coherence(j) = coh.size() > 0 ? coh(keep[i]) : 1.0;
  }
  return b;
}

// Index of the largest |h| (min_w < omega), -1 if none.
Index peak_index(const Band& b, double min_w) {
  Index peak = -1;
  for (Index k = 0; k < b.omega.size(); ++k) {
    if (b.omega(k) > min_w && (peak < 0 || std::abs(b.h(k)) > std::abs(b.h(peak)))) peak = k;
  }
  return peak;
}

void record_failure(UnitAnalysis& u, const std::string& what, const Error& e) {
  u.failed.push_back(what + ": " + e.what());
}

// ------------------------------------------------------------------------------------ analyses

void flatness(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const VectorXd x = r.channel("x"), y = r.channel("y"), z = r.channel("z");
  Eigen::Matrix3Xd p(3, x.size());
  p.row(0) = x.transpose();
  p.row(1) = y.transpose();
  p.row(2) = z.transpose();
  const std::string src = c.file.string() + ": " + r.spec.key + " (" + r.spec.given + ")";
  const metrology::FlatnessResult ls = metrology::flatness(p, {metrology::FlatnessMethod::kLeastSquares}, src);
  std::optional<metrology::FlatnessResult> mz;
  if (p.cols() <= 100) mz = metrology::flatness(p, {metrology::FlatnessMethod::kMinimumZone}, src);
  if (c.specs.flatness_method == metrology::FlatnessMethod::kMinimumZone && !mz) {
    throw InputError(c.file.string(), r.spec.key, "at most 100 points for the minimum-zone flatness of the specification",
                     std::to_string(p.cols()));
  }
  const metrology::FlatnessResult& chosen = c.specs.flatness_method == metrology::FlatnessMethod::kMinimumZone ? *mz : ls;
  u.flatness = chosen.flatness;
  json per_interface = json::array();
  if (r.has("interface")) {
    const VectorXd itf = r.channel("interface");
    std::vector<double> ids(itf.data(), itf.data() + itf.size());
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (const double id : ids) {
      std::vector<Index> cols;
      for (Index k = 0; k < itf.size(); ++k) {
        if (itf(k) == id) cols.push_back(k);
      }
      if (cols.size() < 3) continue;
      Eigen::Matrix3Xd q(3, static_cast<Index>(cols.size()));
      for (std::size_t i = 0; i < cols.size(); ++i) q.col(static_cast<Index>(i)) = p.col(cols[i]);
      try {
        per_interface.push_back({{"interface", id}, {"least_squares_um", metrology::flatness(q, {}, src).flatness * 1e6}});
      } catch (const InputError&) {
        // an interface whose points are collinear has no flatness of its own; the whole set still does
      }
    }
  }
  u.result["flatness_um"] = chosen.flatness * 1e6;
  u.result["flatness"] = {{"method", metrology::to_string(c.specs.flatness_method)},
                          {"least_squares_um", ls.flatness * 1e6},
                          {"minimum_zone_um", mz ? json(mz->flatness * 1e6) : json(nullptr)},
                          {"points", p.cols()},
                          {"per_interface", per_interface},
                          {"probe_accuracy_um", c.bench.probe_accuracy * 1e6},
                          {"provenance", provenance(r, {"x", "y", "z", "interface"})}};
  u.plots["flatness_deviation_um"] = thin(chosen.deviations * 1e6);
}

void capacitance(const Campaign& c, const UnitSpec& spec, UnitAnalysis& u) {
  json prov;
  if (spec.capacitance) {
    const Record r = load_record(c, *spec.capacitance, Experiment::kCapacitance);
    u.capacitance_sensor = r.channel("C_sensor").mean();
    u.capacitance_actuator = r.channel("C_actuator").mean();
    prov = provenance(r, {"C_sensor", "C_actuator"});
    for (const auto& [v, role] : {std::pair{*u.capacitance_sensor, "C_sensor"}, std::pair{*u.capacitance_actuator, "C_actuator"}}) {
      if (!(v > 0.0)) {
        throw InputError(c.file.string(), spec.capacitance->key, fmt::format("a positive capacitance reading ({} in {})", role, spec.capacitance->given),
                         fmt::format("{} F", v));
      }
    }
  } else {
    u.capacitance_sensor = spec.capacitance_sensor;
    u.capacitance_actuator = spec.capacitance_actuator;
    prov = {{"key", spec.key + ".capacitance_uF"}};
  }
  u.result["capacitance_uF"] = {{"sensor", *u.capacitance_sensor * 1e6}, {"actuator", *u.capacitance_actuator * 1e6}};
  u.result["capacitance_provenance"] = prov;
}

void stroke(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const VectorXd va = r.channel("Va"), de = r.channel("de");
  const metrology::StrokeResult s = metrology::analyze_stroke(va, de, r.ts.sample_rate, {}, c.file.string() + ": " + r.spec.key);
  u.stroke = s.stroke;
  u.result["stroke_um"] = s.stroke * 1e6;
  u.result["stroke"] = {{"va_min_V", s.va_min},
                        {"va_max_V", s.va_max},
                        {"sensitivity_um_per_V", s.sensitivity * 1e6},
                        {"loop_width_um", s.loop_width * 1e6},
                        {"provenance", provenance(r, {"Va", "de"})}};
  u.plots["stroke"] = {{"Va", thin(va)}, {"de_um", thin(de * 1e6)}};
}

void hysteresis(const Campaign& c, const std::vector<Record>& records, UnitAnalysis& u) {
  json list = json::array();
  json loops = json::array();
  for (const Record& r : records) {
    const VectorXd va = r.channel("Va"), de = r.channel("de");
    const metrology::HysteresisResult h = metrology::analyze_hysteresis(va, de, {}, c.file.string() + ": " + r.spec.key);
    list.push_back({{"amplitude_V", h.amplitude},
                    {"offset_V", h.offset},
                    {"width_um", h.width * 1e6},
                    {"loop_stroke_um", h.loop_stroke * 1e6},
                    {"relative_width", h.relative_width},
                    {"periods", h.periods},
                    {"provenance", provenance(r, {"Va", "de"})}});
    // The loop: the part of the record the analysis used (between the first and last maxima).
    const VectorXd lv = va.segment(h.first_sample, h.samples);
    const VectorXd ld = de.segment(h.first_sample, h.samples) * 1e6;
    loops.push_back({{"amplitude_V", h.amplitude}, {"Va", thin(lv, 1200)}, {"de_um", thin(ld, 1200)}});
  }
  std::sort(list.begin(), list.end(), [](const json& a, const json& b) { return a["amplitude_V"] < b["amplitude_V"]; });
  u.result["hysteresis"] = list;
  u.plots["hysteresis"] = loops;
}

// The added-mass test (report section 2.2). `open`: every stack open (k_oc), else the stacks on
// the amplifier and the resistor (k1, k2; k_sc = k1). The same readings and creep fit either way.
void stiffness(const Campaign& c, const Record& r, UnitAnalysis& u, bool open) {
  const VectorXd t = r.time();
  const VectorXd de = r.channel("de");
  const VectorXd mass = r.has("added_mass") ? r.channel("added_mass") : VectorXd();
  metrology::StaticStiffnessOptions o;
  o.added_mass = c.bench.added_mass;
  o.gravity = c.bench.gravity;
  const metrology::StaticStiffnessResult s = metrology::static_stiffness(t, de, mass, o, c.file.string() + ": " + r.spec.key);
  if (open) {
    u.k_oc = s.k1;
  } else {
    u.k1 = s.k1;
    u.k2 = s.k2;
  }
  u.result[open ? "stiffness_open_circuit" : "stiffness_static"] = {{"k1_N_per_um", s.k1 * 1e-6},
                                  {"k2_N_per_um", s.k2 * 1e-6},
                                  {"t_on_s", s.t_on},
                                  {"t_off_s", s.t_off},
                                  {"readings_um", {{"before", s.d_before * 1e6}, {"loaded", s.d_loaded * 1e6}, {"after", s.d_after * 1e6}}},
                                  {"reading_windows_s", {{"before", {o.before_s[0], o.before_s[1]}}, {"loaded", {o.loaded_s[0], o.loaded_s[1]}}, {"after", {o.after_s[0], o.after_s[1]}}}},
                                  {"elastic_N_per_um", {{"on", s.k_elastic_on * 1e-6}, {"off", s.k_elastic_off * 1e-6}}},
                                  {"creep_um_per_decade", {{"on", s.creep_on * 1e6}, {"off", s.creep_off * 1e6}}},
                                  {"creep_time_constant_s", s.creep_time_constant},
                                  {"fit_rms_um", s.rms_residual * 1e6},
                                  {"added_mass_kg", o.added_mass},
                                  {"gravity_m_per_s2", o.gravity},
                                  {"mass_log", r.has("added_mass")},
                                  {"provenance", provenance(r, {"de", "added_mass"})}};
  u.plots[open ? "stiffness_open" : "stiffness"] = {{"t", thin(t)}, {"de_um", thin(de * 1e6)}, {"fit_um", thin(s.fit * 1e6)}};
}

// Chooses the feature nearest in frequency to `target` (rad/s).
template <typename T>
const T* nearest(const std::vector<T>& features, double target) {
  const T* best = nullptr;
  for (const T& f : features) {
    if (!best || std::abs(std::log(f.natural_frequency / target)) < std::abs(std::log(best->natural_frequency / target))) best = &f;
  }
  return best;
}

void frf(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  const long nfft = frf_segment_length(a, static_cast<long>(r.ts.samples()), r.ts.sample_rate);
  const dsp::Frf frf = welch(r, "u", {"de", "Vs"}, a, nfft);
  u.frf = frf;
  json out = {{"provenance", provenance(r, {"u", "de", "Vs"})}, {"welch", welch_provenance(frf)}};
  out["provenance"].update({{"input", "u"}, {"outputs", {"de", "Vs"}}});
  const Band de = band(frf, 0, a.fmin_hz, a.fmax_hz);
  const Band vs = band(frf, 1, a.fmin_hz, a.fmax_hz);
  if (de.omega.size() < 20) {
    throw InputError(c.file.string(), r.spec.key, fmt::format("at least 20 FRF points in [{}, {}] Hz", a.fmin_hz, a.fmax_hz),
                     fmt::format("{} (resolution {} Hz)", de.omega.size(), r.ts.sample_rate / static_cast<double>(nfft)));
  }
  ident::FrfFeatureOptions fo;
  fo.fit.order = a.fit_order;
  fo.fit.fail_if_not_converged = false;
  // u -> d_e: static gain and resonance.
  std::optional<double> res_w, res_z;
  try {
    const ident::FrfFeatures f = ident::frf_features(de.omega, de.h, fo);
    const Index pk = peak_index(de, 0.0);
    const ident::ModalFeature* m = nearest(f.resonances, de.omega(pk));
    u.static_gain = f.static_gain;
    out["static_gain_um_per_V"] = f.static_gain * 1e6;
    out["static_gain_source"] = ident::to_string(f.static_gain_source);
    if (m) {
      res_w = m->natural_frequency;
      res_z = m->damping;
    }
    out["fit_de"] = {{"order", a.fit_order}, {"relative_rms_error", f.fit.relative_rms_error}, {"converged", f.fit.converged}};
  } catch (const NumericalError& e) {
    record_failure(u, "frf u -> d_e features", e);
  }
  // u -> d_e as a mass-spring-damper with its own delay (the tuning and the damped plants use it).
  try {
    IffPlantFitOptions so;
    so.fmin_hz = a.fmin_hz;
    so.fmax_hz = a.fmax_hz;
    so.min_coherence = 0.5;
    const DelayedSecondOrderFit f = fit_delayed_second_order(kTwoPi * frf.freq_hz, frf.H[0], frf.coherence[0], so,
                                                             c.file.string() + ": " + r.spec.key);
    u.de_plant = f;
    out["de_plant_fit"] = {{"static_gain_um_per_V", f.static_gain * 1e6},
                           {"resonance_Hz", f.natural_frequency / kTwoPi},
                           {"damping", f.damping},
                           {"delay_s", f.delay},
                           {"relative_rms_error", f.relative_rms_error},
                           {"points", f.points}};
  } catch (const NumericalError& e) {
    record_failure(u, "u -> d_e second-order fit", e);
  }
  // u -> Vs: anti-resonance and the NMP verdict.
  json nmp = json::object();
  std::optional<double> anti_w, anti_z;
  std::optional<bool> nmp_phase, nmp_model;
  try {
    const ident::FrfFeatures f = ident::frf_features(vs.omega, vs.h, fo);
    const Index pk = peak_index(vs, 0.0);
    // The dip below the resonance.
    Index dip = -1;
    for (Index k = 0; k < pk; ++k) {
      if (dip < 0 || std::abs(vs.h(k)) < std::abs(vs.h(dip))) dip = k;
    }
    const ident::AntiResonance* z = dip >= 0 ? nearest(f.antiresonances, vs.omega(dip)) : nullptr;
    if (z) {
      anti_w = z->natural_frequency;
      anti_z = z->damping;
      nmp_model = z->nonminimum_phase_model;
      if (z->phase_verdict != ident::PhaseVerdict::kUndetermined) nmp_phase = z->phase_verdict == ident::PhaseVerdict::kNonMinimumPhase;
      nmp = {{"phase_verdict", ident::to_string(z->phase_verdict)},
             {"phase_change_deg", z->phase_change_deg},
             {"fitted_zero", io::to_json(z->root)},
             {"fitted_zero_nonminimum_phase", z->nonminimum_phase_model}};
    }
    out["static_gain_Vs_V_per_V"] = f.static_gain;
    out["fit_Vs"] = {{"order", a.fit_order}, {"relative_rms_error", f.fit.relative_rms_error}, {"converged", f.fit.converged}};
  } catch (const NumericalError& e) {
    record_failure(u, "frf u -> Vs features", e);
  }
  // High-pass corner (first-order fit at low frequency) and the IFF plant fit (eq. 2.3).
  const Band low = band(frf, 1, 0.0, a.hpf_fmax_hz, 0.5);
  json hpf = json::object();
  if (low.omega.size() >= 3) {
    const ident::HighPassFit h = ident::fit_high_pass(low.omega, low.h);
    hpf["first_order_fit_Hz"] = h.corner_hz();
    hpf["first_order_fit_points"] = low.omega.size();
  }
  // The resistor high-pass: its corner is 1 / (2 pi R C_sensor) (report section 2.5) when the
  // capacitance is measured; the FRF below a few Hz is dominated by the stacks' creep and
  // hysteresis, so the corner fitted to it is a cross-check only.
  const std::optional<double> w_rc = u.capacitance_sensor ? std::optional<double>(1.0 / (c.bench.hpf_resistance * *u.capacitance_sensor))
                                                          : std::nullopt;
  if (w_rc) hpf["R_C_Hz"] = *w_rc / kTwoPi;
  const VectorXd& coh = frf.coherence[1];
  const std::string fit_source = c.file.string() + ": " + r.spec.key;
  try {
    IffPlantFitOptions io_;
    io_.fmin_hz = w_rc ? a.fmin_hz : 0.0;
    io_.fmax_hz = a.fmax_hz;
    io_.hpf_fmax_hz = a.hpf_fmax_hz;
    io_.min_coherence = 0.5;
    io_.fixed_w_hpf = w_rc.value_or(0.0);
    const IffPlantFit p = fit_iff_plant(kTwoPi * frf.freq_hz, frf.H[1], coh, io_, fit_source);
    u.iff_plant = p;
    out["iff_plant_fit"] = {{"g0", p.g0},
                            {"wz_Hz", p.wz / kTwoPi},
                            {"xz", p.xz},
                            {"wp_Hz", p.wp / kTwoPi},
                            {"xp", p.xp},
                            {"w_hpf_Hz", p.w_hpf / kTwoPi},
                            {"w_hpf_from", w_rc ? "R C_sensor" : "fit"},
                            {"delay_s", p.delay},
                            {"band_Hz", {io_.fmin_hz, io_.fmax_hz}},
                            {"relative_rms_error", p.relative_rms_error},
                            {"points", p.points},
                            {"iterations", p.iterations}};
    nmp["iff_plant_fit_xz"] = p.xz;
    if (!w_rc) hpf["iff_plant_fit_Hz"] = p.w_hpf / kTwoPi;
  } catch (const NumericalError& e) {
    record_failure(u, "IFF plant fit", e);
  }
  if (w_rc) {
    // Cross-check: the corner fitted with the rest of eq. 2.3 down to the lowest frequencies.
    try {
      IffPlantFitOptions free;
      free.fmin_hz = 0.0;
      free.fmax_hz = a.fmax_hz;
      free.hpf_fmax_hz = a.hpf_fmax_hz;
      free.min_coherence = 0.5;
      hpf["iff_plant_fit_Hz"] = fit_iff_plant(kTwoPi * frf.freq_hz, frf.H[1], coh, free, fit_source).w_hpf / kTwoPi;
    } catch (const Error& e) {
      hpf["iff_plant_fit_Hz"] = nullptr;
      hpf["iff_plant_fit_error"] = e.what();
    }
  }
  hpf["method"] = w_rc ? "1/(2 pi R C_sensor), R from [bench], C_sensor measured" : "IFF plant fit (eq. 2.3) down to the lowest frequency";
  if (u.capacitance_sensor) {
    u.result["hpf_corner_Hz"] = 1.0 / (kTwoPi * c.bench.hpf_resistance * *u.capacitance_sensor);
  } else if (hpf.contains("iff_plant_fit_Hz")) {
    u.result["hpf_corner_Hz"] = hpf["iff_plant_fit_Hz"];
  } else if (hpf.contains("first_order_fit_Hz")) {
    u.result["hpf_corner_Hz"] = hpf["first_order_fit_Hz"];
  }
  u.result["hpf"] = hpf;

  // The verdict: the phase of the data when it decides, else the fitted models (VF zero, then the
  // sign of xz in the IFF fit).
  std::optional<bool> verdict = nmp_phase;
  if (!verdict && u.iff_plant) verdict = u.iff_plant->zero_is_nonminimum_phase();
  if (!verdict) verdict = nmp_model;
  nmp["verdict_from"] = nmp_phase ? "phase" : (u.iff_plant ? "iff-plant-fit" : (nmp_model ? "fitted-zero" : "none"));
  out["nmp_evidence"] = nmp;
  // Static gain, resonance and its damping: from the mass-spring-damper fit of u -> d_e with its
  // delay (else the vector fit, else the IFF plant fit). Anti-resonance: from the IFF plant fit,
  // whose zero pair is exactly the model's (the order-N vector fit spreads the narrow notch over
  // its poles). The vector fits are kept as cross-checks.
  if (anti_w) {
    out["antiresonance_vector_fit_Hz"] = *anti_w / kTwoPi;
    out["antiresonance_vector_fit_damping"] = *anti_z;
  }
  if (res_w) {
    out["resonance_vector_fit_Hz"] = *res_w / kTwoPi;
    out["resonance_vector_fit_damping"] = *res_z;
  }
  if (u.static_gain) out["static_gain_vector_fit_um_per_V"] = *u.static_gain * 1e6;
  if (u.de_plant) {
    res_w = u.de_plant->natural_frequency;
    res_z = u.de_plant->damping;
    u.static_gain = u.de_plant->static_gain;
    out["static_gain_um_per_V"] = u.de_plant->static_gain * 1e6;
    out["static_gain_source"] = "second-order fit of u -> d_e with delay";
  }
  if (!res_w && u.iff_plant) {
    res_w = u.iff_plant->wp;
    res_z = u.iff_plant->xp;
  }
  if (u.iff_plant) {
    anti_w = u.iff_plant->wz;
    anti_z = std::abs(u.iff_plant->xz);
  }
  if (res_w) {
    u.resonance_hz = *res_w / kTwoPi;
    u.k_resonance = metrology::stiffness_from_resonance(c.bench.suspended_mass, *res_w, c.file.string());
  }
  if (anti_w) u.antiresonance_hz = *anti_w / kTwoPi;
  out["resonance_Hz"] = opt(u.resonance_hz);
  out["resonance_damping"] = opt(res_z);
  out["antiresonance_Hz"] = opt(u.antiresonance_hz);
  // Signed as in the truth: negative for a non-minimum-phase zero pair.
  out["antiresonance_damping"] = anti_z ? num((verdict.value_or(false) ? -1.0 : 1.0) * *anti_z) : json(nullptr);
  out["zero_is_nonminimum_phase"] = verdict ? json(*verdict) : json(nullptr);
  if (!out.contains("static_gain_um_per_V")) out["static_gain_um_per_V"] = nullptr;
  out["shell_stiffness_N_per_um"] = anti_w ? num(c.bench.suspended_mass * *anti_w * *anti_w * 1e-6) : json(nullptr);
  u.result["frf"] = out;

  // The tuned 2-DoF model (report section 3) with the fitted measurement chain.
  try {
    apa::TuningOptions t;
    t.mass = c.bench.suspended_mass;
    t.bench.amplifier_gain = c.bench.amplifier_gain;
    // The tuning removes one delay from both outputs: d_e's (from its second-order fit), with
    // Vs first advanced by the difference (its read-out filter's lag).
    dsp::Frf data = frf;
    if (u.iff_plant) {
      t.bench.hpf_resistance = c.bench.hpf_resistance;
      t.bench.hpf_capacitance = 1.0 / (c.bench.hpf_resistance * u.iff_plant->w_hpf);
    }
    if (u.de_plant) {
      t.bench.delay = std::max(0.0, u.de_plant->delay);
      if (u.iff_plant) {
        const double extra = u.iff_plant->delay - t.bench.delay;
        for (Index k = 0; k < data.freq_hz.size(); ++k) {
          data.H[1](k) *= std::exp(std::complex<double>(0.0, kTwoPi * data.freq_hz(k) * extra));
        }
      }
    }
    t.fmin_hz = a.fmin_hz;
    t.fmax_hz = a.fmax_hz;
    t.min_coherence = 0.5;
    const apa::TwoDofTuning tuned = apa::tune_two_dof(data, t);
    json m = json::object();
    for (const auto& name : apa::TwoDofParams::names()) m[name] = tuned.params.get(name);
    u.result["model_2dof"] = m;
    u.result["model_2dof_fit"] = {{"status", apa::to_string(tuned.status)},
                                  {"iterations", tuned.iterations},
                                  {"relative_error_de", tuned.fit_error_de},
                                  {"relative_error_Vs", tuned.fit_error_vs},
                                  {"points", tuned.points},
                                  {"delay_s", t.bench.delay},
                                  {"band_Hz", {t.fmin_hz, t.fmax_hz}},
                                  {"units", "SI: kg, N/m, N s/m, N/V, V/m"}};
    // The model's response for the report.
    const VectorXd f = frf.freq_hz;
    const std::vector<Index> idx = log_indices(f, std::max(0.5, f(1)), std::min(2.0 * a.fmax_hz, f(f.size() - 1)));
    VectorXd w(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) w(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    apa::TwoDofBench b = t.bench;
    const lti::CMatrix hm = apa::two_dof_response(tuned.params, b, w);
    u.plots["model"] = {{"f", json::array()}, {"de_abs", json::array()}, {"Vs_abs", json::array()}};
    std::vector<std::complex<double>> mde, mvs;
    for (Index k = 0; k < w.size(); ++k) {
      u.plots["model"]["f"].push_back(w(k) / kTwoPi);
      u.plots["model"]["de_abs"].push_back(std::abs(hm(k, 0)) * 1e6);
      u.plots["model"]["Vs_abs"].push_back(std::abs(hm(k, 1)));
      mde.push_back(hm(k, 0));
      mvs.push_back(hm(k, 1));
    }
    u.plots["model"]["de_phase"] = unwrapped_degrees(mde);
    u.plots["model"]["Vs_phase"] = unwrapped_degrees(mvs);
  } catch (const NumericalError& e) {
    record_failure(u, "2-DoF tuning", e);
  }
  // The measured FRFs for the report.
  {
    const VectorXd& f = frf.freq_hz;
    const std::vector<Index> idx = log_indices(f, std::max(0.5, f(1)), std::min(2.0 * a.fmax_hz, f(f.size() - 1)));
    json p = {{"f", json::array()}, {"de_abs", json::array()}, {"de_coh", json::array()},
              {"Vs_abs", json::array()}, {"Vs_coh", json::array()}};
    std::vector<std::complex<double>> hde, hvs;
    for (const Index k : idx) {
      p["f"].push_back(f(k));
      p["de_abs"].push_back(std::abs(frf.H[0](k)) * 1e6);
      p["de_coh"].push_back(frf.coherence[0](k));
      p["Vs_abs"].push_back(std::abs(frf.H[1](k)));
      p["Vs_coh"].push_back(frf.coherence[1](k));
      hde.push_back(frf.H[0](k));
      hvs.push_back(frf.H[1](k));
    }
    p["de_phase"] = unwrapped_degrees(hde);
    p["Vs_phase"] = unwrapped_degrees(hvs);
    // Every line around the anti-resonance (report Figure 2.6: coherence and phase there).
    if (anti_w) {
      const double fz = *anti_w / kTwoPi;
      json z = {{"f", json::array()}, {"abs", json::array()}, {"coh", json::array()}};
      std::vector<std::complex<double>> hz;
      for (Index k = 0; k < f.size(); ++k) {
        if (f(k) < 0.7 * fz || f(k) > 1.4 * fz) continue;
        z["f"].push_back(f(k));
        z["abs"].push_back(std::abs(frf.H[1](k)));
        z["coh"].push_back(frf.coherence[1](k));
        hz.push_back(frf.H[1](k));
      }
      z["phase"] = unwrapped_degrees(hz);
      z["antiresonance_Hz"] = fz;
      u.plots["nmp"] = z;
    }
    if (u.iff_plant) {
      VectorXd w(static_cast<Index>(idx.size()));
      for (std::size_t i = 0; i < idx.size(); ++i) w(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
      const Eigen::VectorXcd g = u.iff_plant->response(w);
      p["iff_fit_abs"] = json::array();
      std::vector<std::complex<double>> hg;
      for (Index k = 0; k < g.size(); ++k) {
        p["iff_fit_abs"].push_back(std::abs(g(k)));
        hg.push_back(g(k));
      }
      p["iff_fit_phase"] = unwrapped_degrees(hg);
    }
    u.plots["frf"] = p;
  }
}

// The low-frequency u -> Vs with and without the resistor across the sensor stack (report section
// 2.5, Figure 2.7): Welch with segments of half the record (the lowest lines matter here), a
// first-order high-pass fitted below hpf_fmax_hz (ident::fit_high_pass). A corner below a third of
// the lowest line (where it would change |H| there by less than 5 %) is not observable in the
// record: it is reported as an upper bound, not as a number.
json low_frequency_vs(const Campaign& c, const Record& r, const std::string& name, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  long nfft = static_cast<long>(r.ts.samples()) / 2;
  nfft -= nfft % 2;
  const dsp::Frf frf = welch(r, "u", {"Vs"}, a, std::max(256L, nfft));
  const double lowest = frf.freq_hz.size() > 1 ? frf.freq_hz(1) : 0.0;
  json out = {{"provenance", provenance(r, {"u", "Vs"})}, {"welch", welch_provenance(frf)}, {"lowest_line_Hz", lowest},
              {"band_Hz", {lowest, a.hpf_fmax_hz}}, {"corner_Hz", nullptr}, {"observable", false}};
  const Band low = band(frf, 0, 0.0, a.hpf_fmax_hz);
  if (low.omega.size() >= 3) {
    const ident::HighPassFit h = ident::fit_high_pass(low.omega, low.h);
    const bool observable = h.corner_hz() >= lowest / 3.0;
    out["observable"] = observable;
    out["fitted_corner_Hz"] = h.corner_hz();
    out["relative_rms_error"] = h.relative_rms_error;
    out["points"] = low.omega.size();
    if (observable) {
      out["corner_Hz"] = h.corner_hz();
    } else {
      out["below_Hz"] = lowest / 3.0;
      out["note"] = fmt::format("not observable in this record: the fitted corner ({:.2g} Hz) is below a third of the lowest line "
                                "({:.3g} Hz)", h.corner_hz(), lowest);
    }
  }
  // For Figure 2.7: up to 20 Hz.
  const std::vector<Index> idx = log_indices(frf.freq_hz, lowest, std::min(20.0, frf.freq_hz(frf.freq_hz.size() - 1)), 200);
  json p = {{"f", json::array()}, {"abs", json::array()}, {"coh", json::array()}};
  std::vector<std::complex<double>> h;
  for (const Index k : idx) {
    p["f"].push_back(frf.freq_hz(k));
    p["abs"].push_back(std::abs(frf.H[0](k)));
    p["coh"].push_back(frf.coherence[0](k));
    h.push_back(frf.H[0](k));
  }
  p["phase"] = unwrapped_degrees(h);
  if (!u.plots.contains("resistor")) u.plots["resistor"] = json::object();
  u.plots["resistor"][name] = p;
  return out;
}

void resistor(const Campaign& c, const Record* with, const Record& without, UnitAnalysis& u) {
  json out = json::object();
  out["with_resistor"] = with ? low_frequency_vs(c, *with, "with", u) : json(nullptr);
  out["without_resistor"] = low_frequency_vs(c, without, "without", u);
  out["method"] = "first-order high-pass g s/(s + wc) fitted to u -> Vs below hpf_fmax_Hz (Welch, segments of half the record)";
  u.result["hpf_resistor"] = out;
}

void iff(const Campaign& c, const std::vector<Record>& records, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  json list = json::array();
  // The loop does not change the delay of d_e: the open-loop u -> d_e fit's is removed first.
  const double delay = u.de_plant ? std::max(0.0, u.de_plant->delay) : 0.0;
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
    d.frf = welch(r, "u_prime", {"de"}, a, nfft);
    d.delay_removed = delay;
    Band b = band(d.frf, 0, a.damped_fmin_hz, a.damped_fmax_hz);
    for (Index k = 0; k < b.omega.size(); ++k) b.h(k) *= std::exp(std::complex<double>(0.0, b.omega(k) * delay));
    json entry = {{"gain", gain}, {"provenance", provenance(r, {"u_prime", "de"})}, {"welch", welch_provenance(d.frf)},
                  {"delay_removed_s", delay}};
    try {
      // The damped pole: the dominant pair of a vector fit (ident/dominant_pole.hpp, the method of
      // `iff study`), not the report's second-order fit, which misplaces it by up to 50 % once the
      // controller's poles have moved into the band.
      ident::DominantPoleOptions po;
      po.fit.order = a.fit_order;
      po.omega_min = kTwoPi * a.damped_fmin_hz;
      po.omega_max = kTwoPi * a.damped_fmax_hz;
      d.identified = ident::dominant_pole(b.omega, b.h, po);
      entry["fit"] = {{"frequency_Hz", d.identified->frequency_hz()},
                      {"damping", d.identified->damping},
                      {"pole", io::to_json(d.identified->pole)},
                      {"order", po.fit.order},
                      {"relative_rms_error", d.identified->fit.relative_rms_error},
                      {"band_Hz", {a.damped_fmin_hz, a.damped_fmax_hz}},
                      {"method", "vector fitting, the dominant pole pair (largest |r|/|Re p|) in the band; delay of d_e removed"}};
    } catch (const NumericalError& e) {
      record_failure(u, fmt::format("damped plant g = {}", gain), e);
      entry["fit"] = nullptr;
    }
    // The report's second-order fit, for comparison only.
    try {
      IffPlantFitOptions so;
      so.fit_delay = false;
      d.second_order = fit_delayed_second_order(b.omega, b.h, b.coherence, so, c.file.string() + ": " + r.spec.key);
      entry["second_order_fit"] = {{"frequency_Hz", d.second_order->natural_frequency / kTwoPi},
                                   {"damping", d.second_order->damping},
                                   {"pole", io::to_json(d.second_order->pole())},
                                   {"relative_rms_error", d.second_order->relative_rms_error},
                                   {"method", "the report's: k wn^2/(s^2 + 2 zeta wn s + wn^2), weighted Levenberg-Marquardt"}};
    } catch (const NumericalError& e) {
      entry["second_order_fit"] = nullptr;
    }
    if (d.identified) u.damped.push_back(d);
    list.push_back(entry);
  }
  std::sort(u.damped.begin(), u.damped.end(), [](const DampedPlant& x, const DampedPlant& y) { return x.gain < y.gain; });
  json plots = json::array();
  for (const DampedPlant& d : u.damped) {
    const VectorXd& f = d.frf.freq_hz;
    const std::vector<Index> idx = log_indices(f, std::max(f(1), 0.5 * a.damped_fmin_hz), std::min(f(f.size() - 1), 2.0 * a.damped_fmax_hz), 300);
    json p = {{"gain", d.gain}, {"f", json::array()}, {"abs", json::array()}, {"fit_abs", json::array()}};
    VectorXd om(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) om(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    // The fit (delay removed) with the delay put back, to sit on the measurement.
    const Eigen::MatrixXcd fit = d.identified->fit.evaluate(om);
    std::vector<std::complex<double>> hm, hf;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const auto k = static_cast<Index>(i);
      const std::complex<double> g = fit(k, 0) * std::exp(std::complex<double>(0.0, -om(k) * d.delay_removed));
      p["f"].push_back(f(idx[i]));
      p["abs"].push_back(std::abs(d.frf.H[0](idx[i])) * 1e6);
      p["fit_abs"].push_back(std::abs(g) * 1e6);
      hm.push_back(d.frf.H[0](idx[i]));
      hf.push_back(g);
    }
    p["phase"] = unwrapped_degrees(hm);
    p["fit_phase"] = unwrapped_degrees(hf);
    plots.push_back(p);
  }
  u.plots["damped"] = plots;
  std::sort(list.begin(), list.end(), [](const json& x, const json& y) { return x["gain"] < y["gain"]; });
  u.result["iff_damped_plants"] = list;
}

void hammer(const Campaign& c, const Record& r, UnitAnalysis& u) {
  const AnalysisSettings& a = c.analysis;
  const long nfft = std::min<long>(std::lround(r.ts.sample_rate), static_cast<long>(r.ts.samples()) / 2);
  const dsp::Frf frf = welch(r, "F", {"v"}, a, nfft);
  const Band b = band(frf, 0, a.hammer_fmin_hz, a.hammer_fmax_hz);
  json out = {{"provenance", provenance(r, {"F", "v"})}, {"welch", welch_provenance(frf)}};
  json peaks = json::array();
  json modes = json::array();
  try {
    ident::PeakPickingOptions po;
    po.max_modes = 6;
    for (const auto& m : ident::peak_picking(b.omega, b.h, po)) peaks.push_back({{"frequency_Hz", m.frequency_hz()}, {"damping", m.damping}});
  } catch (const NumericalError& e) {
    record_failure(u, "hammer peak picking", e);
  }
  try {
    ident::LscfOptions lo;
    lo.max_order = std::min<Index>(24, b.omega.size() - 1);
    for (const auto& m : ident::lscf(b.omega, b.h, lo).modes) {
      modes.push_back({{"frequency_Hz", m.frequency_hz()}, {"damping", m.damping}, {"stable_orders", m.stable_orders}});
    }
  } catch (const NumericalError& e) {
    record_failure(u, "hammer LSCF", e);
  }
  out["peak_picking"] = peaks;
  out["lscf"] = modes;
  u.result["flexible_modes"] = out;
  const std::vector<Index> idx = log_indices(frf.freq_hz, std::max(1.0, frf.freq_hz(1)), frf.freq_hz(frf.freq_hz.size() - 1), 500);
  json p = {{"f", json::array()}, {"abs", json::array()}};
  for (const Index k : idx) {
    p["f"].push_back(frf.freq_hz(k));
    p["abs"].push_back(std::abs(frf.H[0](k)));
  }
  u.plots["hammer"] = p;
}

}  // namespace

UnitAnalysis analyze_unit(const Campaign& c, const UnitSpec& spec, const Log& log) {
  UnitAnalysis u;
  u.id = spec.id;
  u.name = spec.name;
  u.result = {{"id", spec.id},
              {"name", spec.name},
              {"flatness_um", nullptr},
              {"capacitance_uF", nullptr},
              {"stroke_um", nullptr},
              {"stiffness_N_per_um", nullptr},
              {"frf", nullptr},
              {"hpf_corner_Hz", nullptr},
              {"model_2dof", nullptr}};
  u.plots = json::object();
  auto say = [&](const std::string& what, const FileSpec& f) {
    if (log) log(fmt::format("{}: {} ({})", spec.name, what, f.given));
  };
  for (const Experiment e : all_experiments()) {
    if (!spec.has(e)) u.not_measured.push_back(to_string(e));
  }
  if (spec.flatness) {
    say("flatness", *spec.flatness);
    flatness(c, load_record(c, *spec.flatness, Experiment::kFlatness), u);
  }
  if (spec.has(Experiment::kCapacitance)) capacitance(c, spec, u);
  if (spec.stroke) {
    say("stroke", *spec.stroke);
    stroke(c, load_record(c, *spec.stroke, Experiment::kStroke), u);
  }
  if (!spec.hysteresis.empty()) {
    std::vector<Record> records;
    for (const auto& f : spec.hysteresis) {
      say("hysteresis", f);
      records.push_back(load_record(c, f, Experiment::kHysteresis));
    }
    hysteresis(c, records, u);
  }
  if (spec.stiffness) {
    say("static stiffness", *spec.stiffness);
    try {
      stiffness(c, load_record(c, *spec.stiffness, Experiment::kStiffness), u, false);
    } catch (const NumericalError& e) {
      record_failure(u, "static stiffness", e);
    }
  }
  if (spec.stiffness_open) {
    say("static stiffness, stacks open", *spec.stiffness_open);
    try {
      stiffness(c, load_record(c, *spec.stiffness_open, Experiment::kStiffnessOpen), u, true);
    } catch (const NumericalError& e) {
      record_failure(u, "static stiffness, stacks open", e);
    }
  }
  std::optional<Record> frf_record;
  if (spec.frf) {
    say("FRFs u -> d_e, Vs", *spec.frf);
    frf_record = load_record(c, *spec.frf, Experiment::kFrf);
    frf(c, *frf_record, u);
  }
  if (spec.frf_no_resistor) {
    say("u -> Vs without the resistor", *spec.frf_no_resistor);
    try {
      resistor(c, frf_record ? &*frf_record : nullptr, load_record(c, *spec.frf_no_resistor, Experiment::kFrfNoResistor), u);
    } catch (const NumericalError& e) {
      record_failure(u, "high-pass corner with and without the resistor", e);
    }
  }
  frf_record.reset();
  if (u.k1 || u.k_resonance || u.k_oc) {
    // k_sc: the stacks short-circuited (on the amplifier, the sensor on R) = k1; k_oc: every stack
    // open, read the same way (report section 2.2).
    u.result["stiffness_N_per_um"] = {{"k1", opt(u.k1, 1e-6)},    {"k2", opt(u.k2, 1e-6)},   {"resonance", opt(u.k_resonance, 1e-6)},
                                      {"k_sc", opt(u.k1, 1e-6)}, {"k_oc", opt(u.k_oc, 1e-6)}};
  }
  if (!spec.iff.empty()) {
    std::vector<Record> records;
    for (const auto& f : spec.iff) {
      say("IFF damped plant", f);
      records.push_back(load_record(c, f, Experiment::kIff));
    }
    iff(c, records, u);
  }
  if (spec.hammer) {
    say("hammer test", *spec.hammer);
    hammer(c, load_record(c, *spec.hammer, Experiment::kHammer), u);
  }
  u.result["not_measured"] = u.not_measured;
  u.result["failed"] = u.failed;
  return u;
}

}  // namespace piezobench::campaign
