// `piezobench model 2dof`, `piezobench model tune` and `piezobench piezo`: the 2-DoF actuator
// model of report section 3, its tuning to measured FRFs, and the stack sensitivities of eq. 4.1.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include "cli_common.hpp"
#include "piezobench/apa/piezo.hpp"
#include "piezobench/apa/tuning.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/apa/two_dof_file.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::app {
namespace {

constexpr const char* kCommandLine = "command line";

// The sign convention of ga and gs (docs/models.md), and whether `p` follows it.
std::string sign_note(const apa::TwoDofParams& p) {
  const bool follows = p.ga < 0.0 && p.gs > 0.0;
  return fmt::format("  signs: the report's convention is ga < 0 (more voltage lowers the APA: a negative static gain u -> d_e) "
                     "and gs > 0 (Vs rises with it){}",
                     follows ? "" : fmt::format("; these parameters differ (ga {} 0, gs {} 0)", p.ga < 0.0 ? "<" : ">=", p.gs > 0.0 ? ">" : "<="));
}

nlohmann::json params_json(const apa::TwoDofParams& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& n : apa::TwoDofParams::names()) j[n] = io::to_json(p.get(n));
  return j;
}

nlohmann::json complex_list(const lti::CVector& v) {
  nlohmann::json j = nlohmann::json::array();
  for (lti::Index i = 0; i < v.size(); ++i) j.push_back(io::to_json(v(i)));
  return j;
}

// ------------------------------------------------------------------------------ model 2dof
struct TwoDofCommand {
  std::string params_file;
  double fmin = 1.0;
  double fmax = 10000.0;
  int points = 500;
  apa::TwoDofBench bench;
  bool json = false;
};

int run_two_dof(const TwoDofCommand& o) {
  if (!(std::isfinite(o.fmin) && o.fmin > 0.0)) throw UsageError("--fmin", "a frequency > 0 Hz", fmt::format("{}", o.fmin));
  if (!(std::isfinite(o.fmax) && o.fmax > o.fmin)) {
    throw UsageError("--fmax", fmt::format("a frequency above --fmin = {} Hz", o.fmin), fmt::format("{}", o.fmax));
  }
  const apa::TwoDofParams p = o.params_file.empty() ? apa::TwoDofParams{} : apa::read_two_dof_params(o.params_file);
  o.bench.validate(kCommandLine);
  const apa::TwoDofCharacteristics c = apa::characterize(p, o.bench);
  const lti::Vector f = lti::logspace(std::log10(o.fmin), std::log10(o.fmax), o.points);
  const lti::FrequencyResponse fr = lti::freqresp(apa::two_dof_bench(p, o.bench), kTwoPi * f);
  const lti::CVector h_de = fr.channel(apa::kOutputDe, 0);
  const lti::CVector h_vs = fr.channel(apa::kOutputVs, 0);

  if (o.json) {
    nlohmann::json doc = io::results_object(c);  // poles, zeros, static gains, resonances (declared)
    doc.update(nlohmann::json{{"model", "2dof"},
                {"params", params_json(p)},
                {"params_source", o.params_file.empty() ? std::string("report Table 3.1") : o.params_file},
                {"bench",
                 {{"amplifier_gain", o.bench.amplifier_gain},
                  {"moving_mass_kg", o.bench.moving_mass(p)},
                  {"hpf_resistance_Ohm", o.bench.hpf_resistance},
                  {"hpf_capacitance_F", o.bench.hpf_capacitance},
                  {"hpf_corner_Hz", o.bench.hpf_corner() / kTwoPi},
                  {"delay_s", o.bench.delay}}},
                {"input", "u (V at the DAC, amplifier included)"},
                {"units", {{"poles", "rad/s"}, {"zeros_Vs", "rad/s"}, {"H_de", "m/V"}, {"H_Vs", "V/V"}}},
                {"freq_Hz", io::to_json(f)},
                {"H_de", complex_list(h_de)},
                {"H_Vs", complex_list(h_vs)}});
    print_json(doc);
    return 0;
  }
  fmt::print("2-DoF APA model (report section 3), parameters from {}\n",
             o.params_file.empty() ? "Table 3.1" : o.params_file);
  fmt::print("  m = {:.4g} kg, k1 = {:.4g} N/um, c1 = {:.4g} Ns/m\n", p.m, p.k1 * 1e-6, p.c1);
  fmt::print("  ke = {:.4g} N/um, ce = {:.4g} Ns/m, ka = {:.4g} N/um, ca = {:.4g} Ns/m\n", p.ke * 1e-6, p.ce,
             p.ka * 1e-6, p.ca);
  fmt::print("  ga = {:.4g} N/V, gs = {:.4g} V/um, k_tot = {:.4g} N/um\n", p.ga, p.gs * 1e-6,
             p.total_stiffness() * 1e-6);
  fmt::print("{}\n", sign_note(p));
  fmt::print("bench: amplifier {:.4g} V/V, moving mass {:.4g} kg", o.bench.amplifier_gain, o.bench.moving_mass(p));
  if (o.bench.has_hpf()) fmt::print(", high-pass on Vs at {:.4g} Hz", o.bench.hpf_corner() / kTwoPi);
  if (o.bench.delay > 0.0) fmt::print(", delay {:.4g} us", o.bench.delay * 1e6);
  fmt::print("\n");
  fmt::print("static gain u -> d_e: {:.4g} um/V\n", c.static_gain_de * 1e6);
  fmt::print("static gain u -> Vs:  {:.4g} V/V{}\n", c.static_gain_vs,
             o.bench.has_hpf() ? fmt::format(" ({:.4g} V/V before the high-pass)", c.static_gain_vs_actuator) : "");
  fmt::print("resonance:      {:.4g} Hz, damping {:.4g}\n", c.resonance / kTwoPi, c.resonance_damping);
  fmt::print("anti-resonance: {:.4g} Hz, damping {:.4g} (u -> Vs)\n", c.antiresonance / kTwoPi,
             c.antiresonance_damping);
  fmt::print("poles [rad/s]:");
  for (lti::Index i = 0; i < c.poles.size(); ++i) fmt::print(" {:.6g}{:+.6g}j", c.poles(i).real(), c.poles(i).imag());
  fmt::print("\n");
  return 0;
}

