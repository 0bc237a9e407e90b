// `piezobench superelement update`: model updating of a campaign's super element against the
// batch's measured resonance and anti-resonance (issue 31; campaign/superelement_update.hpp).
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/superelement_update.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/fem/matrix_io.hpp"

namespace piezobench::app {
namespace {

namespace fs = std::filesystem;

struct UpdateCli {
  std::string results;
  std::string campaign;
  std::vector<std::string> stacks;
  std::vector<std::string> parameters{"shell", "stacks"};
  double shell_modulus = 0.0;
  double rank_tolerance = 0.05;
  std::string out;
  bool json = false;
};

nlohmann::json read_results(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "file", "a results.json of `piezobench run` or `demo`", "a file that cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    nlohmann::json doc = nlohmann::json::parse(text.str());
    if (!doc.is_object() || !doc.contains("units") || !doc["units"].is_array()) throw InputError(file, "units", "an array of units", "none");
    return doc;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file, "", "a JSON document (results.json)", e.what());
  }
}

// The accepted units' measured resonance and anti-resonance (results.json units[].frf).
std::vector<campaign::UpdateTarget> targets_of(const nlohmann::json& doc, const std::string& file) {
  std::vector<campaign::UpdateTarget> t;
  for (const nlohmann::json& u : doc["units"]) {
    if (!u.is_object() || !u.value("accepted", false) || !u.contains("frf") || !u["frf"].is_object()) continue;
    const nlohmann::json& f = u["frf"];
    if (!f.contains("resonance_Hz") || !f["resonance_Hz"].is_number() || !f.contains("antiresonance_Hz") || !f["antiresonance_Hz"].is_number()) continue;
    t.push_back({u.value("name", std::string("unit")), f["resonance_Hz"].get<double>(), f["antiresonance_Hz"].get<double>()});
  }
  if (t.empty()) throw InputError(file, "units", "accepted units with a measured resonance and anti-resonance", "none");
  return t;
}

fs::path campaign_of(const UpdateCli& o, const nlohmann::json& doc) {
  if (!o.campaign.empty()) return o.campaign;
  if (!doc.contains("campaign") || !doc["campaign"].is_string()) throw InputError(o.results, "campaign", "the campaign file's path (or --campaign)", "none");
  fs::path c = doc["campaign"].get<std::string>();
  if (c.is_relative() && !fs::exists(c)) c = fs::path(o.results).parent_path() / c;
  if (!fs::exists(c)) c = fs::path(o.results).parent_path() / c.filename();  // a batch folder moved since
  return c;
}

nlohmann::json to_json(const campaign::SuperElementUpdate& u) {
  nlohmann::json params = nlohmann::json::array();
  for (const campaign::UpdatedParameter& p : u.parameters) {
    params.push_back({{"name", p.name}, {"scale", p.scale}, {"standard_error", p.standard_error ? nlohmann::json(*p.standard_error) : nlohmann::json(nullptr)},
                      {"modulus_Pa", p.modulus_Pa ? nlohmann::json(*p.modulus_Pa) : nlohmann::json(nullptr)}});
  }
  const auto matrix = [](const Eigen::MatrixXd& m) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      nlohmann::json r = nlohmann::json::array();
      for (Eigen::Index j = 0; j < m.cols(); ++j) r.push_back(m(i, j));
      rows.push_back(r);
    }
    return rows;
  };
  return {{"units", u.units},
          {"parameters", params},
          {"correlation", matrix(u.correlation)},
          {"sensitivity_rows", {"ln resonance", "ln antiresonance"}},
          {"sensitivity", matrix(u.sensitivity)},
          {"singular_values", std::vector<double>(u.singular_values.data(), u.singular_values.data() + u.singular_values.size())},
          {"rank", u.rank},
          {"condition", u.condition},
          {"target", {{"resonance_Hz", u.target_resonance_Hz}, {"antiresonance_Hz", u.target_antiresonance_Hz}}},
          {"initial", {{"resonance_Hz", u.initial_resonance_Hz}, {"antiresonance_Hz", u.initial_antiresonance_Hz}}},
          {"updated", {{"resonance_Hz", u.resonance_Hz}, {"antiresonance_Hz", u.antiresonance_Hz}}},
          {"iterations", u.iterations},
          {"warnings", u.warnings}};
}

