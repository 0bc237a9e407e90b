#include "piezobench/campaign/part.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "piezobench campaign part";

// ------------------------------------------------------------------------------------ encoding
// One list of fields per struct (`fields` below) serves both directions, so the reader is the
// writer's inverse by construction.

// Where a value is read: the file and the dotted path of the field.
struct Where {
  std::string file, path;
  [[nodiscard]] Where key(const std::string& k) const { return {file, path.empty() ? k : path + "." + k}; }
  [[nodiscard]] Where index(std::size_t i) const { return {file, fmt::format("{}[{}]", path, i)}; }
};

[[noreturn]] void bad(const Where& w, const std::string& expected, const json& found) {
  std::string f = found.dump();
  if (f.size() > 80) f = f.substr(0, 77) + "...";
  throw InputError(w.file, w.path, expected, f);
}

template <class T> struct IsOptional : std::false_type {};
template <class T> struct IsOptional<std::optional<T>> : std::true_type {};
template <class T> struct IsVector : std::false_type {};
template <class T, class A> struct IsVector<std::vector<T, A>> : std::true_type {};
template <class T> struct IsStdArray : std::false_type {};
template <class T, std::size_t N> struct IsStdArray<std::array<T, N>> : std::true_type {};
template <class T> struct IsPair : std::false_type {};
template <class A, class B> struct IsPair<std::pair<A, B>> : std::true_type {};
template <class T> struct IsComplex : std::false_type {};
template <class T> struct IsComplex<std::complex<T>> : std::true_type {};
template <class T> constexpr bool kIsEigen = std::is_base_of_v<Eigen::EigenBase<T>, T>;

// The enums, by the names their modules give them.
#define PIEZOBENCH_PART_ENUM(Type, label, parse)                                   \
  std::string enum_name(Type v) { return to_string(v); }                          \
  void enum_parse(const std::string& s, Type& v) { v = parse(s); }                \
  const char* enum_label(Type) { return label; }
PIEZOBENCH_PART_ENUM(metrology::FlatnessMethod, "flatness method", [](const std::string& name) { return metrology::flatness_method_from_string(name); })
PIEZOBENCH_PART_ENUM(ident::PhaseVerdict, "phase verdict", ident::phase_verdict_from_string)
PIEZOBENCH_PART_ENUM(ident::Convergence, "vector fitting convergence", ident::convergence_from_string)
PIEZOBENCH_PART_ENUM(core::LmStatus, "Levenberg-Marquardt status", core::lm_status_from_string)
PIEZOBENCH_PART_ENUM(core::FitVerdict, "fit verdict", core::fit_verdict_from_string)
PIEZOBENCH_PART_ENUM(apa::TuningStatus, "tuning status", apa::tuning_status_from_string)
#undef PIEZOBENCH_PART_ENUM

template <class T> json encode(const T& v);
template <class T> void decode(const json& j, T& v, const Where& w);

struct Writer {
  json& out;
  template <class T> void operator()(const char* key, const T& v) { out[key] = encode(v); }
};

struct PartReader {
  const json& in;
  Where where;
  template <class T> void operator()(const char* key, T& v) {
    const Where w = where.key(key);
    if (!in.contains(key)) throw InputError(w.file, w.path, "present", "missing");
    decode(in[key], v, w);
  }
};