// ------------------------------------------------------------------------------ model tune
struct TuneCommand {
  std::string frf_file;
  apa::TuningOptions options;
  bool no_refine = false;
  bool min_coherence_given = false;
  bool delay_given = false;
  bool free_ratios = false;
  bool no_window_resolution = false;
  bool json = false;
  std::string units;  // --units
};

// The plant fits' options of `model tune` (the tuning's band, coherence threshold and window
// resolution; the Vs fit goes down to the lowest frequency for the high-pass corner).
ident::ActuatorPlantOptions tune_plant_options(const apa::TuningOptions& o, const dsp::Frf& frf) {
  ident::ActuatorPlantOptions po;
  po.fmin_Hz = o.fmin_Hz;
  po.fmax_Hz = o.fmax_Hz;
  po.min_coherence = o.min_coherence;
  po.effective_averages = frf.provenance.effective_averages;
  if (o.window_resolution) po.resolution = dsp::resolution_kernel(frf.provenance);
  return po;
}

int run_tune(const TuneCommand& c) {
  apa::TuningOptions o = c.options;
  o.refine = !c.no_refine;
  o.window_resolution = !c.no_window_resolution;
  o.validate();
  const io::FrfFile file = read_frf_with_units(c.frf_file, c.units);
  const dsp::Frf& frf = file.frf;
  const Eigen::Index de = frf.output_index(o.de_output), vs = frf.output_index(o.vs_output);
  const auto ude = static_cast<std::size_t>(de), uvs = static_cast<std::size_t>(vs);
  // The campaign's procedure and defaults (as `run`): the campaign's band (20 to 500 Hz: eq. 2.3
  // lacks the node relaxation above) inside the band the input excited (coherence), unless given;
  // the delays and the high-pass corner from the plant fits; then the tuning with that chain removed.
  const dsp::FrequencyBand excited = dsp::excited_band(frf, 0.5);
  const bool has_coherence = excited.from_coherence;
  const ident::ActuatorPlantOptions defaults;
  if (o.fmin_Hz == 0.0) o.fmin_Hz = std::max(defaults.fmin_Hz, excited.fmin_Hz);
  if (o.fmax_Hz == 0.0) o.fmax_Hz = std::min(defaults.fmax_Hz, excited.fmax_Hz);
  if (c.min_coherence_given) {
    o.min_coherence = c.options.min_coherence;
  } else if (has_coherence) {
    o.min_coherence = defaults.min_coherence;
  }
  o.validate();
  if (!c.json) {
    log_line(fmt::format("tuning the 2-DoF model on {} ({} frequencies, band {:.4g} to {:.4g} Hz{})", c.frf_file, frf.freq_Hz.size(),
                         o.fmin_Hz, o.fmax_Hz, has_coherence ? " where the coherence is at least 0.5" : ""));
  }
  ident::ActuatorPlantOptions po = tune_plant_options(o, frf);
  if (c.free_ratios) o.stack_stiffness_ratio = o.stack_damping_ratio = 0.0;
  if (o.bench.hpf_resistance > 0.0 && o.bench.hpf_capacitance > 0.0) po.fixed_w_hpf = o.bench.hpf_corner();
  const lti::Vector omega = kTwoPi * frf.freq_Hz;
  const auto coh = [&](std::size_t i) { return i < frf.coherence.size() ? frf.coherence[i] : lti::Vector(); };
  const ident::ActuatorPlants plants = ident::fit_actuator_plants(omega, frf.H[ude], coh(ude), frf.H[uvs], coh(uvs), po, c.frf_file);
  for (const auto& f : plants.failures) log_line("warning: " + f);
  const bool given_delay = c.delay_given;
  const apa::TwoDofTuning t = apa::tune_two_dof_measured(frf, o, plants.de && !given_delay ? &*plants.de : nullptr,
                                                         plants.vs && po.fixed_w_hpf == 0.0 ? &*plants.vs : nullptr);
  if (c.json) {
    // The tuning's declared view (results.json's model_2dof_fit: features, fit errors, initial,
    // bench, uncertainty, status, the verdict ...), the parameters in SI under model_2dof (as
    // results.json's), and only the command's own: the file, the band, the ratios and the chain.
    nlohmann::json doc = io::results_object(t);
    doc.erase("params");
    doc["source"] = c.frf_file;
    doc["model_2dof"] = t.quality.impossible ? nlohmann::json(nullptr) : params_json(t.params);
    if (t.quality.impossible) doc["initial"] = nullptr;
    doc["fit_error_definition"] = "rms over the frequencies used of |H_model / H_data - 1| per output";
    doc["amplifier_gain"] = o.bench.amplifier_gain;
    doc["band_Hz"] = {o.fmin_Hz, o.fmax_Hz};
    doc["min_coherence"] = o.min_coherence;
    doc["chain"] = {{"delay_s", t.bench.delay}, {"hpf_corner_Hz", t.bench.hpf_corner() / kTwoPi}};
    doc["stack_stiffness_ratio"] = o.stack_stiffness_ratio;
    doc["stack_damping_ratio"] = o.stack_damping_ratio;
    doc["warnings"] = file.warnings;
    print_json(doc);
    return report_quality(t.quality);
  }
  const apa::TwoDofParams& p = t.params;
  if (t.quality.impossible) {
    fmt::print("2-DoF model tuning on {} ({:.4g} to {:.4g} Hz) gave no physical parameters\n{}\n", c.frf_file, o.fmin_Hz, o.fmax_Hz,
               t.brief_report());
    return report_quality(t.quality);
  }
  fmt::print("2-DoF model tuned on {} (mass {:.4g} kg, amplifier {:.4g} V/V, {:.4g} to {:.4g} Hz)\n", c.frf_file, p.m,
             o.bench.amplifier_gain, o.fmin_Hz, o.fmax_Hz);
  fmt::print("  chain removed: delay {:.4g} us, high-pass on Vs at {:.4g} Hz\n", t.bench.delay * 1e6, t.bench.hpf_corner() / kTwoPi);
  fmt::print("  k1 = {:.4g} N/um, c1 = {:.4g} Ns/m\n", p.k1 * 1e-6, p.c1);
  fmt::print("  ke = {:.4g} N/um, ce = {:.4g} Ns/m, ka = {:.4g} N/um, ca = {:.4g} Ns/m\n", p.ke * 1e-6, p.ce,
             p.ka * 1e-6, p.ca);
  fmt::print("  ga = {:.4g} N/V, gs = {:.4g} V/um\n", p.ga, p.gs * 1e-6);
  fmt::print("{}\n", sign_note(p));
  if (!t.uncertainty.empty()) {
    std::string se;
    for (const auto& name : apa::TwoDofParams::names()) {
      if (name != "m") se += fmt::format("{}{} {:.2g} %", se.empty() ? "" : ", ", name, 100.0 * t.uncertainty.relative_standard_error_of(name));
    }
    fmt::print("  relative standard errors ({}): {}; condition number {:.3g}\n",
               t.uncertainty.from_data_variance ? "from the FRF's variance" : "from the residuals' scatter", se, t.uncertainty.condition_number);
    for (const auto& h : t.uncertainty.high_correlations) fmt::print("  correlated (> 0.95): {}\n", h);
  }
  if (!t.undetermined.empty()) fmt::print("  undetermined: {}\n", fmt::join(t.undetermined, ", "));
  fmt::print("{}\n{}\nquality: {}\n", t.brief_report(), t.message, core::to_string(t.quality.verdict));
  return report_quality(t.quality);
}

