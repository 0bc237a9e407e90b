#include "superelement_plant.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <limits>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::bench::detail {
namespace {

using io::NumberBounds;

// fix = NODE or [NODE, ...]: at least one.
std::vector<long> read_fix_nodes(const io::TomlReader& keys) {
  const toml::node* n = keys.get("fix");
  if (n == nullptr) keys.fail("fix", "a node number or an array of node numbers", "nothing (the key is required)");
  constexpr std::int64_t lo = std::numeric_limits<long>::min(), hi = std::numeric_limits<long>::max();
  if (n->is_integer()) return {static_cast<long>(*keys.integer("fix", lo, hi))};
  if (!n->is_array()) keys.fail("fix", "a node number or an array of node numbers", io::describe_toml(*n));
  std::vector<long> out;
  // The optional is kept by name: a range-for over `*keys.integers(...)` would read a destroyed temporary.
  const std::vector<std::int64_t> nodes = keys.integers("fix", lo, hi).value_or(std::vector<std::int64_t>{});
  for (const std::int64_t node : nodes) out.push_back(static_cast<long>(node));
  if (out.empty()) keys.fail("fix", "at least one node", "an empty array");
  return out;
}

// The element's files, resolved against the folder of the description, each checked to exist.
void read_files(const io::TomlReader& keys, const std::filesystem::path& dir, fem::SuperElementSetup& setup) {
  const auto resolve = [&](const std::string& p) -> std::filesystem::path {
    if (p.empty()) return {};
    const std::filesystem::path path(p);
    return path.is_absolute() ? path : dir / path;
  };
  setup.k_file = resolve(keys.required_string("k_file"));
  setup.m_file = resolve(keys.required_string("m_file"));
  setup.nodes_file = resolve(keys.required_string("nodes_file"));
  setup.coordinates_file = resolve(keys.string("coordinates_file").value_or(""));
  setup.format = keys.string("format").value_or("auto");
  for (const auto& [key, path] : {std::pair{"k_file", setup.k_file}, {"m_file", setup.m_file}, {"nodes_file", setup.nodes_file}}) {
    if (!std::filesystem::is_regular_file(path)) keys.fail(key, "an existing file", "'" + path.string() + "'");
  }
  (void)setup.resolved_format();  // an unknown format name is refused here, naming the key
  if (!setup.coordinates_file.empty() && !std::filesystem::is_regular_file(setup.coordinates_file)) {
    keys.fail("coordinates_file", "an existing file", "'" + setup.coordinates_file.string() + "'");
  }
}

// actuator, sensor and output in fem's syntax, checked to be a pair, a pair and one translation.
void read_ports(const io::TomlReader& keys, fem::SuperElementSetup& setup) {
  const auto sourced = [&](const char* key, auto parse) {
    try {
      return parse(keys.required_string(key), key);
    } catch (const InputError& e) {
      throw e.with_source(keys.where(keys.get(key)));
    }
  };
  const fem::ForcePair act = sourced("actuator", [](const std::string& t, const char* k) { return fem::ForcePair::parse(t, k); });
  if (act.node_a < 0) keys.fail("actuator", "a force pair A:B:DIR", "a single node");
  const auto output = [](const std::string& t, const char* k) { return fem::DisplacementOutput::parse(t, k); };
  const fem::DisplacementOutput sen = sourced("sensor", output);
  if (sen.node_a < 0) keys.fail("sensor", "a node pair A:B:DIR", "a single node");
  const fem::DisplacementOutput out = sourced("output", output);
  if (out.node_a >= 0) keys.fail("output", "one node NODE:DIR (the moving interface)", "a node pair");
  if (fem::is_rotation(out.direction)) keys.fail("output", "a translation (x, y or z)", "a rotation");
  setup.model.forces = {act};
  setup.model.outputs = {out, sen};
  setup.force_fields = {"actuator"};
  setup.output_fields = {"output", "sensor"};
}

}  // namespace