template <class T> json encode(const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    return io::to_json(v);
  } else if constexpr (std::is_same_v<T, bool> || std::is_integral_v<T> || std::is_same_v<T, std::string>) {
    return v;
  } else if constexpr (std::is_enum_v<T>) {
    return enum_name(v);
  } else if constexpr (IsComplex<T>::value) {
    return json::array({encode(v.real()), encode(v.imag())});
  } else if constexpr (IsOptional<T>::value) {
    return v ? encode(*v) : json(nullptr);
  } else if constexpr (IsVector<T>::value || IsStdArray<T>::value) {
    json a = json::array();
    for (const auto& x : v) a.push_back(encode(x));
    return a;
  } else if constexpr (IsPair<T>::value) {
    return json::array({encode(v.first), encode(v.second)});
  } else if constexpr (kIsEigen<T>) {
    json a = json::array();
    if constexpr (T::ColsAtCompileTime == 1) {
      for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(encode(v(i)));
    } else {
      for (Eigen::Index r = 0; r < v.rows(); ++r) {
        json row = json::array();
        for (Eigen::Index c = 0; c < v.cols(); ++c) row.push_back(encode(v(r, c)));
        a.push_back(row);
      }
    }
    return a;
  } else {
    json o = json::object();
    Writer w{o};
    fields(w, const_cast<T&>(v));
    return o;
  }
}

template <class T> void decode(const json& j, T& v, const Where& w) {
  if constexpr (std::is_same_v<T, double>) {
    if (j.is_number()) {
      v = j.get<double>();
    } else if (j == "nan") {
      v = std::numeric_limits<double>::quiet_NaN();
    } else if (j == "inf" || j == "-inf") {
      v = (j == "inf" ? 1.0 : -1.0) * std::numeric_limits<double>::infinity();
    } else {
      bad(w, "a number (or \"nan\", \"inf\", \"-inf\")", j);
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!j.is_boolean()) bad(w, "true or false", j);
    v = j.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    if (!j.is_number_integer()) bad(w, "an integer", j);
    v = j.get<T>();
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!j.is_string()) bad(w, "a string", j);
    v = j.get<std::string>();
  } else if constexpr (std::is_enum_v<T>) {
    if (!j.is_string()) bad(w, std::string("a ") + enum_label(v) + " name", j);
    try {
      enum_parse(j.get<std::string>(), v);
    } catch (const InputError&) {
      bad(w, std::string("a ") + enum_label(v) + " name", j);
    }
  } else if constexpr (IsComplex<T>::value) {
    if (!j.is_array() || j.size() != 2) bad(w, "a complex number [re, im]", j);
    double re = 0.0, im = 0.0;
    decode(j[0], re, w.index(0));
    decode(j[1], im, w.index(1));
    v = T(re, im);
  } else if constexpr (IsOptional<T>::value) {
    if (j.is_null()) {
      v.reset();
    } else {
      v = typename T::value_type{};  // not emplace(): clang 14 takes NmpEvidence::Zero for not default-constructible
      decode(j, *v, w);
    }
  } else if constexpr (IsVector<T>::value) {
    if (!j.is_array()) bad(w, "a list", j);
    v.clear();
    v.resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) decode(j[i], v[i], w.index(i));
  } else if constexpr (IsStdArray<T>::value) {
    if (!j.is_array() || j.size() != v.size()) bad(w, fmt::format("a list of {}", v.size()), j);
    for (std::size_t i = 0; i < v.size(); ++i) decode(j[i], v[i], w.index(i));
  } else if constexpr (IsPair<T>::value) {
    if (!j.is_array() || j.size() != 2) bad(w, "a pair [first, second]", j);
    decode(j[0], v.first, w.index(0));
    decode(j[1], v.second, w.index(1));
  } else if constexpr (kIsEigen<T>) {
    if (!j.is_array()) bad(w, "a list", j);
    const auto n = static_cast<Eigen::Index>(j.size());
    if constexpr (T::ColsAtCompileTime == 1) {
      v.resize(n);
      for (Eigen::Index i = 0; i < n; ++i) decode(j[i], v(i), w.index(i));
    } else {
      const Eigen::Index cols = n > 0 && j[0].is_array() ? static_cast<Eigen::Index>(j[0].size()) : 0;
      v.resize(n, cols);
      for (Eigen::Index r = 0; r < n; ++r) {
        const Where wr = w.index(r);
        if (!j[r].is_array() || static_cast<Eigen::Index>(j[r].size()) != cols) bad(wr, fmt::format("a row of {} values", cols), j[r]);
        for (Eigen::Index c = 0; c < cols; ++c) decode(j[r][c], v(r, c), wr.index(c));
      }
    }
  } else {
    if (!j.is_object()) bad(w, "an object", j);
    PartReader r{j, w};
    fields(r, v);
  }
}