// ------------------------------------------------------------------------------ piezo
struct PiezoCommand {
  apa::PiezoConstants constants;
  bool json = false;
};

int run_piezo(const PiezoCommand& c) {
  c.constants.validate(kCommandLine);
  const apa::PiezoSensitivities s = apa::piezo_sensitivities(c.constants);
  const apa::PiezoConstants& k = c.constants;
  if (c.json) {
    nlohmann::json doc = io::results_object(s);  // ka_N_per_m, ga_N_per_V, gs_V_per_m (declared)
    doc.update(nlohmann::json{{"formulas", "ka = cE A / L, ga = d33 n ka, gs = d33 / (eps_T sD n) (report eq. 4.1)"},
                {"constants",
                 {{"d33_m_per_V", k.d33},
                  {"eps_t_F_per_m", k.eps_t},
                  {"s_d_m2_per_N", k.s_d},
                  {"c_e_N_per_m2", k.c_e},
                  {"length_m", k.length},
                  {"area_m2", k.area},
                  {"layers", k.layers}}}});
    print_json(doc);
    return 0;
  }
  fmt::print("stack sensitivities from piezo constants (report eq. 4.1)\n");
  fmt::print("  ka = cE A / L           = {:.6g} N/m ({:.4g} N/um)\n", s.ka, s.ka * 1e-6);
  fmt::print("  ga = d33 n ka           = {:.6g} N/V\n", s.ga);
  fmt::print("  gs = d33 / (eps_T sD n) = {:.6g} V/m ({:.4g} V/um)\n", s.gs, s.gs * 1e-6);
  fmt::print("  signs: magnitudes; the 2-DoF model's convention gives ga the sign < 0 and gs > 0 (docs/models.md)\n");
  return 0;
}

