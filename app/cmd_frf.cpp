// `piezobench frf` (Welch H1/H2 FRFs and coherence from a time-series file) and `piezobench fit`
// (vector fitting of an FRF file).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/vector_fit_uncertainty.hpp"
#include "piezobench/ident/vector_fitting.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/io/lti_toml.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/io/units.hpp"
#include "piezobench/lti/analysis.hpp"

namespace piezobench::app {
namespace {

struct FrfOptions {
  std::string file;
  std::string input;
  std::string outputs;
  double fs = 0.0;
  std::string window = "hann";
  Eigen::Index nfft = 0;       // 0: from the record and the resolution (as `run`)
  double resolution = 0.25;    // Hz, target bin width when nfft is 0
  double overlap = 0.5;
  std::string detrend = "mean";
  std::string estimator = "H1";
  std::string out;
  bool json = false;
  std::string delimiter = "auto";  // CSV input only
  std::string decimal = "auto";
  std::string units;               // --units de=um,Vs=mV
};

// The unit of H = output / input from the SI symbols of the record ("m/V"; "" when neither is known).
std::string h_unit(const std::string& output_unit, const std::string& input_unit) {
  if (output_unit.empty() && input_unit.empty()) return "";
  const io::Unit num = output_unit.empty() ? io::Unit{} : io::unit_from_string(output_unit, "", "unit");
  const io::Unit den = input_unit.empty() ? io::Unit{} : io::unit_from_string(input_unit, "", "unit");
  const std::string symbol = io::divide(num, den).si_symbol;
  const auto wrap = [](const std::string& u) { return u.find('/') == std::string::npos ? u : "(" + u + ")"; };
  if (symbol.empty() && !output_unit.empty() && !input_unit.empty()) return wrap(output_unit) + "/" + wrap(input_unit);  // V/V
  return symbol.empty() ? "1" : symbol;
}

nlohmann::json frf_json(const dsp::Frf& frf) {
  nlohmann::json outputs = nlohmann::json::object();
  for (std::size_t i = 0; i < frf.outputs.size(); ++i) {
    nlohmann::json o = {{"H", io::to_json(frf.H[i])}};
    if (i < frf.coherence.size() && frf.coherence[i].size() > 0) o["coherence"] = io::to_json(frf.coherence[i]);
    if (i < frf.std_H.size() && frf.std_H[i].size() > 0) o["std"] = io::to_json(frf.std_H[i]);
    outputs[frf.outputs[i]] = std::move(o);
  }
  // Welch's settings from dsp::FrfProvenance's declaration (estimator, nfft, overlap, detrend,
  // averages; the window below as an object); the fields its declaration keeps out of results.json
  // (source, sample rate, effective averages) and the FRF itself, whose outputs this document keys by name.
  const auto& p = frf.provenance;
  nlohmann::json doc = io::results_object(p);
  doc["window"] = {{"name", p.window}, {"length", p.nfft}, {"periodic", p.window.find("periodic") != std::string::npos}};
  doc["source"] = p.source;
  doc["input"] = frf.input;
  doc["freq_Hz"] = io::to_json(frf.freq_Hz);
  doc["effective_averages"] = io::to_json(p.effective_averages);
  doc["sample_rate_Hz"] = p.sample_rate;
  doc["outputs"] = std::move(outputs);
  return doc;
}

int run_frf(const FrfOptions& o) {
  io::ReadOptions read;
  read.fs = o.fs;
  const std::vector<std::string> output_names = split_list(o.outputs, "--output");
  // The input may be an output too (H = 1: a single-channel file still gives its spectrum's FRF).
  read.channels = {o.input};
  for (const std::string& name : output_names) {
    if (std::find(read.channels.begin(), read.channels.end(), name) == read.channels.end()) read.channels.push_back(name);
  }
  read.delimiter = io::csv_delimiter_from_string(o.delimiter);
  read.decimal = io::csv_decimal_from_string(o.decimal);
  read.unit_overrides = parse_units(o.units);
  if (!o.json) log_line("reading " + o.file);
  // One pass over the samples: a large v5 record is used in place from the file's mapping, its
  // channels checked for NaN/Inf by the estimate's own pass (dsp::estimate_frf).
  const io::TimeSeriesView ts = io::read_timeseries_view(o.file, read, io::FiniteCheck::kCaller);
  print_warnings(ts.warnings);
  // The settings `run` uses for a record (dsp::welch_options_for_record), then the options given.
  dsp::WelchOptions welch = dsp::welch_options_for_record(ts.samples, ts.sample_rate, o.resolution, "--resolution");
  welch.window = dsp::window_type_from_string(o.window);
  if (o.nfft > 0) {
    welch.nfft = o.nfft;
  } else if (welch.nfft > ts.samples) {
    // A record shorter than `run`'s 256-sample minimum (UFF examples hold 13 or 250 samples):
    // four segments of a quarter of it, 8 samples at least.
    welch.nfft = std::min<Eigen::Index>(ts.samples, std::max<Eigen::Index>(8, ts.samples / 4));
    if (!o.json) log_line(fmt::format("a short record ({} samples): nfft {} (--nfft to choose)", ts.samples, welch.nfft));
  }
  welch.overlap = o.overlap;
  welch.detrend = dsp::detrend_from_string(o.detrend);
  welch.estimator = dsp::frf_estimator_from_string(o.estimator);
  welch.validate("command line");

  std::vector<dsp::Channel> outputs;
  const auto column = [&](const std::string& name) { return ts.columns[static_cast<std::size_t>(ts.index(name))]; };
  for (const std::string& name : output_names) outputs.push_back({name, {column(name), static_cast<std::size_t>(ts.samples)}});
  const dsp::Channel input{o.input, {column(o.input), static_cast<std::size_t>(ts.samples)}};
  if (!o.json) {
    log_line(fmt::format("{} samples at {:g} Hz, nfft {} ({:.4g} Hz bins), {} outputs", ts.samples, ts.sample_rate, welch.nfft,
                         ts.sample_rate / static_cast<double>(welch.nfft), outputs.size()));
  }
  const dsp::FrfEstimate estimate = dsp::estimate_frf(input, outputs, ts.sample_rate, welch, o.file);
  // The verdict before any output, so that the exit code is the same whatever --json and --out
  // say: a record whose input excited nothing (no band of coherence >= 0.5) is refused (exit 3)
  // and no file is written.
  const dsp::FrequencyBand band = dsp::excited_band(estimate.frf, 0.5);

  if (!o.out.empty()) {
    io::FrfWriteOptions wo;
    if (!ts.units.empty()) {
      for (const std::string& name : estimate.frf.outputs) wo.output_units.push_back(ts.unit(name));
      wo.input_unit = ts.unit(o.input);
    }
    io::write_frf(estimate.frf, o.out, wo);
    if (!o.json) log_line("wrote " + o.out);
  }
  if (o.json) {
    // Units of the SI samples the reader returned ("" where the file gave none): H is output / input.
    nlohmann::json document = frf_json(estimate.frf);
    nlohmann::json units = nlohmann::json::object();
    for (const std::string& name : estimate.frf.outputs) {
      const std::string num = ts.unit(name), den = ts.unit(o.input);
      units[name] = (num.empty() ? "1" : num) + "/" + (den.empty() ? "1" : den);
    }
    document["H_units"] = std::move(units);
    document["warnings"] = ts.warnings;
    print_json(document);
    return 0;
  }
  const dsp::Frf& frf = estimate.frf;
  fmt::print("FRF {} of {} -> {}: {} averages, window {} ({} samples), {:.4g} Hz resolution\n",
             frf.provenance.estimator, frf.input, fmt::join(frf.outputs, ", "), frf.provenance.averages,
             frf.provenance.window, frf.provenance.nfft, frf.freq_Hz.size() > 1 ? frf.freq_Hz(1) - frf.freq_Hz(0) : 0.0);
  // The summary covers the band the input excited (coherence >= 0.5), not the noise around it.
  fmt::print("excited band (coherence >= 0.5): {:.4g} to {:.4g} Hz\n", band.fmin_Hz, band.fmax_Hz);
  for (std::size_t i = 0; i < frf.outputs.size(); ++i) {
    Eigen::Index peak = -1;
    double coh_sum = 0.0;
    int count = 0;
    for (Eigen::Index k = 0; k < frf.freq_Hz.size(); ++k) {
      if (frf.freq_Hz(k) < band.fmin_Hz || frf.freq_Hz(k) > band.fmax_Hz) continue;
      if (peak < 0 || std::abs(frf.H[i](k)) > std::abs(frf.H[i](peak))) peak = k;
      coh_sum += frf.coherence[i](k);
      ++count;
    }
    const std::string unit = h_unit(ts.unit(frf.outputs[i]), ts.unit(o.input));
    fmt::print("  {}: peak |H| {:.4g} {} at {:.4g} Hz, mean coherence {:.3f} in the band\n", frf.outputs[i], std::abs(frf.H[i](peak)),
               unit.empty() ? "(no unit: SI assumed)" : unit, frf.freq_Hz(peak), count > 0 ? coh_sum / count : 0.0);
  }
  return 0;
}

struct FitOptions {
  std::string file;
  Eigen::Index order = 6;
  double fmin = 0.0;
  double fmax = 0.0;
  std::string outputs;
  std::string asymptote = "d";
  std::string weighting = "output-scale";
  int max_iterations = 50;
  std::string out;
  bool json = false;
  std::string units;  // --units
};

// The part of an FRF inside [fmin, fmax], for the named outputs (empty = all). Without --fmin and
// --fmax: the band the input excited (dsp::excited_band, coherence >= 0.5), as `run` and
// `model tune`; a bound given alone keeps the other one open.
dsp::Frf select_band(const dsp::Frf& frf, FitOptions o) {
  if (o.fmin < 0.0 || (o.fmax > 0.0 && o.fmax <= o.fmin)) {
    throw UsageError("--fmin/--fmax", "0 <= fmin < fmax",
                     fmt::format("fmin {}, fmax {}", format_number_exact(o.fmin), format_number_exact(o.fmax)));
  }
  if (o.fmin == 0.0 && o.fmax == 0.0) {
    const dsp::FrequencyBand excited = dsp::excited_band(frf, 0.5);
    if (excited.from_coherence) {
      o.fmin = excited.fmin_Hz;
      o.fmax = excited.fmax_Hz;
      if (!o.json) log_line(fmt::format("band {:.4g} to {:.4g} Hz: where the coherence is at least 0.5 (--fmin/--fmax to choose)", o.fmin, o.fmax));
    }
  }
  dsp::BandSelection selection;
  selection.fmin_Hz = o.fmin;
  selection.fmax_Hz = o.fmax;
  if (!o.outputs.empty()) {
    for (const auto& name : split_list(o.outputs, "--output")) selection.outputs.push_back(frf.output_index(name));
  }
  dsp::Frf band = dsp::select_band(frf, selection);
  if (band.freq_Hz.size() == 0) {
    throw InputError(
        o.file, "freq_Hz",
        fmt::format("frequencies inside [{}, {}] Hz", format_number_exact(o.fmin), format_number_exact(o.fmax)),
        "none");
  }
  return band;
}

// The zeros of output i of the fitted model (its proper part), with Im >= 0, by frequency.
std::vector<lti::Complex> output_zeros(const ident::VectorFittingResult& r, Eigen::Index i) {
  lti::StateSpace one = r.model;
  one.C = r.model.C.row(i);
  one.D = r.model.D.row(i);
  const lti::CVector z = lti::zeros(one);
  std::vector<lti::Complex> out;
  for (Eigen::Index k = 0; k < z.size(); ++k) {
    if (z(k).imag() >= 0.0 && std::isfinite(std::abs(z(k)))) out.push_back(z(k));
  }
  std::sort(out.begin(), out.end(), [](lti::Complex a, lti::Complex b) { return std::abs(a) < std::abs(b); });
  return out;
}

struct ZeroReport {
  lti::Complex zero;
  double frequency_se = 0.0;  // rad/s, standard error of |zero| (ident::zero_uncertainty)
  double damping_se = 0.0;    // standard error of the damping ratio
  bool lightly_damped = false;            // |damping| < 0.2
  std::optional<bool> nonminimum_phase;   // for a lightly damped pair in the band: the data's phase, else the model's
  std::string evidence;                   // ident::zero_phase_verdict's reason, or "fitted zero"
};

double zero_frequency(const ZeroReport& z) { return std::abs(z.zero); }  // rad/s

constexpr auto describe(core::Type<ZeroReport>) {
  using S = ZeroReport;
  using namespace core::shown;
  return core::fields<S>("ZeroReport", "a zero of `fit`'s model of one output, with its phase evidence",
      core::field("zero", &S::zero, kRadPerSecond, "[re, im]").key("zero"),
      core::derived("frequency", &zero_frequency, kRadPerSecondAsHz, "|zero|"),
      core::field("frequency_se", &S::frequency_se, kRadPerSecondAsHz, "standard error of |zero|"),
      core::field("damping_se", &S::damping_se, kRatio, "standard error of the damping ratio -Re zero / |zero|"),
      core::field("lightly_damped", &S::lightly_damped, kNone, "|damping| < 0.2"),
      core::field("nonminimum_phase", &S::nonminimum_phase, kNone,
                  "for a lightly damped pair in the band: the data's phase, else the model's (null: undecided)"),
      core::field("evidence", &S::evidence, kNone, "ident::zero_phase_verdict's reason, or \"fitted zero\""));
}

std::vector<ZeroReport> zero_reports(const ident::VectorFittingResult& r, const dsp::Frf& band, Eigen::Index i,
                                     const ident::VectorFittingOptions& vf, const ident::VectorFitUncertainty& u) {
  std::vector<ZeroReport> out;
  // The phase of the data across each lightly damped zero pair (ident::frf_features).
  std::vector<ident::AntiResonance> anti;
  try {
    ident::FrfFeatureOptions fo;
    fo.fit = vf;
    fo.fit.weighting = ident::Weighting::kUnit;
    if (fo.fit.asymptote == ident::Asymptote::kConstantAndLinear) fo.fit.asymptote = ident::Asymptote::kConstant;
    fo.fit.fail_if_not_converged = false;
    anti = ident::frf_features(kTwoPi * band.freq_Hz, band.H[static_cast<std::size_t>(i)], fo).antiresonances;
  } catch (const Error&) {
    // no phase evidence: the fitted zero decides
  }
  const double f_lo = band.freq_Hz.minCoeff(), f_hi = band.freq_Hz.maxCoeff();
  const std::vector<lti::Complex> found = output_zeros(r, i);
  const std::vector<ident::RootUncertainty> se =
      ident::zero_uncertainty(r, u, i, Eigen::Map<const lti::CVector>(found.data(), static_cast<Eigen::Index>(found.size())));
  for (std::size_t k = 0; k < found.size(); ++k) {
    const lti::Complex z = found[k];
    ZeroReport rep;
    rep.zero = z;
    rep.frequency_se = se[k].natural_frequency_se;
    rep.damping_se = se[k].damping_se;
    const double damping = std::abs(z) > 0.0 ? -z.real() / std::abs(z) : 0.0;
    rep.lightly_damped = z.imag() > 0.0 && std::abs(damping) < 0.2;
    const double fz = std::abs(z) / kTwoPi;
    if (rep.lightly_damped && (fz < f_lo || fz > f_hi)) {
      // No data constrain a zero outside the band: its side of the axis is the fit's guess.
      rep.evidence = fmt::format("outside the fitted band {:g} to {:g} Hz: phase not determined by the data", f_lo, f_hi);
    } else if (rep.lightly_damped) {
      rep.nonminimum_phase = z.real() > 0.0;
      rep.evidence = "fitted zero";
      for (const auto& a : anti) {
        if (std::abs(a.natural_frequency / std::abs(z) - 1.0) < 0.05 && a.phase_verdict != ident::PhaseVerdict::kUndetermined) {
          // The phase as counted; the reason says when it is within the ambiguity of +-180 deg
          // (no plant fit here: `fit iff-plant`'s xz decides for u -> Vs).
          const ident::ZeroPhaseVerdict v = ident::zero_phase_verdict(&a, nullptr);
          rep.nonminimum_phase = v.nonminimum_phase;
          rep.evidence = v.reason;
        }
      }
    }
    out.push_back(rep);
  }
  return out;
}

// VectorFittingResult's declared view (results.json's: poles_rad_per_s, d, e, rms_error,
// relative_rms_error(_per_output), the verdict, iterations, convergence, frequency_scale_rad_per_s),
// the residues one list per output (the declared view flattens the matrix), and the command's own:
// the file, outputs, band, order and each output's declared zeros.
nlohmann::json fit_json(const ident::VectorFittingResult& r, const ident::VectorFitUncertainty& u, const dsp::Frf& band,
                        const std::vector<std::vector<ZeroReport>>& zeros) {
  nlohmann::json doc = io::results_object(r);
  doc["pole_uncertainty"] = io::shown_json(u.poles);
  doc["uncertainty_from_data_variance"] = u.from_data_variance;
  doc["condition_number"] = io::to_json(u.covariance.condition_number);
  nlohmann::json residues = nlohmann::json::array();
  for (Eigen::Index i = 0; i < r.residues.rows(); ++i) residues.push_back(io::to_json(Eigen::VectorXcd(r.residues.row(i).transpose())));
  doc["residues"] = residues;
  nlohmann::json per_output = nlohmann::json::object();
  for (std::size_t i = 0; i < band.outputs.size(); ++i) {
    per_output[band.outputs[i]] = {{"relative_rms_error", io::to_json(r.relative_rms_error_per_output(static_cast<Eigen::Index>(i)))},
                                   {"zeros", io::shown_json(zeros[i])}};
  }
  doc["source"] = band.provenance.source;
  doc["outputs"] = band.outputs;
  doc["fmin_Hz"] = band.freq_Hz(0);
  doc["fmax_Hz"] = band.freq_Hz(band.freq_Hz.size() - 1);
  doc["order"] = r.poles.size();
  doc["per_output"] = per_output;
  return doc;
}

int run_fit(const FitOptions& o) {
  ident::VectorFittingOptions vf;
  vf.order = o.order;
  vf.asymptote = ident::asymptote_from_string(o.asymptote);
  vf.weighting = ident::weighting_from_string(o.weighting);
  vf.max_iterations = o.max_iterations;
  vf.validate();
  const io::FrfFile file = read_frf_with_units(o.file, o.units);
  const dsp::Frf band = select_band(file.frf, o);
  if (!o.json) log_line(fmt::format("fitting {} poles to {} points of {}", o.order, band.freq_Hz.size(), fmt::join(band.outputs, ", ")));
  const ident::VectorFittingResult r = ident::vector_fit(band, vf);
  const ident::VectorFitUncertainty u = ident::vector_fit_uncertainty(band, r, vf);
  std::vector<std::vector<ZeroReport>> zeros;
  for (std::size_t i = 0; i < band.outputs.size(); ++i) zeros.push_back(zero_reports(r, band, static_cast<Eigen::Index>(i), vf, u));
  nlohmann::json document = fit_json(r, u, band, zeros);
  document["warnings"] = file.warnings;
  nlohmann::json units = nlohmann::json::object();
  for (std::size_t i = 0; i < file.frf.outputs.size(); ++i) units[file.frf.outputs[i]] = file.units[i];
  document["H_units"] = std::move(units);
  if (!o.out.empty()) io::write_text_atomically(o.out, document.dump(2) + "\n");
  if (o.json) {
    print_json(document);
    return report_quality(r.quality);
  }
  fmt::print("{}\n", r.brief_report());
  fmt::print("{:>26}  {:>10}  {:>9}  {:>9}  {:>9}   (standard errors {})\n", "pole [rad/s]", "f [Hz]", "se [Hz]", "damping", "se",
             u.from_data_variance ? "from the FRF's std_H" : "from the residuals' noise");
  for (Eigen::Index k = 0; k < r.poles.size(); ++k) {
    const auto p = r.poles(k);
    if (p.imag() < 0.0) continue;
    const ident::RootUncertainty& pu = u.poles[static_cast<std::size_t>(k)];
    fmt::print("{:>12.6g} {:+12.6g}j  {:>10.5g}  {:>9.2g}  {:>9.5f}  {:>9.2g}\n", p.real(), p.imag(), pu.natural_frequency / kTwoPi,
               pu.natural_frequency_se / kTwoPi, pu.damping, pu.damping_se);
  }
  for (std::size_t i = 0; i < band.outputs.size(); ++i) {
    fmt::print("{}: relative rms error {:.3g}; zeros of the fitted model [rad/s], frequency, damping ratio:{}\n", band.outputs[i],
               r.relative_rms_error_per_output(static_cast<Eigen::Index>(i)), zeros[i].empty() ? " none" : "");
    for (const auto& rep : zeros[i]) {
      const lti::Complex z = rep.zero;
      fmt::print("  {:>12.6g} {:+12.6g}j  {:>10.5g} Hz (se {:.2g})  damping {:+.5f} (se {:.2g})", z.real(), z.imag(), std::abs(z) / kTwoPi,
                 rep.frequency_se / kTwoPi, std::abs(z) > 0 ? -z.real() / std::abs(z) : 0.0, rep.damping_se);
      if (rep.nonminimum_phase) {
        fmt::print("  lightly damped, {} ({})", *rep.nonminimum_phase ? "NON-minimum phase" : "minimum phase", rep.evidence);
      } else if (rep.lightly_damped) {
        fmt::print("  lightly damped, {}", rep.evidence);
      }
      fmt::print("\n");
    }
  }
  return report_quality(r.quality);
}

// `fit iff-plant`: the IFF plant of the report (eq. 2.3 with delay) fitted to u -> Vs; its TOML
// is what `iff rlocus --plant` reads.
struct IffPlantOptions {
  std::string file;
  std::string output = "Vs";
  double fmin = 0.0;
  double fmax = 0.0;
  double hpf_fmax = 5.0;
  double min_coherence = 0.5;
  bool no_window_resolution = false;
  std::string out;
  bool json = false;
  std::string units;  // --units
};

int run_fit_iff_plant(const IffPlantOptions& o) {
  if (o.fmin < 0.0 || (o.fmax > 0.0 && o.fmax <= o.fmin)) {
    throw UsageError("--fmin/--fmax", "0 <= fmin < fmax",
                     fmt::format("fmin {}, fmax {}", format_number_exact(o.fmin), format_number_exact(o.fmax)));
  }
  const io::FrfFile file = read_frf_with_units(o.file, o.units);
  const dsp::Frf& frf = file.frf;
  const auto i = static_cast<std::size_t>(frf.output_index(o.output));
  ident::IffPlantFitOptions fo;
  fo.fmin_Hz = o.fmin;
  fo.fmax_Hz = o.fmax;
  if (o.fmin == 0.0 && o.fmax == 0.0) {
    const dsp::FrequencyBand excited = dsp::excited_band(frf, o.min_coherence);
    fo.fmin_Hz = excited.fmin_Hz;
    fo.fmax_Hz = excited.fmax_Hz;
  }
  fo.hpf_fmax_Hz = o.hpf_fmax;
  fo.min_coherence = o.min_coherence;
  fo.effective_averages = frf.provenance.effective_averages;
  if (!o.no_window_resolution) fo.resolution = dsp::resolution_kernel(frf.provenance);
  if (!o.json) log_line(fmt::format("fitting the IFF plant (eq. 2.3 with delay) to u -> {} of {}, {:.4g} to {:.4g} Hz", o.output, o.file, fo.fmin_Hz, fo.fmax_Hz));
  const lti::Vector coh = i < frf.coherence.size() ? frf.coherence[i] : lti::Vector();
  const ident::IffPlantFit p = ident::fit_iff_plant(kTwoPi * frf.freq_Hz, frf.H[i], coh, fo, o.file);
  const double hz = 1.0 / kTwoPi;
  // g0 has the unit of H (output / input) in SI, as the file states it; V/V only for u -> Vs in V.
  const std::string g0_unit = i < file.units.size() ? file.units[i] : std::string();
  const std::string g0_unit_text = g0_unit.empty() ? "(H's unit, not stated in the file: SI assumed)"
                                   : g0_unit == "1"  ? "(dimensionless: output and input in one unit)"
                                                     : g0_unit;
  nlohmann::json doc = {{"source", o.file},
                        {"output", o.output},
                        {"band_Hz", {fo.fmin_Hz, fo.fmax_Hz}},
                        {"relative_rms_error", io::to_json(p.relative_rms_error)},
                        {"points", p.points},
                        {"iterations", p.iterations},
                        {"status", core::to_string(p.status)},
                        {"formula", "G(s) = g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2) s / (w_hpf + s) exp(-s delay)"}};
  if (!p.quality.impossible) {
    // IffPlantFit's declared parameters (wz_Hz, xz, wp_Hz, xp, w_hpf_Hz, delay_s; the fit's
    // statistics are the document's own keys above); g0 in H's unit as the file states it (the
    // declaration's V/V is the campaign's u -> Vs in V), with that unit.
    nlohmann::json plant = io::results_object(p);
    for (const char* k : {"g0_V_per_V", "relative_rms_error", "weighted_relative_rms_error", "initial_relative_rms_error", "points",
                          "iterations", "converged", "status", "quality", "quality_advice", "quality_impossible", "quality_problems",
                          "uncertainty"}) {
      plant.erase(k);
    }
    plant["g0"] = io::to_json(p.g0);
    plant["g0_unit"] = g0_unit.empty() ? nlohmann::json() : nlohmann::json(g0_unit);
    plant["zero_is_nonminimum_phase"] = p.zero_is_nonminimum_phase();
    doc["plant"] = plant;
    doc["uncertainty"] = io::to_json(p.uncertainty);
    const ident::ZeroPhaseVerdict v = ident::zero_phase_verdict(nullptr, &p);
    doc["zero_verdict"] = {{"nonminimum_phase", v.nonminimum_phase ? nlohmann::json(*v.nonminimum_phase) : nlohmann::json(nullptr)},
                           {"reason", v.reason}};
  }
  doc.update(quality_json(p.quality));
  doc["warnings"] = file.warnings;
  if (!o.out.empty() && !p.quality.impossible) {
    io::write_lti_toml(p.transfer_function(), o.out,
                       fmt::format("IFF plant (eq. 2.3) fitted to u -> {} of {} by piezobench fit iff-plant, {:.4g} to {:.4g} Hz, "
                                   "relative rms error {:.3g}, quality {}",
                                   o.output, o.file, fo.fmin_Hz, fo.fmax_Hz, p.relative_rms_error, core::to_string(p.quality.verdict)));
    if (!o.json) log_line("wrote " + o.out + " (read by `iff rlocus --plant`)");
  }
  if (o.json) {
    print_json(doc);
    return report_quality(p.quality);
  }
  fmt::print("IFF plant (eq. 2.3 with delay) fitted to u -> {} of {}, {:.4g} to {:.4g} Hz ({} points)\n", o.output, o.file,
             fo.fmin_Hz, fo.fmax_Hz, p.points);
  if (!p.quality.impossible) {
    fmt::print("  g0 = {:.5g} {}, wz = {:.5g} Hz, xz = {:+.4g}, wp = {:.5g} Hz, xp = {:.4g}\n", p.g0, g0_unit_text, p.wz * hz, p.xz, p.wp * hz, p.xp);
    fmt::print("  high-pass corner {:.4g} Hz, delay {:.4g} us\n", p.w_hpf * hz, p.delay * 1e6);
    const ident::ZeroPhaseVerdict v = ident::zero_phase_verdict(nullptr, &p);
    fmt::print("  zero pair: {} ({})\n", v.nonminimum_phase ? (*v.nonminimum_phase ? "NON-minimum phase" : "minimum phase") : "undetermined",
               v.reason);
    const auto& u = p.uncertainty;
    fmt::print("  standard errors ({}): g0 {:.2g}, wz {:.2g} Hz, xz {:.2g}, wp {:.2g} Hz, xp {:.2g}, delay {:.2g} us; condition number {:.3g}\n",
               u.from_data_variance ? "from the FRF's variance" : "from the residuals' scatter", u.standard_error_of("g0"),
               u.standard_error_of("wz") * hz, u.standard_error_of("xz"), u.standard_error_of("wp") * hz, u.standard_error_of("xp"),
               u.standard_error_of("delay") * 1e6, u.condition_number);
    for (const auto& c : u.high_correlations) fmt::print("  correlated (> 0.95): {}\n", c);
  }
  fmt::print("  relative rms error {:.3g}, Levenberg-Marquardt {} after {} steps\n", p.relative_rms_error, core::to_string(p.status),
             p.iterations);
  return report_quality(p.quality);
}

}  // namespace

void add_frf_commands(CLI::App& app, Action& action) {
  auto f = std::make_shared<FrfOptions>();
  CLI::App* frf = app.add_subcommand("frf", "FRFs (Welch H1 or H2) and coherence from one input to several outputs of a time-series file");
  frf->add_option("file", f->file, "time series: .mat (v5 or v7.3), .csv with a header row or .uff (UFF58 time histories)")->required()->check(input_file());
  frf->add_option("--input", f->input, "input channel name (e.g. u)")->required();
  frf->add_option("--output", f->outputs, "output channel names, comma-separated (e.g. de,Vs)")->required();
  frf->add_option("--fs", f->fs, "sample rate, Hz (needed when the file has no time vector t)");
  frf->add_option("--window", f->window,
                  "hann (= hann-periodic, scipy's), hann-symmetric, hanning (MATLAB's), hamming (= hamming-periodic), "
                  "hamming-symmetric, flattop (= flattop-periodic), flattop-symmetric, flattopwin (MATLAB's), rectangular "
                  "(boxcar, rectwin); any case")
      ->capture_default_str()
      ->check(parsed_by([](const std::string& v) { (void)dsp::window_type_from_string(v); }, "WINDOW"));
  frf->add_option("--nfft", f->nfft, "segment length, samples (0 = as `run`: 1/--resolution seconds, at most a quarter of the record)")
      ->capture_default_str()
      ->check(non_negative());
  frf->add_option("--resolution", f->resolution, "target bin width when --nfft is 0, Hz")->capture_default_str()->check(positive());
  frf->add_option("--overlap", f->overlap, "overlap of segments, fraction of nfft in [0, 1)")->capture_default_str();
  frf->add_option("--detrend", f->detrend, "none, mean or linear (per segment)")
      ->capture_default_str()
      ->check(parsed_by([](const std::string& v) { (void)dsp::detrend_from_string(v); }, "DETREND"));
  frf->add_option("--estimator", f->estimator, "H1 (noise on the output) or H2 (noise on the input)")
      ->capture_default_str()
      ->check(parsed_by([](const std::string& v) { (void)dsp::frf_estimator_from_string(v); }, "ESTIMATOR"));
  frf->add_option("--out", f->out, "write the FRF: .csv, .mat or .uff (Universal File Format 58)")
      ->check(output_extension({".csv", ".mat", ".uff", ".unv", ".uf"}));
  frf->add_flag("--json", f->json, "print one JSON document on stdout");
  add_units_option(frf, f->units);
  frf->add_option("--delimiter", f->delimiter, "CSV input: auto (detected), ',', ';', tab or space")
      ->check(CLI::IsMember({"auto", ",", ";", "tab", "space"}))
      ->capture_default_str();
  frf->add_option("--decimal", f->decimal, "CSV input: auto (detected), '.' or ','")
      ->check(CLI::IsMember({"auto", ".", ","}))
      ->capture_default_str();
  frf->callback([f, &action] { action = [f] { return run_frf(*f); }; });

  auto v = std::make_shared<FitOptions>();
  CLI::App* fit = app.add_subcommand("fit", "Vector fitting (Gustavsen & Semlyen) of an FRF file: common poles, residues, D, zeros per output; "
                                            "`fit iff-plant`: the IFF plant of eq. 2.3");
  fit->require_subcommand(0, 1);
  fit->add_option("file", v->file, "FRF file: .csv (freq_Hz,re_NAME,im_NAME[,coh_NAME]...), .mat or .uff")->check(input_file());
  fit->add_option("--order", v->order, "number of poles")->check(positive());
  fit->add_option("--fmin", v->fmin, "lowest frequency used, Hz (default: the band where the coherence is at least 0.5)");
  fit->add_option("--fmax", v->fmax, "highest frequency used, Hz (0 = all; default: as --fmin)");
  fit->add_option("--output", v->outputs, "outputs to fit, comma-separated (default: all, with common poles)");
  fit->add_option("--asymptote", v->asymptote, "none, d or de (d + s e)")
      ->capture_default_str()
      ->check(parsed_by([](const std::string& x) { (void)ident::asymptote_from_string(x); }, "ASYMPTOTE"));
  fit->add_option("--weighting", v->weighting,
                  "output-scale (each output by 1/rms|H|: outputs in other units count alike), unit, inverse-magnitude, "
                  "inverse-sqrt-magnitude or inverse-std (each point by 1/its standard deviation: the file's std columns)")
      ->capture_default_str()
      ->check(parsed_by([](const std::string& x) { (void)ident::weighting_from_string(x); }, "WEIGHTING"));
  fit->add_option("--max-iterations", v->max_iterations, "pole relocations at most")->capture_default_str();
  fit->add_option("--out", v->out, "write the fitted model as JSON (same document as --json)")->check(output_extension({".json"}));
  fit->add_flag("--json", v->json, "print one JSON document on stdout");
  add_units_option(fit, v->units);

  auto ip = std::make_shared<IffPlantOptions>();
  CLI::App* iff_plant = fit->add_subcommand("iff-plant", "Fit the IFF plant of the report (eq. 2.3 with delay) to u -> Vs; --out writes "
                                                         "the TOML that `iff rlocus --plant` reads");
  iff_plant->add_option("file", ip->file, "FRF file (.csv, .mat, .uff) with the output")->required()->check(input_file());
  iff_plant->add_option("--output", ip->output, "the force-sensor output")->capture_default_str();
  iff_plant->add_option("--fmin", ip->fmin, "lowest frequency used, Hz (default: the band where the coherence is at least --min-coherence)");
  iff_plant->add_option("--fmax", ip->fmax, "highest frequency used, Hz (0 = all)");
  iff_plant->add_option("--hpf-fmax", ip->hpf_fmax, "points below this start the high-pass corner, Hz")->capture_default_str()->check(positive());
  iff_plant->add_option("--min-coherence", ip->min_coherence, "leave out frequencies with a lower coherence")
      ->capture_default_str()
      ->check(number_in(0.0, 0.999));
  iff_plant->add_flag("--no-window-resolution", ip->no_window_resolution,
                      "compare the model with the FRF directly, not through its Welch window's resolution kernel (which is used when "
                      "the file gives the window, nfft and sample rate)");
  iff_plant->add_option("--out", ip->out, "write the plant as an LTI TOML file (transfer function with delay)")
      ->check(output_extension({".toml"}));
  iff_plant->add_flag("--json", ip->json, "print one JSON document on stdout");
  add_units_option(iff_plant, ip->units);
  iff_plant->callback([ip, &action] { action = [ip] { return run_fit_iff_plant(*ip); }; });

  fit->callback([v, fit, &action] {
    if (!fit->get_subcommands().empty()) return;
    if (v->file.empty()) throw CLI::RequiredError("file");
    if (fit->count("--order") == 0) throw CLI::RequiredError("--order");
    action = [v] { return run_fit(*v); };
  });
}

}  // namespace piezobench::app