// ------------------------------------------------------------------------------------ fields
// Every field of every struct a UnitAnalysis holds (results.hpp and the modules' result types).

template <class V> void fields(V& v, core::FitQuality& s) {
  v("verdict", s.verdict); v("impossible", s.impossible); v("problems", s.problems); v("advice", s.advice);
}
template <class V> void fields(V& v, RecordProvenance& s) {
  v("file", s.file); v("key", s.key); v("channels", s.channels); v("samples", s.samples);
  v("sample_rate_Hz", s.sample_rate_Hz); v("input", s.input); v("outputs", s.outputs);
}
template <class V> void fields(V& v, Curve& s) { v("x", s.x); v("y", s.y); }
template <class V> void fields(V& v, FlatnessAnalysis::Interface& s) { v("id", s.id); v("least_squares", s.least_squares); }
template <class V> void fields(V& v, FlatnessAnalysis& s) {
  v("method", s.method); v("flatness", s.flatness); v("least_squares", s.least_squares); v("minimum_zone", s.minimum_zone);
  v("points", s.points); v("per_interface", s.per_interface); v("probe_accuracy", s.probe_accuracy);
  v("provenance", s.provenance); v("deviation", s.deviation); v("probe_xy", s.probe_xy);
}
template <class V> void fields(V& v, CapacitanceAnalysis& s) {
  v("sensor", s.sensor); v("actuator", s.actuator); v("provenance", s.provenance); v("key", s.key);
}
template <class V> void fields(V& v, metrology::StrokeResult& s) {
  v("stroke", s.stroke); v("va_min", s.va_min); v("va_max", s.va_max); v("sensitivity", s.sensitivity); v("loop_width", s.loop_width);
}
template <class V> void fields(V& v, StrokeAnalysis& s) { v("result", s.result); v("provenance", s.provenance); v("de_vs_va", s.de_vs_va); }
template <class V> void fields(V& v, metrology::HysteresisResult& s) {
  v("offset", s.offset); v("amplitude", s.amplitude); v("width", s.width); v("loop_stroke", s.loop_stroke);
  v("relative_width", s.relative_width); v("periods", s.periods); v("first_sample", s.first_sample); v("samples", s.samples);
}
template <class V> void fields(V& v, HysteresisLoop& s) { v("result", s.result); v("provenance", s.provenance); v("loop", s.loop); }
template <class V> void fields(V& v, ident::PrandtlIshlinskii& s) {
  v("linear_weight", s.linear_weight); v("thresholds", s.thresholds); v("weights", s.weights);
}
template <class V> void fields(V& v, ident::DeadZoneSuperposition& s) {
  v("x", s.x); v("y", s.y); v("slope_below", s.slope_below); v("slope_above", s.slope_above);
}
template <class V> void fields(V& v, ident::HysteresisModel& s) {
  v("hysteresis", s.hysteresis); v("output", s.output); v("creep_time_constants", s.creep_time_constants); v("creep_coefficients", s.creep_coefficients);
  v("gain", s.gain); v("offset", s.offset); v("reference_slope", s.reference_slope); v("reference_intercept", s.reference_intercept);
  v("input_min", s.input_min); v("input_max", s.input_max);
}
template <class V> void fields(V& v, ident::HysteresisFit& s) {
  v("model", s.model); v("rms_residual", s.rms_residual); v("relative_residual", s.relative_residual); v("stroke", s.stroke);
  v("samples", s.samples); v("quality", s.quality);
}
template <class V> void fields(V& v, HysteresisModelFit& s) {
  v("fit", s.fit); v("alternative", s.alternative); v("alternative_error", s.alternative_error); v("asymmetry", s.asymmetry);
  v("amplitude", s.amplitude); v("width", s.width); v("model_width", s.model_width); v("provenance", s.provenance);
  v("loop", s.loop); v("model_loop", s.model_loop);
}
template <class V> void fields(V& v, bench::TrackingFigures& s) {
  v("width_open", s.width_open); v("width_ff", s.width_ff); v("rms_open", s.rms_open); v("rms_ff", s.rms_ff); v("stroke_open", s.stroke_open);
}
template <class V> void fields(V& v, TrackingAnalysis& s) {
  v("sine", s.sine); v("triangle", s.triangle); v("amplitude", s.amplitude); v("feedforward", s.feedforward);
  v("clamped_samples", s.clamped_samples); v("provenance", s.provenance); v("sine_open", s.sine_open); v("sine_ff", s.sine_ff);
  v("triangle_open", s.triangle_open); v("triangle_ff", s.triangle_ff);
}
template <class V> void fields(V& v, metrology::StaticStiffnessResult& s) {
  v("t_on", s.t_on); v("t_off", s.t_off); v("d_before", s.d_before); v("d_loaded", s.d_loaded); v("d_after", s.d_after);
  v("k1", s.k1); v("k2", s.k2); v("deflection_on", s.deflection_on); v("deflection_off", s.deflection_off);
  v("k_elastic_on", s.k_elastic_on); v("k_elastic_off", s.k_elastic_off); v("creep_on", s.creep_on); v("creep_off", s.creep_off);
  v("creep_time_constant", s.creep_time_constant); v("rms_residual", s.rms_residual); v("fit", s.fit);
}
template <class V> void fields(V& v, metrology::StaticStiffnessOptions& s) {
  v("added_mass", s.added_mass); v("gravity", s.gravity); v("settle_s", s.settle_s); v("before_s", s.before_s);
  v("loaded_s", s.loaded_s); v("after_s", s.after_s); v("t_on", s.t_on); v("t_off", s.t_off);
  v("min_time_constant", s.min_time_constant); v("max_time_constant", s.max_time_constant);
}
template <class V> void fields(V& v, ident::CreepFit& s) {
  v("time_constants", s.time_constants); v("coefficients", s.coefficients); v("gain", s.gain); v("offset", s.offset);
  v("creep_per_decade", s.creep_per_decade); v("rms_residual", s.rms_residual); v("relative_residual", s.relative_residual);
  v("quality", s.quality);
}
template <class V> void fields(V& v, StiffnessAnalysis& s) {
  v("result", s.result); v("options", s.options); v("mass_log", s.mass_log); v("provenance", s.provenance); v("de", s.de); v("fit", s.fit);
  v("creep", s.creep);
}
template <class V> void fields(V& v, VectorFitSummary& s) { v("order", s.order); v("relative_rms_error", s.relative_rms_error); v("converged", s.converged); }
template <class V> void fields(V& v, NmpEvidence::Zero& s) {
  v("phase_verdict", s.phase_verdict); v("phase_change_deg", s.phase_change_deg); v("fitted_zero", s.fitted_zero);
  v("fitted_zero_nonminimum_phase", s.fitted_zero_nonminimum_phase);
}
template <class V> void fields(V& v, NmpEvidence& s) { v("zero", s.zero); v("iff_plant_fit_xz", s.iff_plant_fit_xz);
  v("iff_plant_fit_xz_standard_error", s.iff_plant_fit_xz_standard_error); v("verdict_from", s.verdict_from); v("verdict_reason", s.verdict_reason); }