void add_bench_options(CLI::App* cmd, apa::TwoDofBench& b) {
  cmd->add_option("--amplifier-gain", b.amplifier_gain, "voltage amplifier gain Va/u, V/V")->capture_default_str();
  cmd->add_option("--hpf-r", b.hpf_resistance, "resistor across the sensor stack, Ohm (with --hpf-c: high-pass on Vs)");
  cmd->add_option("--hpf-c", b.hpf_capacitance, "sensor stack capacitance, F (with --hpf-r)");
  cmd->add_option("--delay", b.delay, "pure delay on u, s");
}

}  // namespace

void add_model_commands(CLI::App& app, Action& action) {
  CLI::App* model = app.add_subcommand("model", "Actuator models: the 2-DoF model of the APA and its tuning");
  model->require_subcommand(1);

  auto t = std::make_shared<TwoDofCommand>();
  CLI::App* two = model->add_subcommand("2dof", "Poles, zeros, static gains and FRFs u -> d_e, u -> Vs of the 2-DoF model");
  two->add_option("--params", t->params_file, "TOML file with m, k1, c1, ke, ce, ka, ca, ga, gs (SI); default Table 3.1")
      ->check(input_file());
  two->add_option("--fmin", t->fmin, "lowest frequency of the FRF, Hz")->capture_default_str();
  two->add_option("--fmax", t->fmax, "highest frequency of the FRF, Hz")->capture_default_str();
  two->add_option("--points", t->points, "number of log-spaced frequencies")->check(CLI::Range(2, 1000000))->capture_default_str();
  add_bench_options(two, t->bench);
  two->add_option("--added-mass", t->bench.added_mass, "mass added on the suspended mass, kg");
  two->add_option("--suspended-mass", t->bench.suspended_mass, "suspended mass replacing the model's m, kg");
  two->add_flag("--json", t->json, "print one JSON document on stdout");
  two->callback([t, &action] { action = [t] { return run_two_dof(*t); }; });

  auto u = std::make_shared<TuneCommand>();
  CLI::App* tune = model->add_subcommand("tune", "Fit the 9 parameters of the 2-DoF model to measured FRFs u -> de, u -> Vs");
  tune->add_option("--frf", u->frf_file, "FRF file (.csv, .mat, .uff) with outputs de and Vs, input u")
      ->required()
      ->check(input_file());
  tune->add_option("--mass", u->options.mass, "known moving mass m, kg")->capture_default_str();
  add_bench_options(tune, u->options.bench);
  tune->add_option("--fmin", u->options.fmin_Hz, "lowest frequency used, Hz (default: 20 Hz as `run`, or where the coherence reaches 0.5)");
  tune->add_option("--fmax", u->options.fmax_Hz, "highest frequency used, Hz (default: 500 Hz as `run`, or where the coherence falls below 0.5)");
  tune->add_option("--min-coherence", u->options.min_coherence, "leave out frequencies with a lower coherence (default 0.5 when the file has coherence)");
  tune->add_option("--stack-ratio", u->options.stack_stiffness_ratio, "ke/ka kept during the refinement (0 = free)")
      ->capture_default_str();
  tune->add_option("--damping-ratio", u->options.stack_damping_ratio, "ce/ca kept during the refinement (0 = free)")
      ->capture_default_str();
  tune->add_flag("--free-ratios", u->free_ratios, "free ke and ce (both ratios 0): parameters the data do not determine are reported undetermined");
  tune->add_option("--de-output", u->options.de_output, "name of the displacement output")->capture_default_str();
  tune->add_option("--vs-output", u->options.vs_output, "name of the force-sensor output")->capture_default_str();
  tune->add_flag("--no-window-resolution", u->no_window_resolution,
                 "compare the models with the FRF directly, not through its Welch window's resolution kernel (which is used when "
                 "the file gives the window, nfft and sample rate)");
  tune->add_flag("--no-refine", u->no_refine, "stop after the report's procedure (no least-squares refinement)");
  tune->add_flag("--json", u->json, "print one JSON document on stdout");
  add_units_option(tune, u->units);
  tune->callback([u, tune, &action] {
    u->min_coherence_given = tune->count("--min-coherence") > 0;
    u->delay_given = tune->count("--delay") > 0;
    action = [u] { return run_tune(*u); };
  });

  auto pz = std::make_shared<PiezoCommand>();
  CLI::App* piezo = app.add_subcommand("piezo", "Stack sensitivities ga, gs and stiffness ka from piezo constants (eq. 4.1)");
  apa::PiezoConstants& k = pz->constants;
  piezo->add_option("--d33", k.d33, "piezoelectric constant d33, m/V")->capture_default_str();
  piezo->add_option("--eps-t", k.eps_t, "permittivity at constant stress, F/m")->capture_default_str();
  piezo->add_option("--s-d", k.s_d, "compliance at constant electric displacement, m^2/N")->capture_default_str();
  piezo->add_option("--c-e", k.c_e, "Young's modulus at constant field, N/m^2")->capture_default_str();
  piezo->add_option("--length", k.length, "stack length, m")->capture_default_str();
  piezo->add_option("--area", k.area, "stack cross-section, m^2")->capture_default_str();
  piezo->add_option("--layers", k.layers, "number of layers per stack (integer >= 1)")->capture_default_str();
  piezo->add_flag("--json", pz->json, "print one JSON document on stdout");
  piezo->callback([pz, &action] { action = [pz] { return run_piezo(*pz); }; });
}

}  // namespace piezobench::app
