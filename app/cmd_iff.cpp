// `piezobench iff rlocus`: root locus of the Integral Force Feedback loop (report section 2.6);
// `piezobench iff study`: the damped-plant study on the virtual bench (Figure 2.10).
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

#include "cli_common.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/io/lti_toml.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/rt/damped_plant_study.hpp"

namespace piezobench::app {
namespace {

struct RlocusOptions {
  std::string plant_file;
  std::string controller_file;
  std::string gains;
  double delay = 0.0;
  int pade_order = 6;
  double resonance_Hz = 0.0;
  int max_order = lti::RootLocusOptions{}.max_order;
  double max_work = lti::RootLocusOptions{}.max_work;
  std::string out;  // the JSON document (with the full table) also written here
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
                       {"wz_Hz", p.wz / kTwoPi},
                       {"xz", p.xz},
                       {"wp_Hz", p.wp / kTwoPi},
                       {"xp", p.xp},
                       {"w_hpf_Hz", p.w_hpf / kTwoPi}};
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

double hz(lti::Complex pole) { return lti::pole_info(pole).natural_frequency / kTwoPi; }

// The first gain of the locus at which a closed-loop pole crosses into the right half plane, and
// that pole; nullopt when the loop is stable at every gain computed. A pole counts as unstable past
// a relative real part of 1e-9 (the integrator-like poles of the controller sit on the axis at g = 0).
struct Instability {
  double gain = 0.0;
  lti::Complex pole;
};
std::optional<Instability> first_unstable_gain(const lti::RootLocus& locus) {
  for (std::size_t i = 0; i < locus.gains.size(); ++i) {
    for (const lti::Complex p : locus.poles[i]) {
      if (p.real() > 1e-9 * std::max(1.0, std::abs(p))) return Instability{locus.gains[i], p};
    }
  }
  return std::nullopt;
}

int run_rlocus(const RlocusOptions& o) {
  if (!(std::isfinite(o.delay) && o.delay >= 0.0)) {
    throw UsageError("--delay", "a delay >= 0 s", format_number_exact(o.delay));
  }
  const LoadedSystem plant = load_plant(o);
  const LoadedSystem controller = load_controller(o);
  const std::vector<double> gains = o.gains.empty() ? std::vector<double>{} : parse_number_list(o.gains, "--gains");

  control::IffLoopOptions options;
  options.pade_order = o.pade_order;
  options.locus.max_order = o.max_order;
  options.locus.max_work = o.max_work;
  const lti::Index order = plant.system.states() + controller.system.states();
  if (order > o.max_order) {
    throw InputError(o.plant_file.empty() ? o.controller_file : o.plant_file, "order",
                     "a loop (plant and controller) of at most " + std::to_string(o.max_order) + " states (--max-order)",
                     std::to_string(order) + " states");
  }
  if (o.resonance_Hz > 0.0) options.resonance = kTwoPi * o.resonance_Hz;
  if (!o.json) log_line("computing the root locus" + std::string(gains.empty() ? " on an automatic gain grid" : ""));
  const control::IffRootLocus r = control::iff_root_locus(plant.system, controller.system, gains, options);

  const std::optional<Instability> unstable = first_unstable_gain(r.locus);
  const double largest = r.locus.gains.empty() ? 0.0 : r.locus.gains.back();
  if (o.json || !o.out.empty()) {
    nlohmann::json poles = nlohmann::json::array();
    nlohmann::json branch = nlohmann::json::array();
    for (const auto& p : r.locus.poles) {
      poles.push_back(io::to_json(p));
      branch.push_back(io::to_json(p(r.resonance_branch)));
    }
    const nlohmann::json document = {
                {"convention", "u = u' + g K(s) Vs with Vs = G(s) u; closed-loop poles solve 1 - g K(s) G(s) = 0"},
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
                {"optimal_frequency_Hz", io::to_json(hz(r.optimum.pole))},
                {"unstable_from_gain", unstable ? io::to_json(unstable->gain) : nlohmann::json(nullptr)},
                {"unstable_pole", unstable ? io::to_json(unstable->pole) : nlohmann::json(nullptr)},
                {"largest_gain", io::to_json(largest)}};
    if (!o.out.empty()) io::write_text_atomically(o.out, document.dump(2) + "\n");
    if (o.json) {
      print_json(document);
      return 0;
    }
  }
  fmt::print("IFF root locus: u = u' + g K(s) Vs (report Figure 2.9)\n");
  fmt::print("plant: {}, controller: {}\n", plant.description["source"].get<std::string>(),
             controller.description["source"].get<std::string>());
  fmt::print("branch from the resonance pole {:.4g} Hz (damping {:.4g}):\n", hz(r.resonance_pole),
             lti::pole_info(r.resonance_pole).damping);
  // The summary; the full table of gains and poles is in the JSON document (--json, --out).
  fmt::print("maximum damping: gain g = {:.6g} (a factor on K(s)), damping ratio {:.4f} at {:.4g} Hz, pole {:.6g} {:+.6g}j rad/s\n",
             r.optimum.gain, r.optimum.damping, hz(r.optimum.pole), r.optimum.pole.real(), r.optimum.pole.imag());
  if (unstable) {
    fmt::print("unstable from gain g = {:.6g}: a closed-loop pole at {:.6g} {:+.6g}j rad/s ({:.4g} Hz) in the right half plane\n",
               unstable->gain, unstable->pole.real(), unstable->pole.imag(), hz(unstable->pole));
  } else {
    fmt::print("stable at every gain computed (g = 0 to {:.6g})\n", largest);
  }
  fmt::print("{} gains computed; the table of gains and closed-loop poles: --json or --out FILE.json\n", r.locus.gains.size());
  return 0;
}

// `iff study`: the damped-plant study of Figure 2.10 on the virtual bench (rt/damped_plant_study.hpp).
struct StudyOptions {
  std::string gains = "0,20000,50000,100000,200000,240000,280000";
  int unit = 1;
  std::uint64_t seed = 1;
  double duration = 10.0;
  double settle = 2.0;
  double amplitude = 0.05;
  bool strict = false;
  bool json = false;
};

int run_study(const StudyOptions& o) {
  rt::DampedPlantStudyOptions so;
  so.gains = parse_number_list(o.gains, "--gains");
  so.unit = o.unit;
  so.seed = o.seed;
  so.duration = o.duration;
  so.settle = o.settle;
  so.excitation_rms = o.amplitude;
  if (!o.json) log_line(fmt::format("damped-plant study: {} gains, {:g} s each on the virtual bench (lockstep)", so.gains.size(), o.settle + o.duration));
  const rt::DampedPlantStudy s = rt::run_damped_plant_study(so);
  const int exit_code = o.strict && !(s.within_tolerance && s.damping_increases_to_optimum) ? 5 : 0;
  if (o.json) {
    nlohmann::json gains = nlohmann::json::array(), id = nlohmann::json::array(), model = nlohmann::json::array(),
                   err = nlohmann::json::array(), id_damping = nlohmann::json::array(),
                   model_damping = nlohmann::json::array(), id_Hz = nlohmann::json::array(),
                   model_Hz = nlohmann::json::array(), so_poles = nlohmann::json::array(),
                   so_damping = nlohmann::json::array(), so_err = nlohmann::json::array(),
                   frf_rms = nlohmann::json::array(), coherence = nlohmann::json::array(),
                   fit_rms = nlohmann::json::array(), clamped = nlohmann::json::array();
    for (const auto& p : s.points) {
      gains.push_back(p.gain);
      id.push_back(io::to_json(p.identified_pole));
      model.push_back(io::to_json(p.model_pole));
      err.push_back(p.relative_error);
      id_damping.push_back(p.identified_damping);
      model_damping.push_back(p.model_damping);
      id_Hz.push_back(p.identified_frequency_Hz);
      model_Hz.push_back(p.model_frequency_Hz);
      so_poles.push_back(io::to_json(p.second_order_pole));
      so_damping.push_back(p.second_order_damping);
      so_err.push_back(p.second_order_relative_error);
      frf_rms.push_back(p.frf_model_relative_rms);
      coherence.push_back(p.mean_coherence);
      fit_rms.push_back(p.fit_relative_rms_error);
      clamped.push_back(p.clamped_samples);
    }
    print_json({{"convention", "u = u' + g K(z) Vs on the virtual bench; identified: u' -> d_e; model: root locus of linear_model() u -> Vs with K(s)"},
                {"unit", o.unit},
                {"seed", o.seed},
                {"model", s.model},
                {"delay_s", s.delay},
                {"gains", gains},
                {"identified_poles", id},
                {"model_poles", model},
                {"relative_errors", err},
                {"identified_damping", id_damping},
                {"model_damping", model_damping},
                {"identified_frequency_Hz", id_Hz},
                {"model_frequency_Hz", model_Hz},
                {"second_order", {{"poles", so_poles}, {"damping", so_damping}, {"relative_errors", so_err}}},
                {"fit_relative_rms_error", fit_rms},
                {"frf_model_relative_rms", frf_rms},
                {"mean_coherence", coherence},
                {"clamped_samples", clamped},
                {"open_loop_pole", io::to_json(s.open_loop_pole)},
                {"optimal_gain", s.optimal_gain},
                {"max_damping", s.max_damping},
                {"max_relative_error", s.max_relative_error},
                {"tolerance", so.tolerance},
                {"within_tolerance", s.within_tolerance},
                {"damping_increases_to_optimum", s.damping_increases_to_optimum}});
    return exit_code;
  }
  fmt::print("damped plant u' -> d_e on the virtual bench (unit {}, seed {}), report Figure 2.10\n", o.unit, o.seed);
  fmt::print("{:>10}  {:>22}  {:>22}  {:>7}  {:>16}\n", "gain g", "identified f [Hz], z", "model f [Hz], z", "error", "2nd-order error");
  for (const auto& p : s.points) {
    fmt::print("{:>10.4g}  {:>12.2f}, {:>7.4f}  {:>12.2f}, {:>7.4f}  {:>6.2f}%  {:>15.2f}%\n", p.gain, p.identified_frequency_Hz,
               p.identified_damping, p.model_frequency_Hz, p.model_damping, 100 * p.relative_error,
               100 * p.second_order_relative_error);
  }
  fmt::print("model optimum: g = {:.4g}, damping {:.4f}\n", s.optimal_gain, s.max_damping);
  fmt::print("check: identified poles within {:g} % of the root locus: {}; damping grows with the gain up to the optimum: {}\n",
             100 * so.tolerance, s.within_tolerance ? "yes" : "NO", s.damping_increases_to_optimum ? "yes" : "NO");
  return exit_code;
}

}  // namespace

void add_iff_commands(CLI::App& app, Action& action) {
  CLI::App* iff = app.add_subcommand("iff", "Integral Force Feedback: root locus and damping of the IFF loop");
  iff->require_subcommand(1);
  auto o = std::make_shared<RlocusOptions>();
  CLI::App* rl = iff->add_subcommand("rlocus", "Closed-loop poles of the IFF loop u = u' + g K(s) Vs against the gain g");
  rl->add_option("--plant", o->plant_file, "TOML file with the plant u -> Vs (tf, zpk or ss); default: report eq. 2.3")
      ->check(input_file());
  rl->add_option("--controller", o->controller_file, "TOML file with K(s) at g = 1; default: report eq. 2.4")
      ->check(input_file());
  rl->add_option("--gains", o->gains, "comma-separated gains g (default: an automatic grid that follows every branch)");
  rl->add_option("--delay", o->delay, "pure delay added to the plant, s (the report's fit uses 200e-6)");
  rl->add_option("--pade-order", o->pade_order, "order of the Pade approximant of delays in the loop")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  rl->add_option("--resonance-hz", o->resonance_Hz,
                 "frequency of the resonance whose damping is optimized (default: the plant's least damped pole)");
  rl->add_option("--max-order", o->max_order, "largest loop order (plant + controller states) accepted")
      ->check(CLI::Range(1, 5000))
      ->capture_default_str();
  rl->add_option("--max-work", o->max_work,
                 "work budget of the automatic gain grid: eigenvalue problems x order^3 (exit 4 when exceeded)")
      ->check(number_in(1e3, 1e15))
      ->capture_default_str();
  rl->add_flag("--json", o->json, "print one JSON document on stdout (with the full table of gains and poles)");
  rl->add_option("--out", o->out, "write that JSON document to this file too")->check(output_extension({".json"}));
  rl->callback([o, &action] { action = [o] { return run_rlocus(*o); }; });

  auto so = std::make_shared<StudyOptions>();
  CLI::App* st = iff->add_subcommand("study", "Damped-plant study (Figure 2.10): identified poles vs the root locus, on the virtual bench");
  st->add_option("--gains", so->gains, "comma-separated IFF gains g")->capture_default_str();
  st->add_option("--unit", so->unit, "unit of the batch (1..7)")->capture_default_str();
  st->add_option("--seed", so->seed, "unit, noise and excitation seed")->capture_default_str();
  st->add_option("--duration", so->duration, "seconds analysed per gain (whole periods of 1 s)")->capture_default_str();
  st->add_option("--settle", so->settle, "seconds discarded at the start of each run")->capture_default_str();
  st->add_option("--amplitude", so->amplitude, "excitation u' rms, V at the DAC")->capture_default_str();
  st->add_flag("--strict", so->strict, "exit with code 5 when a check fails");
  st->add_flag("--json", so->json, "print one JSON document on stdout");
  st->callback([so, &action] { action = [so] { return run_study(*so); }; });
}

}  // namespace piezobench::app