template <class V> void fields(V& v, HighPassCorner& s) {
  v("first_order_fit_Hz", s.first_order_fit_Hz); v("first_order_fit_points", s.first_order_fit_points); v("r_c_Hz", s.r_c_Hz);
  v("iff_plant_fit_Hz", s.iff_plant_fit_Hz); v("iff_plant_fit_error", s.iff_plant_fit_error); v("method", s.method); v("observable_above_Hz", s.observable_above_Hz); v("corner_Hz", s.corner_Hz);
}
template <class V> void fields(V& v, dsp::FrfProvenance& s) {
  v("source", s.source); v("estimator", s.estimator); v("window", s.window); v("nfft", s.nfft); v("overlap", s.overlap);
  v("detrend", s.detrend); v("averages", s.averages); v("sample_rate", s.sample_rate); v("effective_averages", s.effective_averages);
}
template <class V> void fields(V& v, dsp::Frf& s) {
  v("freq_Hz", s.freq_Hz); v("input", s.input); v("outputs", s.outputs); v("H", s.H); v("coherence", s.coherence); v("std_H", s.std_H);
  v("provenance", s.provenance);
}
template <class V> void fields(V& v, core::ParameterUncertainty& s) {
  v("names", s.names); v("value", s.value); v("standard_error", s.standard_error); v("correlation", s.correlation);
  v("condition_number", s.condition_number); v("chi2_per_dof", s.chi2_per_dof); v("from_data_variance", s.from_data_variance);
  v("high_correlations", s.high_correlations);
}
template <class V> void fields(V& v, ident::DelayedSecondOrderFit& s) {
  v("static_gain", s.static_gain); v("natural_frequency", s.natural_frequency); v("damping", s.damping); v("delay", s.delay);
  v("relative_rms_error", s.relative_rms_error); v("points", s.points); v("iterations", s.iterations); v("status", s.status); v("quality", s.quality);
  v("uncertainty", s.uncertainty);
}
template <class V> void fields(V& v, ident::IffPlantFit& s) {
  v("g0", s.g0); v("wz", s.wz); v("xz", s.xz); v("wp", s.wp); v("xp", s.xp); v("w_hpf", s.w_hpf); v("delay", s.delay);
  v("relative_rms_error", s.relative_rms_error); v("weighted_relative_rms_error", s.weighted_relative_rms_error);
  v("initial_relative_rms_error", s.initial_relative_rms_error); v("points", s.points); v("iterations", s.iterations);
  v("converged", s.converged); v("status", s.status); v("quality", s.quality); v("uncertainty", s.uncertainty);
}
template <class V> void fields(V& v, FrfAnalysis& s) {
  v("provenance", s.provenance); v("welch", s.welch); v("fit_de", s.fit_de); v("fit_vs", s.fit_vs);
  v("static_gain_vector_fit", s.static_gain_vector_fit); v("static_gain", s.static_gain); v("static_gain_source", s.static_gain_source);
  v("static_gain_vs", s.static_gain_vs); v("de_plant", s.de_plant); v("iff_plant", s.iff_plant); v("iff_plant_fmin_Hz", s.iff_plant_fmin_Hz);
  v("iff_plant_fmax_Hz", s.iff_plant_fmax_Hz); v("iff_plant_w_hpf_measured", s.iff_plant_w_hpf_measured); v("nmp", s.nmp); v("hpf", s.hpf);
  v("resonance_vector_fit_Hz", s.resonance_vector_fit_Hz); v("resonance_vector_fit_damping", s.resonance_vector_fit_damping);
  v("antiresonance_vector_fit_Hz", s.antiresonance_vector_fit_Hz); v("antiresonance_vector_fit_damping", s.antiresonance_vector_fit_damping);
  v("resonance_Hz", s.resonance_Hz); v("resonance_damping", s.resonance_damping); v("antiresonance_Hz", s.antiresonance_Hz);
  v("antiresonance_damping", s.antiresonance_damping); v("zero_is_nonminimum_phase", s.zero_is_nonminimum_phase);
  v("shell_stiffness", s.shell_stiffness);
}
template <class V> void fields(V& v, apa::TwoDofParams& s) {
  v("m", s.m); v("k1", s.k1); v("c1", s.c1); v("ke", s.ke); v("ce", s.ce); v("ka", s.ka); v("ca", s.ca); v("ga", s.ga); v("gs", s.gs);
}
template <class V> void fields(V& v, apa::TuningFeatures& s) {
  v("resonance", s.resonance); v("resonance_damping", s.resonance_damping); v("antiresonance", s.antiresonance);
  v("antiresonance_damping", s.antiresonance_damping); v("static_gain_de", s.static_gain_de); v("static_gain_vs", s.static_gain_vs);
}
template <class V> void fields(V& v, apa::TwoDofBench& s) {
  v("amplifier_gain", s.amplifier_gain); v("suspended_mass", s.suspended_mass); v("added_mass", s.added_mass);
  v("hpf_resistance", s.hpf_resistance); v("hpf_capacitance", s.hpf_capacitance); v("delay", s.delay);
}
template <class V> void fields(V& v, apa::TwoDofTuning& s) {
  v("params", s.params); v("initial", s.initial); v("features", s.features); v("bench", s.bench); v("fit_error_de", s.fit_error_de);
  v("fit_error_vs", s.fit_error_vs); v("initial_fit_error_de", s.initial_fit_error_de); v("initial_fit_error_vs", s.initial_fit_error_vs);
  v("points", s.points); v("iterations", s.iterations); v("status", s.status); v("message", s.message); v("quality", s.quality);
  v("uncertainty", s.uncertainty); v("undetermined", s.undetermined);
}
template <class V> void fields(V& v, Model2DofFit& s) { v("tuning", s.tuning); v("bench", s.bench); v("fmin_Hz", s.fmin_Hz); v("fmax_Hz", s.fmax_Hz); }
template <class V> void fields(V& v, LowFrequencyVs& s) {
  v("provenance", s.provenance); v("frf", s.frf); v("lowest_line_Hz", s.lowest_line_Hz); v("fmax_Hz", s.fmax_Hz);
  v("fitted_corner_Hz", s.fitted_corner_Hz); v("relative_rms_error", s.relative_rms_error); v("points", s.points); v("observable", s.observable);
}
template <class V> void fields(V& v, ResistorComparison& s) { v("with_resistor", s.with_resistor); v("without_resistor", s.without_resistor); }
// The state space `model` is left out (see part.hpp): evaluate() uses the poles and residues.
template <class V> void fields(V& v, ident::VectorFittingResult& s) {
  v("poles", s.poles); v("residues", s.residues); v("d", s.d); v("e", s.e); v("rms_error", s.rms_error);
  v("relative_rms_error", s.relative_rms_error); v("relative_rms_error_per_output", s.relative_rms_error_per_output);
  v("quality", s.quality); v("iterations", s.iterations); v("converged", s.converged); v("convergence", s.convergence);
  v("last_pole_change", s.last_pole_change); v("frequency_scale", s.frequency_scale);
}
template <class V> void fields(V& v, ident::DominantPole& s) {
  v("pole", s.pole); v("natural_frequency", s.natural_frequency); v("damping", s.damping); v("peak", s.peak); v("fit", s.fit);
}
template <class V> void fields(V& v, DampedPlant& s) {
  v("gain", s.gain); v("file", s.file); v("provenance", s.provenance); v("frf", s.frf); v("identified", s.identified);
  v("identified_order", s.identified_order); v("fmin_Hz", s.fmin_Hz); v("fmax_Hz", s.fmax_Hz); v("second_order", s.second_order);
  v("delay_removed", s.delay_removed);
}
template <class V> void fields(V& v, FlexibleModes::Mode& s) { v("frequency_Hz", s.frequency_Hz); v("damping", s.damping); v("stable_orders", s.stable_orders); }
template <class V> void fields(V& v, FlexibleModes& s) {
  v("provenance", s.provenance); v("welch", s.welch); v("peak_picking", s.peak_picking); v("lscf", s.lscf); v("frf", s.frf);
}
template <class V> void fields(V& v, NotAnalysed& s) { v("file", s.file); v("key", s.key); v("reason", s.reason); }
template <class V> void fields(V& v, UnitAnalysis& s) {
  v("id", s.id); v("name", s.name); v("not_analysed", s.not_analysed); v("flatness_analysis", s.flatness_analysis); v("capacitance_analysis", s.capacitance_analysis);
  v("stroke_analysis", s.stroke_analysis); v("hysteresis", s.hysteresis); v("hysteresis_model", s.hysteresis_model); v("tracking", s.tracking);
  v("stiffness_analysis", s.stiffness_analysis);
  v("stiffness_open_analysis", s.stiffness_open_analysis); v("frf_analysis", s.frf_analysis); v("resistor", s.resistor);
  v("model_2dof", s.model_2dof); v("damped", s.damped); v("flexible_modes", s.flexible_modes); v("flatness", s.flatness);
  v("capacitance_sensor", s.capacitance_sensor); v("capacitance_actuator", s.capacitance_actuator); v("stroke", s.stroke);
  v("k1", s.k1); v("k2", s.k2); v("k_resonance", s.k_resonance); v("k_oc", s.k_oc); v("resonance_Hz", s.resonance_Hz);
  v("antiresonance_Hz", s.antiresonance_Hz); v("static_gain", s.static_gain); v("frf", s.frf); v("iff_plant", s.iff_plant);
  v("de_plant", s.de_plant); v("not_measured", s.not_measured); v("failed", s.failed); v("warnings", s.warnings); v("accepted", s.accepted); v("reasons", s.reasons);
}