SuperElementBench read_superelement_spec(const std::filesystem::path& file) {
  const std::string source = file.string();
  const toml::table table = io::read_toml_file(file);
  const io::TomlReader keys(table, source);
  keys.only({"k_file", "m_file", "nodes_file", "coordinates_file", "format", "fix", "actuator", "sensor", "output", "ga", "gs",
             "modal_damping", "max_mode_Hz", "guided", "stack_modulus_Pa"});
  SuperElementBench s;
  s.file = file;
  fem::SuperElementSetup& setup = s.setup;
  setup.source = source;
  read_files(keys, file.parent_path(), setup);
  setup.model.fixed_nodes = read_fix_nodes(keys);
  read_ports(keys, setup);
  s.ga = keys.number("ga").value_or(s.ga);
  s.gs = keys.number("gs").value_or(s.gs);
  if (s.ga == 0.0) keys.fail("ga", "a nonzero actuator sensitivity (N/V)", "0");
  if (s.gs == 0.0) keys.fail("gs", "a nonzero sensor sensitivity (V/m)", "0");
  s.modal_damping = keys.number("modal_damping", NumberBounds::open(0.0, 1.0)).value_or(s.modal_damping);
  s.max_mode_Hz = keys.number("max_mode_Hz", NumberBounds::positive()).value_or(s.max_mode_Hz);
  s.guided = keys.boolean("guided").value_or(s.guided);
  // The stacks' effective modulus the element was built with: information for the campaign's eq. 4.1
  // (campaign_file.hpp's stack_modulus_Pa), ga and gs above already include it.
  (void)keys.number("stack_modulus_Pa", NumberBounds::open(0.0, 1e13));
  for (long n : setup.model.fixed_nodes) {
    if (n == setup.model.outputs[0].node_b) keys.fail("fix", "nodes other than the output node", std::to_string(n));
  }
  return s;
}

SuperElementMechanics load_superelement(const std::filesystem::path& file) {
  SuperElementMechanics m;
  m.spec = read_superelement_spec(file);
  m.se = m.spec.setup.load();
  return m;
}

fem::StructuralModel bench_structure(const SuperElementMechanics& mech, double moving_mass) {
  const SuperElementBench& s = mech.spec;
  const fem::DisplacementOutput& out = s.output();
  fem::ModelOptions o = s.setup.model;  // inputs [actuator], outputs [d_e, sensor]
  o.masses.push_back({out.node_b, moving_mass, 0.0});
  o.forces.push_back({-1, out.node_b, out.direction});
  if (s.guided) o.guided.push_back({out.node_b, out.direction});  // the air bearing
  return fem::assemble(mech.se, o);
}

