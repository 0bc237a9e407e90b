// `piezobench twin`: the digital twin of one unit (campaign/twin.hpp, docs/twin.md), from its entry
// in a campaign file or from its records given on the command line, written as the TOML file that
// `simulate --twin`, `measure --bench` (virtual, `twin = "FILE"`) and `bench serve --twin` accept.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <sstream>
#include <toml++/toml.h>

#include "cli_common.hpp"
#include "piezobench/bench/twin.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/twin.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/fields_json.hpp"

namespace piezobench::app {
namespace {

struct TwinArgs {
  std::string campaign;
  int unit = 0;
  std::string frf, stiffness, capacitance;
  std::vector<std::string> hysteresis, quiet;
  double amplifier_gain = 20.0, mass = 5.7, hpf_resistance = 80.6e3;
  campaign::TwinOptions options;
  std::string out = "twin.toml";
  bool json = false;
};

std::string toml_string(const std::string& s) {
  std::ostringstream out;
  out << toml::value<std::string>(s);
  return out.str();
}

// The records form: a one-unit campaign in memory, the paths as given (relative to the working
// directory), the bench's default channel names.
campaign::Campaign records_campaign(const TwinArgs& a) {
  std::string text = fmt::format("[bench]\namplifier_gain = {:.17g}\nsuspended_mass_kg = {:.17g}\nhpf_resistance_ohm = {:.17g}\n\n",
                                 a.amplifier_gain, a.mass, a.hpf_resistance);
  text += fmt::format("[[units]]\nid = {}\nfrf = {}\n", a.unit > 0 ? a.unit : 1, toml_string(a.frf));
  if (!a.stiffness.empty()) text += "stiffness = " + toml_string(a.stiffness) + "\n";
  if (!a.capacitance.empty()) text += "capacitance = " + toml_string(a.capacitance) + "\n";
  if (!a.hysteresis.empty()) {
    text += "hysteresis = [";
    for (std::size_t i = 0; i < a.hysteresis.size(); ++i) text += (i ? ", " : "") + toml_string(a.hysteresis[i]);
    text += "]\n";
  }
  return campaign::parse_campaign(text, std::filesystem::current_path() / "twin (command line)", true);
}

// The build's declared fields (campaign/twin.hpp: FRF errors, hysteresis checks, noise, creep, IFF,
// quality, notes and what it shows of the twin's chain), then what the declaration leaves to this
// command: the file written and the twin's model, in SI as in the file's [model].
nlohmann::json build_json(const campaign::TwinBuild& b, const std::string& file) {
  const apa::TwoDofParams& p = b.twin.unit.model;
  nlohmann::json doc = io::results_object(b);
  doc["file"] = file;
  doc["model"] = {{"k1", p.k1}, {"c1", p.c1}, {"ke", p.ke}, {"ce", p.ce}, {"ka", p.ka}, {"ca", p.ca}, {"ga", p.ga}, {"gs", p.gs}};
  return doc;
}

void print_build(const campaign::TwinBuild& b, const std::string& file) {
  const apa::TwoDofParams& p = b.twin.unit.model;
  fmt::print("Digital twin of {} (unit {}): {} ({:.2f} s)\n", b.twin.name, b.twin.unit.id, file, b.seconds);
  fmt::print("  model: k1 {:.4g} N/um, ka {:.4g} N/um, ke {:.4g} N/um, ga {:.4g} N/V, gs {:.4g} V/um; delay {:.1f} us, R_g {:.3g} Ohm\n",
             1e-6 * p.k1, 1e-6 * p.ka, 1e-6 * p.ke, p.ga, 1e-6 * p.gs, 1e6 * b.twin.options.delay, b.twin.options.ground_resistance);
  fmt::print("  FRF against the unit's (coherence >= 0.9): u -> d_e max {:.2f} dB ({} points), u -> Vs max {:.2f} dB ({} points)\n", b.de.max_dB,
             b.de.points, b.vs.max_dB, b.vs.points);
  for (const auto& h : b.hysteresis) {
    fmt::print("  hysteresis at {:.3g} V: width {:.2f} % (unit {:.2f} %)\n", h.amplitude, 100.0 * h.twin_width, 100.0 * h.unit_width);
  }
  for (const auto* n : {&b.de_noise, &b.vs_noise}) {
    fmt::print("  noise {}: {:.4g} rms white{}\n", n->channel, n->white_rms, n->measured ? " (from " + n->source + ")" : " (not measured)");
  }
  fmt::print("  IFF optimum of the report's controller: g = {:.4g} (damping {:.3f}){}\n", b.iff_optimal_gain, b.iff_max_damping,
             b.iff_optimal_gain_unit ? fmt::format("; on the unit's fitted plant g = {:.4g}", *b.iff_optimal_gain_unit) : std::string());
  for (const auto& n : b.notes) fmt::print("  note: {}\n", n);
  fmt::print("  {}\n", b.quality.summary());
}

int run_twin(TwinArgs a) {
  const bool from_campaign = !a.campaign.empty();
  if (from_campaign == !a.frf.empty()) throw UsageError("twin: give either CAMPAIGN.toml --unit ID or --frf FILE (the unit's records)");
  for (const auto& q : a.quiet) a.options.quiet.emplace_back(q);
  try {
    a.options.validate();
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
  const campaign::Campaign c = from_campaign ? campaign::read_campaign(a.campaign) : records_campaign(a);
  const campaign::UnitSpec* unit = nullptr;
  for (const auto& u : c.units) {
    if (!from_campaign || u.id == a.unit) unit = &u;
  }
  if (unit == nullptr) throw UsageError("--unit", "a unit id of " + a.campaign, std::to_string(a.unit));
  const campaign::TwinBuild b = campaign::build_twin(c, *unit, a.options, a.json ? campaign::Log{} : campaign::Log{log_line});
  bench::write_twin(a.out, b.twin);
  if (a.json) {
    print_json(build_json(b, a.out));
  } else {
    print_build(b, a.out);
  }
  return report_quality(b.quality);
}

}  // namespace

void add_twin_commands(CLI::App& app, Action& action) {
  auto a = std::make_shared<TwinArgs>();
  CLI::App* t = app.add_subcommand("twin", "The digital twin of one unit (its virtual bench) from its records or its campaign entry");
  t->add_option("campaign", a->campaign, "campaign file (TOML) holding the unit's records");
  t->add_option("--unit", a->unit, "the unit's id in the campaign (with --frf: the id written in the twin)");
  t->add_option("--frf", a->frf, "without a campaign: the unit's FRF record (u, de, Vs)");
  t->add_option("--hysteresis", a->hysteresis, "without a campaign: hysteresis records (Va, de), one per amplitude")->delimiter(',');
  t->add_option("--stiffness", a->stiffness, "without a campaign: the static stiffness record (de, added_mass)");
  t->add_option("--capacitance", a->capacitance, "without a campaign: the LCR readings (C_sensor, C_actuator)");
  t->add_option("--amplifier-gain", a->amplifier_gain, "without a campaign: V/V")->capture_default_str();
  t->add_option("--mass", a->mass, "without a campaign: suspended mass, kg")->capture_default_str();
  t->add_option("--hpf-resistance", a->hpf_resistance, "without a campaign: resistor across the sensor stack, Ohm")->capture_default_str();
  t->add_option("--quiet", a->quiet, "records with quiet segments (de, Vs; u and Va held) for the noise spectra")->delimiter(',');
  t->add_option("--min-coherence", a->options.min_coherence, "FRF points the model is refined on and judged by")->capture_default_str();
  t->add_option("--fmin", a->options.fmin_Hz, "band of the FRF refinement, Hz")->capture_default_str();
  t->add_option("--fmax", a->options.fmax_Hz, "band of the FRF refinement, Hz")->capture_default_str();
  t->add_option("-o,--out", a->out, "the twin file (TOML)")->capture_default_str();
  t->add_flag("--json", a->json, "print one JSON document on stdout");
  t->callback([a, &action] { action = [a] { return run_twin(*a); }; });
}

}  // namespace piezobench::app