std::string generator() { return std::string("piezobench ") + kVersion; }

std::string units_text(const std::vector<int>& ids) {
  std::string s;
  for (const int id : ids) s += (s.empty() ? "" : ", ") + std::to_string(id);
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------------ public

std::string campaign_hash(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "campaign", "a readable campaign file", "cannot be opened");
  std::uint64_t h = 14695981039346656037ULL;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ULL;
    }
  }
  return fmt::format("fnv1a64:{:016x}", h);
}

std::vector<std::size_t> part_indices(const Campaign& c, int k, int n) {
  if (n < 1 || k < 1 || k > n) throw InputError("", "--part", "K/N with 1 <= K <= N", fmt::format("{}/{}", k, n));
  std::vector<std::size_t> out;
  for (std::size_t i = static_cast<std::size_t>(k - 1); i < c.units.size(); i += static_cast<std::size_t>(n)) out.push_back(i);
  return out;
}

std::vector<std::size_t> unit_indices(const Campaign& c, const std::vector<int>& ids, const std::string& option) {
  std::vector<int> all;
  for (const auto& u : c.units) all.push_back(u.id);
  for (const int id : ids) {
    if (std::find(all.begin(), all.end(), id) == all.end()) {
      throw InputError(c.file.string(), option, "unit ids of the campaign (" + units_text(all) + ")", std::to_string(id));
    }
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < c.units.size(); ++i) {
    if (std::find(ids.begin(), ids.end(), c.units[i].id) != ids.end()) out.push_back(i);
  }
  return out;
}