ContinuousPlant superelement_plant(const SuperElementMechanics& mech, double moving_mass, double ga_factor,
                                   const Electrics& e, SuperElementPlantInfo* info) {
  const SuperElementBench& s = mech.spec;
  const std::string source = s.file.string();
  const fem::StructuralModel model = bench_structure(mech, moving_mass);
  const fem::Modes modes = fem::modes(model);
  const fem::Index f = model.size();
  if (!(modes.frequencies_Hz(0) > 0.0)) {
    throw InputError(source, "fix", "a structure held by its fixed nodes (every mode above 0 Hz)",
                     "a mode at " + format_number(modes.frequencies_Hz(0), 4) + " Hz");
  }
  fem::Index nk = 0;
  while (nk < f && modes.frequencies_Hz(nk) <= s.max_mode_Hz) ++nk;
  if (nk == 0) {
    throw InputError(source, "max_mode_Hz", "at least the first mode (" + format_number(modes.frequencies_Hz(0)) + " Hz)",
                     format_number(s.max_mode_Hz) + " Hz");
  }
  const Eigen::MatrixXd phi = modes.shapes.leftCols(nk);
  const Eigen::VectorXd w = kTwoPi * modes.frequencies_Hz.head(nk);
  // Static correction: what the truncated modes add at DC, T (K^-1 - Phi W^-2 Phi^T) F.
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(model.K);
  if (ldlt.info() != Eigen::Success) {
    throw NumericalError("super-element bench (static solve)", "the constrained stiffness matrix could not be factored", false);
  }
  const Eigen::MatrixXd static_full = model.T * ldlt.solve(model.F);
  const Eigen::MatrixXd pf = phi.transpose() * model.F;                     // nk x 2
  const Eigen::MatrixXd tp = model.T * phi;                                  // 2 x nk
  const Eigen::MatrixXd residual = static_full - tp * w.cwiseInverse().cwiseAbs2().asDiagonal() * pf;  // 2 x 2

  const double ga = s.ga * ga_factor;
  const double gs = s.gs;
  const double wa = e.amplifier_bandwidth;
  const double wc = 1.0 / (e.hpf_resistance * e.capacitance_sensor);
  const double kappa = -e.ground_resistance * e.capacitance_actuator;
  const fem::Index n = 3 + 2 * nk;
  const fem::Index iz = n - 2;  // high-pass state
  const fem::Index iy = n - 1;  // anti-aliasing state: Vs as the ADC reads it
  ContinuousPlant c;
  c.A = lti::Matrix::Zero(n, n);
  c.B = lti::Matrix::Zero(n, kInputs);
  c.C = lti::Matrix::Zero(kOutputs, n);
  c.D = lti::Matrix::Zero(kOutputs, kInputs);
  c.A(0, 0) = -wa;
  c.B(0, kInVa) = wa;
  const double r_da = residual(0, 0), r_dm = residual(0, 1), r_sa = residual(1, 0), r_sm = residual(1, 1);
  for (fem::Index i = 0; i < nk; ++i) {
    const fem::Index q = 1 + i, v = 1 + nk + i;
    c.A(q, v) = 1.0;
    c.A(v, q) = -w(i) * w(i);
    c.A(v, v) = -2.0 * s.modal_damping * w(i);
    c.A(v, 0) = pf(i, 0) * ga;
    c.B(v, kInForce) = pf(i, 0);
    c.B(v, kInMass) = pf(i, 1);
    c.A(iz, q) = wc * gs * tp(1, i);
    c.C(kOutDe, q) = tp(0, i);
  }
  // High-pass: z' = wc (gs e_s - z); at the ADC: Vs_raw = gs e_s - z + kappa wa (va - Va), through the
  // anti-aliasing low-pass y' = w_aa (Vs_raw - y), Vs = y.
  c.A(iz, 0) = wc * gs * r_sa * ga;
  c.A(iz, iz) = -wc;
  c.B(iz, kInForce) = wc * gs * r_sa;
  c.B(iz, kInMass) = wc * gs * r_sm;
  const double waa = e.adc_bandwidth;
  for (fem::Index i = 0; i < nk; ++i) c.A(iy, 1 + i) = waa * gs * tp(1, i);
  c.A(iy, 0) = waa * (gs * r_sa * ga - kappa * wa);
  c.A(iy, iz) = -waa;
  c.A(iy, iy) = -waa;
  c.B(iy, kInVa) = waa * kappa * wa;
  c.B(iy, kInForce) = waa * gs * r_sa;
  c.B(iy, kInMass) = waa * gs * r_sm;
  c.C(kOutVa, 0) = 1.0;
  c.C(kOutDe, 0) = r_da * ga;
  c.D(kOutDe, kInForce) = r_da;
  c.D(kOutDe, kInMass) = r_dm;
  c.C(kOutVs, iy) = 1.0;
  if (info != nullptr) {
    info->kept_modes = static_cast<int>(nk);
    info->total_modes = static_cast<int>(f);
    info->first_mode_Hz = modes.frequencies_Hz(0);
    info->last_kept_mode_Hz = modes.frequencies_Hz(nk - 1);
  }
  return c;
}

}  // namespace piezobench::bench::detail
