// `piezobench frf` (Welch H1/H2 FRFs and coherence from a time-series file) and `piezobench fit`
// (vector fitting of an FRF file).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/ident/vector_fitting.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::app {
namespace {

struct FrfOptions {
  std::string file;
  std::string input;
  std::string outputs;
  double fs = 0.0;
  std::string window = "hann";
  Eigen::Index nfft = 1024;
  double overlap = 0.5;
  std::string detrend = "none";
  std::string estimator = "H1";
  std::string out;
  bool json = false;
  std::string delimiter = "auto";  // CSV input only
  std::string decimal = "auto";
};

// The CLI's short window names ("hann", "hamming", "flattop") are the periodic windows that Welch
// averaging uses (scipy's defaults); the full names say which is meant.
dsp::WindowType window_from_cli(const std::string& name) {
  if (name == "hann" || name == "hamming" || name == "flattop") return dsp::window_type_from_string(name + "-periodic");
  return dsp::window_type_from_string(name);
}

nlohmann::json frf_json(const dsp::Frf& frf) {
  nlohmann::json outputs = nlohmann::json::object();
  for (std::size_t i = 0; i < frf.outputs.size(); ++i) {
    nlohmann::json o = {{"H", io::to_json(frf.H[i])}};
    if (i < frf.coherence.size() && frf.coherence[i].size() > 0) o["coherence"] = io::to_json(frf.coherence[i]);
    outputs[frf.outputs[i]] = o;
  }
  const auto& p = frf.provenance;
  return {{"source", p.source},
          {"input", frf.input},
          {"freq_Hz", io::to_json(frf.freq_hz)},
          {"window", {{"name", p.window}, {"length", p.nfft}, {"periodic", p.window.find("periodic") != std::string::npos}}},
          {"nfft", p.nfft},
          {"overlap", p.overlap},
          {"detrend", p.detrend},
          {"estimator", p.estimator},
          {"averages", p.averages},
          {"sample_rate_Hz", p.sample_rate},
          {"outputs", outputs}};
}

int run_frf(const FrfOptions& o) {
  dsp::WelchOptions welch;
  welch.window = window_from_cli(o.window);
  welch.nfft = o.nfft;
  welch.overlap = o.overlap;
  welch.detrend = dsp::detrend_from_string(o.detrend);
  welch.estimator = dsp::frf_estimator_from_string(o.estimator);
  welch.validate("command line");

  io::ReadOptions read;
  read.fs = o.fs;
  read.channels = split_list(o.outputs, "--output");
  read.channels.insert(read.channels.begin(), o.input);
  read.delimiter = io::csv_delimiter_from_string(o.delimiter);
  read.decimal = io::csv_decimal_from_string(o.decimal);
  if (!o.json) log_line("reading " + o.file);
  const io::TimeSeries ts = io::read_timeseries(o.file, read);

  std::vector<dsp::Channel> outputs;
  for (std::size_t i = 1; i < read.channels.size(); ++i) {
    outputs.push_back({read.channels[i], {ts.data.col(static_cast<Eigen::Index>(i)).data(), static_cast<std::size_t>(ts.samples())}});
  }
  const dsp::Channel input{o.input, {ts.data.col(0).data(), static_cast<std::size_t>(ts.samples())}};
  if (!o.json) log_line(fmt::format("{} samples at {:g} Hz, nfft {}, {} outputs", ts.samples(), ts.sample_rate, o.nfft, outputs.size()));
  const dsp::FrfEstimate estimate = dsp::estimate_frf(input, outputs, ts.sample_rate, welch, o.file);

  if (!o.out.empty()) {
    io::write_frf(estimate.frf, o.out);
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
    document["H_units"] = units;
    print_json(document);
    return 0;
  }
  const dsp::Frf& frf = estimate.frf;
  fmt::print("FRF {} of {} -> {}: {} averages, window {} ({} samples), {:.4g} Hz resolution\n",
             frf.provenance.estimator, frf.input, fmt::join(frf.outputs, ", "), frf.provenance.averages,
             frf.provenance.window, frf.provenance.nfft, frf.freq_hz.size() > 1 ? frf.freq_hz(1) - frf.freq_hz(0) : 0.0);
  for (std::size_t i = 0; i < frf.outputs.size(); ++i) {
    Eigen::Index peak = 1;
    for (Eigen::Index k = 1; k < frf.freq_hz.size(); ++k) {
      if (std::abs(frf.H[i](k)) > std::abs(frf.H[i](peak))) peak = k;
    }
    const double mean_coh = frf.coherence[i].size() > 1 ? frf.coherence[i].tail(frf.coherence[i].size() - 1).mean() : 0.0;
    fmt::print("  {}: peak |H| {:.4g} at {:.4g} Hz, mean coherence {:.3f}\n", frf.outputs[i], std::abs(frf.H[i](peak)),
               frf.freq_hz(peak), mean_coh);
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
  std::string weighting = "unit";
  int max_iterations = 50;
  std::string out;
  bool json = false;
};

// The part of an FRF inside [fmin, fmax] (0 = no bound), for the named outputs (empty = all).
dsp::Frf select_band(const dsp::Frf& frf, const FitOptions& o) {
  if (o.fmin < 0.0 || (o.fmax > 0.0 && o.fmax <= o.fmin)) {
    throw InputError("", "--fmin/--fmax", "0 <= fmin < fmax", fmt::format("fmin {:g}, fmax {:g}", o.fmin, o.fmax));
  }
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < frf.freq_hz.size(); ++k) {
    if (frf.freq_hz(k) >= o.fmin && (o.fmax <= 0.0 || frf.freq_hz(k) <= o.fmax)) keep.push_back(k);
  }
  if (keep.empty()) {
    throw InputError(o.file, "freq_Hz", fmt::format("frequencies inside [{:g}, {:g}] Hz", o.fmin, o.fmax), "none");
  }
  std::vector<Eigen::Index> outs;
  if (o.outputs.empty()) {
    for (std::size_t i = 0; i < frf.outputs.size(); ++i) outs.push_back(static_cast<Eigen::Index>(i));
  } else {
    for (const auto& name : split_list(o.outputs, "--output")) outs.push_back(frf.output_index(name));
  }
  dsp::Frf band;
  band.input = frf.input;
  band.provenance = frf.provenance;
  band.freq_hz.resize(static_cast<Eigen::Index>(keep.size()));
  for (std::size_t k = 0; k < keep.size(); ++k) band.freq_hz(static_cast<Eigen::Index>(k)) = frf.freq_hz(keep[k]);
  for (const Eigen::Index i : outs) {
    const auto ui = static_cast<std::size_t>(i);
    band.outputs.push_back(frf.outputs[ui]);
    Eigen::VectorXcd h(band.freq_hz.size());
    for (std::size_t k = 0; k < keep.size(); ++k) h(static_cast<Eigen::Index>(k)) = frf.H[ui](keep[k]);
    band.H.push_back(h);
    if (ui < frf.coherence.size() && frf.coherence[ui].size() > 0) {
      Eigen::VectorXd c(band.freq_hz.size());
      for (std::size_t k = 0; k < keep.size(); ++k) c(static_cast<Eigen::Index>(k)) = frf.coherence[ui](keep[k]);
      band.coherence.push_back(c);
    }
  }
  return band;
}

nlohmann::json fit_json(const ident::VectorFittingResult& r, const dsp::Frf& band) {
  nlohmann::json residues = nlohmann::json::array();
  for (Eigen::Index i = 0; i < r.residues.rows(); ++i) residues.push_back(io::to_json(Eigen::VectorXcd(r.residues.row(i).transpose())));
  return {{"source", band.provenance.source},
          {"outputs", band.outputs},
          {"fmin_Hz", band.freq_hz(0)},
          {"fmax_Hz", band.freq_hz(band.freq_hz.size() - 1)},
          {"order", r.poles.size()},
          {"poles", io::to_json(r.poles)},
          {"residues", residues},
          {"d", io::to_json(r.d)},
          {"e", io::to_json(r.e)},
          {"rms_error", io::to_json(r.rms_error)},
          {"relative_rms_error", io::to_json(r.relative_rms_error)},
          {"iterations", r.iterations},
          {"converged", r.converged},
          {"convergence", ident::to_string(r.convergence)},
          {"frequency_scale_rad_per_s", r.frequency_scale}};
}

int run_fit(const FitOptions& o) {
  ident::VectorFittingOptions vf;
  vf.order = o.order;
  vf.asymptote = ident::asymptote_from_string(o.asymptote);
  vf.weighting = ident::weighting_from_string(o.weighting);
  vf.max_iterations = o.max_iterations;
  vf.validate();
  const dsp::Frf band = select_band(io::read_frf(o.file), o);
  if (!o.json) log_line(fmt::format("fitting {} poles to {} points of {}", o.order, band.freq_hz.size(), fmt::join(band.outputs, ", ")));
  const ident::VectorFittingResult r = ident::vector_fit(band, vf);
  const nlohmann::json document = fit_json(r, band);
  if (!o.out.empty()) io::write_text_atomically(o.out, document.dump(2) + "\n");
  if (o.json) {
    print_json(document);
    return 0;
  }
  fmt::print("{}\n", r.brief_report());
  fmt::print("{:>26}  {:>10}  {:>9}\n", "pole [rad/s]", "f [Hz]", "damping");
  for (const auto p : r.poles) {
    if (p.imag() < 0.0) continue;
    fmt::print("{:>12.6g} {:+12.6g}j  {:>10.5g}  {:>9.5f}\n", p.real(), p.imag(), std::abs(p) / (2 * std::numbers::pi),
               std::abs(p) > 0 ? -p.real() / std::abs(p) : 0.0);
  }
  return 0;
}

}  // namespace

