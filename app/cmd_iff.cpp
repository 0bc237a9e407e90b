// `piezobench iff rlocus`: root locus of the Integral Force Feedback loop (report section 2.6).
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "cli_common.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/io/lti_toml.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"

namespace piezobench::app {
namespace {

struct RlocusOptions {
  std::string plant_file;
  std::string controller_file;
  std::string gains;
  double delay = 0.0;
  int pade_order = 6;
  double resonance_hz = 0.0;
  bool json = false;
};

struct LoadedSystem {
  lti::StateSpace system;
  nlohmann::json description;
};

LoadedSystem load_plant(const RlocusOptions& o) {
  LoadedSystem out;
  if (o.plant_file.empty()) {
    const control::IffPlantParams p;
    out.system = lti::to_state_space(control::iff_plant(p));
    out.description = {{"source", "report eq. 2.3"},
                       {"g0", p.g0},
                       {"wz_Hz", p.wz / (2 * std::numbers::pi)},
                       {"xz", p.xz},
                       {"wp_Hz", p.wp / (2 * std::numbers::pi)},
                       {"xp", p.xp},
                       {"w_hpf_Hz", p.w_hpf / (2 * std::numbers::pi)}};
  } else {
    io::LtiFile f = io::read_lti_toml(o.plant_file);
    out.system = std::move(f.system);
    out.description = {{"source", o.plant_file}, {"form", io::to_string(f.form)}, {"description", f.description}};
  }
  if (o.delay > 0.0) {
    if (out.system.input_delay.size() == 0) out.system.input_delay = lti::Vector::Zero(out.system.inputs());
    out.system.input_delay.array() += o.delay;
  }
  out.description["delay_s"] = out.system.input_delay.size() > 0 ? out.system.input_delay(0) : 0.0;
  return out;
}

LoadedSystem load_controller(const RlocusOptions& o) {
  LoadedSystem out;
  if (o.controller_file.empty()) {
    out.system = lti::to_state_space(control::iff_controller());
    out.description = {{"source", "report eq. 2.4"}, {"formula", "K(s) = -10 g s/(s + 2 pi 2)/(s + 2 pi 20)/(s + 2 pi 2000)"}};
  } else {
    io::LtiFile f = io::read_lti_toml(o.controller_file);
    out.system = std::move(f.system);
    out.description = {{"source", o.controller_file}, {"form", io::to_string(f.form)}, {"description", f.description}};
  }
  return out;
}

double hz(lti::Complex pole) { return lti::pole_info(pole).natural_frequency / (2 * std::numbers::pi); }

int run_rlocus(const RlocusOptions& o) {
  if (!(std::isfinite(o.delay) && o.delay >= 0.0)) {
    throw InputError("", "--delay", "a delay >= 0 s", std::to_string(o.delay));
  }
  const LoadedSystem plant = load_plant(o);
  const LoadedSystem controller = load_controller(o);
  const std::vector<double> gains = o.gains.empty() ? std::vector<double>{} : parse_number_list(o.gains, "--gains");

  control::IffLoopOptions options;
  options.pade_order = o.pade_order;
  if (o.resonance_hz > 0.0) options.resonance = 2 * std::numbers::pi * o.resonance_hz;
  if (!o.json) log_line("computing the root locus" + std::string(gains.empty() ? " on an automatic gain grid" : ""));
  const control::IffRootLocus r = control::iff_root_locus(plant.system, controller.system, gains, options);

  if (o.json) {
    nlohmann::json poles = nlohmann::json::array();
    nlohmann::json branch = nlohmann::json::array();
    for (const auto& p : r.locus.poles) {
      poles.push_back(io::to_json(p));
      branch.push_back(io::to_json(p(r.resonance_branch)));
    }
    print_json({{"convention", "u = u' + g K(s) Vs with Vs = G(s) u; closed-loop poles solve 1 - g K(s) G(s) = 0"},
                {"plant", plant.description},
                {"controller", controller.description},
                {"pade_order", (plant.system.has_delay() || controller.system.has_delay()) ? nlohmann::json(o.pade_order) : nlohmann::json(nullptr)},
                {"gains", io::to_json(r.locus.gains)},
                {"poles", poles},
                {"resonance_pole", io::to_json(r.resonance_pole)},
                {"resonance_branch", branch},
                {"optimal_gain", io::to_json(r.optimum.gain)},
                {"max_damping", io::to_json(r.optimum.damping)},
                {"optimal_pole", io::to_json(r.optimum.pole)},
                {"optimal_frequency_Hz", io::to_json(hz(r.optimum.pole))}});
    return 0;
  }
  fmt::print("IFF root locus: u = u' + g K(s) Vs (report Figure 2.9)\n");
  fmt::print("plant: {}, controller: {}\n", plant.description["source"].get<std::string>(),
             controller.description["source"].get<std::string>());
  fmt::print("branch from the resonance pole {:.4g} Hz (damping {:.4g}):\n", hz(r.resonance_pole),
             lti::pole_info(r.resonance_pole).damping);
  fmt::print("{:>14}  {:>26}  {:>10}  {:>9}\n", "gain g", "pole [rad/s]", "f [Hz]", "damping");
  for (std::size_t i = 0; i < r.locus.gains.size(); ++i) {
    const lti::Complex p = r.locus.poles[i](r.resonance_branch);
    fmt::print("{:>14.6g}  {:>12.6g} {:+12.6g}j  {:>10.4g}  {:>9.4f}\n", r.locus.gains[i], p.real(), p.imag(), hz(p),
               lti::pole_info(p).damping);
  }
  fmt::print("optimal gain {:.6g}: damping {:.4f} at {:.4g} Hz\n", r.optimum.gain, r.optimum.damping, hz(r.optimum.pole));
  return 0;
}

}  // namespace

void add_iff_commands(CLI::App& app, Action& action) {
  CLI::App* iff = app.add_subcommand("iff", "Integral Force Feedback: root locus and damping of the IFF loop");
  iff->require_subcommand(1);
  auto o = std::make_shared<RlocusOptions>();
  CLI::App* rl = iff->add_subcommand("rlocus", "Closed-loop poles of the IFF loop u = u' + g K(s) Vs against the gain g");
  rl->add_option("--plant", o->plant_file, "TOML file with the plant u -> Vs (tf, zpk or ss); default: report eq. 2.3")
      ->check(CLI::ExistingFile);
  rl->add_option("--controller", o->controller_file, "TOML file with K(s) at g = 1; default: report eq. 2.4")
      ->check(CLI::ExistingFile);
  rl->add_option("--gains", o->gains, "comma-separated gains g (default: an automatic grid that follows every branch)");
  rl->add_option("--delay", o->delay, "pure delay added to the plant, s (the report's fit uses 200e-6)");
  rl->add_option("--pade-order", o->pade_order, "order of the Pade approximant of delays in the loop")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  rl->add_option("--resonance-hz", o->resonance_hz,
                 "frequency of the resonance whose damping is optimized (default: the plant's least damped pole)");
  rl->add_flag("--json", o->json, "print one JSON document on stdout");
  rl->callback([o, &action] { action = [o] { return run_rlocus(*o); }; });
}

}  // namespace piezobench::app