json typed_unit_json(const UnitAnalysis& unit) { return encode(unit); }

UnitAnalysis typed_unit_from_json(const json& j, const std::string& source, const std::string& path) {
  UnitAnalysis u;
  decode(j, u, Where{source, path});
  return u;
}

json part_json(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  json ids = json::array();
  for (const auto& u : c.units) ids.push_back(u.id);
  json list = json::array();
  for (const auto& u : units) list.push_back(typed_unit_json(u));
  return {{"format", kFormat},
          {"format_version", kPartFormatVersion},
          {"generator", generator()},
          {"campaign", c.file.string()},
          {"campaign_path", fs::absolute(c.file).lexically_normal().string()},
          {"campaign_hash", campaign_hash(c.file)},
          {"campaign_units", ids},
          {"units", list}};
}

fs::path write_part(const Campaign& c, const std::vector<UnitAnalysis>& units, const fs::path& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    throw InputError(out_dir.string(), "--out", "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  const fs::path file = out_dir / "part.json";
  io::write_text_atomically(file, part_json(c, units).dump() + "\n");
  return file;
}

CampaignPart read_part(const fs::path& path) {
  const fs::path file = fs::is_directory(path) ? path / "part.json" : path;
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw InputError(path.string(), "part.json", "a partial result of `piezobench run --part K/N` or `--units LIST`",
                     fs::exists(path) ? "no part.json in it" : "no such file or folder");
  }
  std::ostringstream text;
  text << in.rdbuf();
  json doc;
  try {
    doc = json::parse(text.str());
  } catch (const json::exception& e) {
    throw InputError(name, "", "a JSON document (part.json)", e.what());
  }
  const Where top{name, ""};
  if (!doc.is_object() || !doc.contains("format") || doc["format"] != kFormat) {
    throw InputError(name, "format", fmt::format("\"{}\" (a part.json of `piezobench run --part/--units`)", kFormat),
                     doc.is_object() && doc.contains("format") ? doc["format"].dump() : "no format key");
  }
  int version = 0;
  PartReader r{doc, top};
  r("format_version", version);
  if (version != kPartFormatVersion) throw InputError(name, "format_version", std::to_string(kPartFormatVersion), std::to_string(version));
  CampaignPart p;
  p.file = file;
  r("generator", p.generator);
  if (p.generator != generator()) {
    throw InputError(name, "generator", generator() + " (parts are merged by the program that wrote them)", p.generator);
  }
  std::string campaign_path;
  r("campaign", p.campaign);
  r("campaign_path", campaign_path);
  p.campaign_path = campaign_path;
  r("campaign_hash", p.campaign_hash);
  r("campaign_units", p.campaign_units);
  r("units", p.units);
  return p;
}