void add_frf_commands(CLI::App& app, Action& action) {
  auto f = std::make_shared<FrfOptions>();
  CLI::App* frf = app.add_subcommand("frf", "FRFs (Welch H1 or H2) and coherence from one input to several outputs of a time-series file");
  frf->add_option("file", f->file, "time series: .mat (v5 or v7.3) or .csv with a header row")->required()->check(CLI::ExistingFile);
  frf->add_option("--input", f->input, "input channel name (e.g. u)")->required();
  frf->add_option("--output", f->outputs, "output channel names, comma-separated (e.g. de,Vs)")->required();
  frf->add_option("--fs", f->fs, "sample rate, Hz (needed when the file has no time vector t)");
  frf->add_option("--window", f->window,
                  "hann (= hann-periodic), hann-symmetric, hamming (= hamming-periodic), hamming-symmetric, flattop "
                  "(= flattop-periodic), flattop-symmetric, rectangular")
      ->capture_default_str();
  frf->add_option("--nfft", f->nfft, "segment length, samples (any integer >= 2)")->capture_default_str();
  frf->add_option("--overlap", f->overlap, "overlap of segments, fraction of nfft in [0, 1)")->capture_default_str();
  frf->add_option("--detrend", f->detrend, "none, mean or linear (per segment)")->capture_default_str();
  frf->add_option("--estimator", f->estimator, "H1 (noise on the output) or H2 (noise on the input)")->capture_default_str();
  frf->add_option("--out", f->out, "write the FRF: .csv, .mat or .uff (Universal File Format 58)");
  frf->add_flag("--json", f->json, "print one JSON document on stdout");
  frf->add_option("--delimiter", f->delimiter, "CSV input: auto (detected), ',', ';', tab or space")
      ->check(CLI::IsMember({"auto", ",", ";", "tab", "space"}))
      ->capture_default_str();
  frf->add_option("--decimal", f->decimal, "CSV input: auto (detected), '.' or ','")
      ->check(CLI::IsMember({"auto", ".", ","}))
      ->capture_default_str();
  frf->callback([f, &action] { action = [f] { return run_frf(*f); }; });

  auto v = std::make_shared<FitOptions>();
  CLI::App* fit = app.add_subcommand("fit", "Vector fitting (Gustavsen & Semlyen) of an FRF file: common poles, residues, D");
  fit->add_option("file", v->file, "FRF file: .csv (freq_Hz,re_NAME,im_NAME[,coh_NAME]...), .mat or .uff")->required()->check(CLI::ExistingFile);
  fit->add_option("--order", v->order, "number of poles")->required();
  fit->add_option("--fmin", v->fmin, "lowest frequency used, Hz");
  fit->add_option("--fmax", v->fmax, "highest frequency used, Hz (0 = all)");
  fit->add_option("--output", v->outputs, "outputs to fit, comma-separated (default: all, with common poles)");
  fit->add_option("--asymptote", v->asymptote, "none, d or de (d + s e)")->capture_default_str();
  fit->add_option("--weighting", v->weighting, "unit, inverse-magnitude or inverse-sqrt-magnitude")->capture_default_str();
  fit->add_option("--max-iterations", v->max_iterations, "pole relocations at most")->capture_default_str();
  fit->add_option("--out", v->out, "write the fitted model as JSON (same document as --json)");
  fit->add_flag("--json", v->json, "print one JSON document on stdout");
  fit->callback([v, &action] { action = [v] { return run_fit(*v); }; });
}

}  // namespace piezobench::app
