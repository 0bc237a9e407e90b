// `piezobench superelement`: imports a super element (Ansys CMS text, CalculiX MATRIXSTORAGE dumps
// or Matrix Market), applies boundary conditions, point masses, stack force pairs and outputs, and
// returns the modes and the frequency response (report section 4).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/lti/freqresp.hpp"

namespace piezobench::app {
namespace {

using fem::Index;

struct SuperElementCli {
  std::string k_file, m_file, nodes_file;
  std::string nlist_file;
  std::string format = "auto";
  std::vector<long> fix;
  std::vector<std::string> forces, outputs, masses;
  std::string damping = "none";
  double fmin = 10.0, fmax = 10000.0;
  int points = 500;
  bool json = false;
};

fem::SuperElementFormat choose_format(const SuperElementCli& o) {
  if (o.format == "auto") return fem::detect_format(o.k_file);
  const auto f = fem::super_element_format_from_string(o.format);
  if (!f) throw InputError("", "--format", "auto, ansys, calculix or matrix-market", "'" + o.format + "'");
  return *f;
}

// Checks the command-line nodes against the element first, so that messages name the option.
fem::ModelOptions model_options(const SuperElementCli& o, const fem::SuperElement& se) {
  fem::ModelOptions m;
  for (long node : o.fix) {
    if (!se.has_node(node)) (void)se.index_of(node, fem::Direction::kX, "", "--fix");
    m.fixed_nodes.push_back(node);
  }
  for (const std::string& text : o.forces) {
    const fem::ForcePair f = fem::ForcePair::parse(text, "--force");
    if (f.node_a >= 0) (void)se.index_of(f.node_a, f.direction, "", "--force " + text);
    (void)se.index_of(f.node_b, f.direction, "", "--force " + text);
    m.forces.push_back(f);
  }
  for (const std::string& text : o.outputs) {
    const fem::DisplacementOutput out = fem::DisplacementOutput::parse(text, "--output");
    if (out.node_a >= 0) (void)se.index_of(out.node_a, out.direction, "", "--output " + text);
    (void)se.index_of(out.node_b, out.direction, "", "--output " + text);
    m.outputs.push_back(out);
  }
  for (const std::string& text : o.masses) {
    const fem::PointMass pm = fem::PointMass::parse(text, "--mass");
    (void)se.index_of(pm.node, fem::Direction::kX, "", "--mass " + text);
    m.masses.push_back(pm);
  }
  m.damping = fem::Damping::parse(o.damping, "--damping");
  return m;
}

int run_superelement(const SuperElementCli& o) {
  if (!(std::isfinite(o.fmin) && o.fmin > 0.0)) throw InputError("", "--fmin", "a frequency > 0 Hz", fmt::format("{}", o.fmin));
  if (!(std::isfinite(o.fmax) && o.fmax > o.fmin)) {
    throw InputError("", "--fmax", fmt::format("a frequency > --fmin ({} Hz)", o.fmin), fmt::format("{}", o.fmax));
  }
  const fem::SuperElementFormat format = choose_format(o);
  if (!o.json) log_line("reading the super element (" + fem::to_string(format) + ")");
  const fem::SuperElement se = fem::read_super_element(format, o.k_file, o.m_file, o.nodes_file, o.nlist_file);
  for (const std::string& w : se.warnings) log_line("warning: " + w);
  const fem::ModelOptions options = model_options(o, se);
  const fem::StructuralModel model = fem::assemble(se, options);
  const fem::Modes modes = fem::modes(model);

  const Eigen::VectorXd hz = lti::logspace(std::log10(o.fmin), std::log10(o.fmax), o.points);
  std::vector<Eigen::MatrixXcd> H;
  if (model.F.cols() > 0 && model.T.rows() > 0) {
    if (!o.json) log_line(fmt::format("frequency response at {} points on {} DOF", o.points, model.size()));
    H = fem::frequency_response(model, 2 * std::numbers::pi * hz);
  }

  if (o.json) {
    nlohmann::json channels = nlohmann::json::array();
    nlohmann::json h = nlohmann::json::array();
    for (Index out = 0; out < model.T.rows(); ++out) {
      for (Index in = 0; in < model.F.cols(); ++in) {
        channels.push_back({{"output", model.output_names[static_cast<std::size_t>(out)]},
                            {"input", model.input_names[static_cast<std::size_t>(in)]},
                            {"units", "m/N"}});
        Eigen::VectorXcd v(hz.size());
        for (Index k = 0; k < hz.size(); ++k) v(k) = H[static_cast<std::size_t>(k)](out, in);
        h.push_back(io::to_json(v));
      }
    }
    nlohmann::json nodes = nlohmann::json::array();
    for (long node : se.nodes()) {
      nlohmann::json n = {{"node", node}};
      const auto it = se.coordinates.find(node);
      if (it != se.coordinates.end()) n["position_m"] = {it->second.x(), it->second.y(), it->second.z()};
      nodes.push_back(n);
    }
    print_json({{"source", se.source},
                {"format", fem::to_string(format)},
                {"dofs", se.size()},
                {"modal_dofs", se.modal_dofs()},
                {"free_dofs", model.size()},
                {"nodes", nodes},
                {"fixed_nodes", options.fixed_nodes},
                {"damping", o.damping},
                {"modes_Hz", io::to_json(modes.frequencies_Hz)},
                {"freq_Hz", H.empty() ? nlohmann::json::array() : io::to_json(hz)},
                {"channels", channels},
                {"H", h},
                {"warnings", se.warnings}});
    return 0;
  }
  fmt::print("super element {} ({}): {} DOF ({} modal), {} nodes; {} free DOF\n", se.source, fem::to_string(format),
             se.size(), se.modal_dofs(), se.nodes().size(), model.size());
  const Index shown = std::min<Index>(modes.frequencies_Hz.size(), 20);
  fmt::print("first {} modes [Hz]:", shown);
  for (Index i = 0; i < shown; ++i) fmt::print(" {:.5g}", modes.frequencies_Hz(i));
  fmt::print("\n");
  for (Index out = 0; out < model.T.rows() && !H.empty(); ++out) {
    for (Index in = 0; in < model.F.cols(); ++in) {
      fmt::print("{} <- {}: |H| at {:.4g} Hz = {:.4g} m/N, at {:.4g} Hz = {:.4g} m/N\n",
                 model.output_names[static_cast<std::size_t>(out)], model.input_names[static_cast<std::size_t>(in)],
                 hz(0), std::abs(H.front()(out, in)), hz(hz.size() - 1), std::abs(H.back()(out, in)));
    }
  }
  for (const std::string& w : se.warnings) fmt::print("warning: {}\n", w);
  return 0;
}

}  // namespace

void add_superelement_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<SuperElementCli>();
  CLI::App* se = app.add_subcommand(
      "superelement", "Import a super element (Ansys CMS text, CalculiX .sti/.mas/.dof, Matrix Market) and compute its "
                      "modes and frequency response");
  se->add_option("K_FILE", o->k_file, "stiffness: Ansys K text, CalculiX .sti or Matrix Market")->required()->check(CLI::ExistingFile);
  se->add_option("M_FILE", o->m_file, "mass: Ansys M text, CalculiX .mas or Matrix Market")->required()->check(CLI::ExistingFile);
  se->add_option("NODES_FILE", o->nodes_file,
                 "DOF list: Ansys master-DOF listing, CalculiX .dof or a piezobench DOF list")
      ->required()
      ->check(CLI::ExistingFile);
  se->add_option("--nlist", o->nlist_file,
                 "node coordinates: Ansys node list (default: out_NLIST.txt beside NODES_FILE) or a CalculiX deck with *NODE")
      ->check(CLI::ExistingFile);
  se->add_option("--format", o->format, "auto, ansys, calculix or matrix-market")->capture_default_str();
  se->add_option("--fix", o->fix, "clamp every DOF of this node (repeatable)");
  se->add_option("--force", o->forces, "NODE_A:NODE_B:DIR: +1 N on B, -1 N on A along DIR (x|y|z|rx|ry|rz); repeatable");
  se->add_option("--output", o->outputs, "NODE:DIR displacement, or NODE_A:NODE_B:DIR relative (B - A); repeatable");
  se->add_option("--mass", o->masses, "NODE:KG point mass on the node's translations (repeatable)");
  se->add_option("--damping", o->damping, "none, modal:ZETA or rayleigh:ALPHA:BETA")->capture_default_str();
  se->add_option("--fmin", o->fmin, "lowest frequency, Hz")->capture_default_str();
  se->add_option("--fmax", o->fmax, "highest frequency, Hz")->capture_default_str();
  se->add_option("--points", o->points, "number of log-spaced frequencies")->check(CLI::Range(1, 100000))->capture_default_str();
  se->add_flag("--json", o->json, "print one JSON document on stdout");
  se->callback([o, &action] { action = [o] { return run_superelement(*o); }; });
}

}  // namespace piezobench::app