std::vector<UnitAnalysis> merge_parts(const Campaign& c, const std::vector<CampaignPart>& parts) {
  const std::string campaign_file = c.file.string();
  const std::string hash = campaign_hash(c.file);
  std::map<int, std::pair<const UnitAnalysis*, const CampaignPart*>> found;
  for (const CampaignPart& p : parts) {
    const std::string name = p.file.string();
    if (p.campaign_hash != hash) {
      throw InputError(name, "campaign_hash",
                       fmt::format("{} (campaign {} as it is now)", hash, campaign_file),
                       fmt::format("{} (campaign {}): a part of another campaign, or of this file before it changed", p.campaign_hash, p.campaign));
    }
    for (std::size_t i = 0; i < p.units.size(); ++i) {
      const UnitAnalysis& u = p.units[i];
      const bool known = std::any_of(c.units.begin(), c.units.end(), [&](const UnitSpec& s) { return s.id == u.id; });
      if (!known) throw InputError(name, fmt::format("units[{}].id", i), "a unit of campaign " + campaign_file, std::to_string(u.id));
      const auto [it, inserted] = found.emplace(u.id, std::pair{&u, &p});
      if (!inserted) {
        throw InputError(name, fmt::format("units[{}].id", i), "a unit no other part holds",
                         fmt::format("unit {} ({}), also in {}", u.id, u.name, it->second.second->file.string()));
      }
    }
  }
  std::vector<UnitAnalysis> out;
  std::vector<int> missing;
  for (const UnitSpec& s : c.units) {
    const auto it = found.find(s.id);
    if (it == found.end()) {
      missing.push_back(s.id);
    } else {
      out.push_back(*it->second.first);
    }
  }
  if (!missing.empty()) {
    throw InputError(campaign_file, "units", fmt::format("every unit of the campaign in one of the {} parts", parts.size()),
                     fmt::format("unit{} {} in none of them", missing.size() > 1 ? "s" : "", units_text(missing)));
  }
  return out;
}

}  // namespace piezobench::campaign