void print_text(const campaign::SuperElementUpdate& u) {
  fmt::print("super element updated against {} unit(s): resonance {:.2f} Hz (was {:.2f}), anti-resonance {:.2f} Hz (was {:.2f}); "
             "measured {:.2f} / {:.2f} Hz\n",
             u.units, u.resonance_Hz, u.initial_resonance_Hz, u.antiresonance_Hz, u.initial_antiresonance_Hz, u.target_resonance_Hz,
             u.target_antiresonance_Hz);
  for (const campaign::UpdatedParameter& p : u.parameters) {
    fmt::print("  {:<22} scale {:.4f}{}{}\n", p.name, p.scale, p.standard_error ? fmt::format(" +- {:.4f}", *p.standard_error) : std::string(" (no standard error)"),
               p.modulus_Pa ? fmt::format("  modulus {:.4g} GPa", *p.modulus_Pa * 1e-9) : std::string());
  }
  for (Eigen::Index i = 0; i < u.correlation.rows(); ++i) {
    for (Eigen::Index j = i + 1; j < u.correlation.cols(); ++j) {
      fmt::print("  correlation {} / {}: {:+.3f}\n", u.parameters[static_cast<std::size_t>(i)].name, u.parameters[static_cast<std::size_t>(j)].name, u.correlation(i, j));
    }
  }
  fmt::print("  sensitivity d ln(f_r, f_a) / d ln(scale): rank {}, condition {:.3g}\n", u.rank, u.condition);
  for (const std::string& w : u.warnings) fmt::print("warning: {}\n", w);
}

int run_update(const UpdateCli& o) {
  const nlohmann::json doc = read_results(o.results);
  const std::vector<campaign::UpdateTarget> targets = targets_of(doc, o.results);
  const campaign::Campaign c = campaign::read_campaign(campaign_of(o, doc));
  if (!c.superelement) throw InputError(c.file.string(), "superelement", "a [superelement] table (the element to update)", "none");
  campaign::SuperElementUpdateOptions opt;
  opt.bench.moving_mass = c.bench.suspended_mass;
  opt.bench.amplifier_gain = c.bench.amplifier_gain;
  opt.parameters = o.parameters;
  for (const std::string& s : o.stacks) opt.stacks.push_back(campaign::StackBeam::parse(s, "--stack " + s));
  opt.shell_modulus_Pa = o.shell_modulus;
  opt.rank_tolerance = o.rank_tolerance;
  if (!o.json) log_line(fmt::format("updating {} against {} unit(s)", c.superelement->given, targets.size()));
  const fem::SuperElement se = c.superelement->setup.load();
  const campaign::SuperElementUpdate u = campaign::update_superelement(se, c.superelement->setup, targets, opt);
  nlohmann::json out = to_json(u);
  if (!o.out.empty()) {
    std::error_code ec;
    fs::create_directories(o.out, ec);  // a failure is reported by the writer, naming the file
    const std::vector<fs::path> files = fem::write_super_element(o.out, "updated", u.element);
    out["written"] = nlohmann::json::array();
    for (const fs::path& f : files) out["written"].push_back(f.string());
  }
  if (o.json) {
    print_json(out);
  } else {
    print_text(u);
    if (!o.out.empty()) fmt::print("written: {}\n", o.out);
  }
  return 0;
}

}  // namespace

CLI::App* add_superelement_update_command(CLI::App& se, Action& action) {
  auto o = std::make_shared<UpdateCli>();
  CLI::App* u = se.add_subcommand(
      "update", "Model updating: scale the shell's and the stacks' moduli of a campaign's super element so that its bench model has the "
                "batch's measured resonance and anti-resonance; standard errors, correlation, refuses parameters the data do not determine");
  u->add_option("RESULTS", o->results, "results.json of `piezobench run` or `demo` (accepted units' frf.resonance_Hz, antiresonance_Hz)")
      ->required()
      ->check(input_file());
  u->add_option("--campaign", o->campaign, "the campaign file with the [superelement] table (default: the one results.json names)")->check(input_file());
  u->add_option("--stack", o->stacks, "a stack of the element as built: NODE_A:NODE_B:E,nu,rho,AREA (repeatable; required)")->required();
  u->add_option("--parameter", o->parameters, "shell, stacks or stack:NODE_A:NODE_B (repeatable)")->capture_default_str();
  u->add_option("--shell-modulus", o->shell_modulus, "the shell's modulus the element was built with, Pa (to print the updated one)")
      ->check(number_in(0.0, 1e15));
  u->add_option("--rank-tolerance", o->rank_tolerance, "singular values of the sensitivity below this fraction of the largest: undetermined")
      ->check(number_in(1e-9, 0.99))
      ->capture_default_str();
  u->add_option("--out", o->out, "write the updated element (updated_K.mtx, updated_M.mtx, updated_dofs.txt) here");
  u->add_flag("--json", o->json, "print one JSON document on stdout");
  u->callback([o, &action] { action = [o] { return run_update(*o); }; });
  return u;
}

}  // namespace piezobench::app
