// `piezobench superelement`: imports a super element (Ansys CMS text, CalculiX MATRIXSTORAGE dumps
// or Matrix Market), applies boundary conditions, point masses, stack force pairs and outputs, and
// returns the modes and the frequency response (report section 4).
// `piezobench superelement from-step`: makes one from a STEP file with gmsh, ccx and the
// Craig-Bampton reduction (issue 8; fem/from_step.hpp, docs/from-step.md).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/fem/from_step.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/fem/superelement_setup.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/core/units.hpp"

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

// The command line as a super-element set-up; messages name the options.
fem::SuperElementSetup setup_of(const SuperElementCli& o) {
  fem::SuperElementSetup s;
  if (o.format != "auto" && !fem::super_element_format_from_string(o.format)) {
    throw UsageError("--format", "auto, ansys, calculix or matrix-market", "'" + o.format + "'");
  }
  s.format = o.format;
  s.k_file = o.k_file;
  s.m_file = o.m_file;
  s.nodes_file = o.nodes_file;
  s.coordinates_file = o.nlist_file;
  s.fix_field = "--fix";
  s.model.fixed_nodes = o.fix;
  for (const std::string& text : o.forces) {
    s.model.forces.push_back(fem::ForcePair::parse(text, "--force"));
    s.force_fields.push_back("--force " + text);
  }
  for (const std::string& text : o.outputs) {
    s.model.outputs.push_back(fem::DisplacementOutput::parse(text, "--output"));
    s.output_fields.push_back("--output " + text);
  }
  for (const std::string& text : o.masses) {
    s.model.masses.push_back(fem::PointMass::parse(text, "--mass"));
    s.mass_fields.push_back("--mass " + text);
  }
  s.model.damping = fem::Damping::parse(o.damping, "--damping");
  return s;
}

int run_superelement(const SuperElementCli& o) {
  if (!(std::isfinite(o.fmin) && o.fmin > 0.0)) throw UsageError("--fmin", "a frequency > 0 Hz", fmt::format("{}", o.fmin));
  if (!(std::isfinite(o.fmax) && o.fmax > o.fmin)) {
    throw UsageError("--fmax", fmt::format("a frequency > --fmin ({} Hz)", o.fmin), fmt::format("{}", o.fmax));
  }
  const fem::SuperElementSetup setup = setup_of(o);
  const fem::SuperElementFormat format = setup.resolved_format();
  if (!o.json) log_line("reading the super element (" + fem::to_string(format) + ")");
  const fem::SuperElement se = setup.load();
  for (const std::string& w : se.warnings) log_line("warning: " + w);
  const fem::ModelOptions& options = setup.model;
  const fem::StructuralModel model = fem::assemble(se, options);
  if (!o.json) log_line(fmt::format("modes of the constrained model ({} DOF)", model.size()));
  const fem::Modes modes = fem::modes(model);

  const Eigen::VectorXd hz = lti::logspace(std::log10(o.fmin), std::log10(o.fmax), o.points);
  lti::FrequencyResponse H;
  if (model.F.cols() > 0 && model.T.rows() > 0) {
    if (!o.json) log_line(fmt::format("frequency response at {} points on {} DOF", o.points, model.size()));
    H = fem::frequency_response(model, modes, kTwoPi * hz);  // modal superposition
  }

  if (o.json) {
    nlohmann::json channels = nlohmann::json::array();
    nlohmann::json h = nlohmann::json::array();
    for (Index out = 0; out < model.T.rows(); ++out) {
      for (Index in = 0; in < model.F.cols(); ++in) {
        channels.push_back({{"output", model.output_names[static_cast<std::size_t>(out)]},
                            {"input", model.input_names[static_cast<std::size_t>(in)]},
                            {"units", "m/N"}});
        h.push_back(io::to_json(H.channel(out, in)));
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
                {"freq_Hz", H.H.empty() ? nlohmann::json::array() : io::to_json(hz)},
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
  for (Index out = 0; out < model.T.rows() && !H.H.empty(); ++out) {
    for (Index in = 0; in < model.F.cols(); ++in) {
      fmt::print("{} <- {}: |H| at {:.4g} Hz = {:.4g} m/N, at {:.4g} Hz = {:.4g} m/N\n",
                 model.output_names[static_cast<std::size_t>(out)], model.input_names[static_cast<std::size_t>(in)],
                 hz(0), std::abs(H.H.front()(out, in)), hz(hz.size() - 1), std::abs(H.H.back()(out, in)));
    }
  }
  for (const std::string& w : se.warnings) fmt::print("warning: {}\n", w);
  return 0;
}

// ---- superelement from-step ------------------------------------------------------------------

struct FromStepCli {
  std::string step_file;
  std::string preset = "auto";
  double mesh_size = 4.0;
  int order = 2;
  int modes = 30;
  int clamped_modes = 10;
  std::vector<std::string> regions, materials, remote_points, joints, stacks, geo_parameters;
  double max_memory = 0.0, tool_timeout = 3600.0;
  std::string axial;
  std::string clamp;
  bool verify = false, keep_temp = false, json = false;
  std::string out = "superelement-from-step";
  std::string stem;
  std::string gmsh = "gmsh", ccx = "ccx";
  double tolerance = 1e-3;
};

fem::FromStepOptions from_step_options(const FromStepCli& c) {
  fem::FromStepOptions o;
  std::string preset = c.preset;
  if (preset == "auto") {
    const std::string ext = std::filesystem::path(c.step_file).extension().string();
    preset = ext == ".geo" || ext == ".GEO" ? "apa300ml" : "apa95ml";
  }
  if (preset == "apa95ml") {
    o = fem::FromStepOptions::apa95ml();
  } else if (preset == "apa95ml-beam") {
    o = fem::FromStepOptions::apa95ml_beam();
  } else if (preset == "apa300ml") {
    o = fem::FromStepOptions::apa300ml();
  } else if (preset == "none") {
    o.materials["body"] = fem::FromStepOptions::apa95ml().materials.at("body");
  } else {
    throw UsageError("--preset", "auto, apa95ml, apa95ml-beam, apa300ml or none", "'" + c.preset + "'");
  }
  if (!c.regions.empty()) {
    o.regions.clear();
    for (const std::string& t : c.regions) o.regions.push_back(fem::RegionSpec::parse(t, "--region"));
    // Materials of preset regions that are gone.
    for (auto it = o.materials.begin(); it != o.materials.end();) {
      const bool kept = it->first == "body" || std::any_of(o.regions.begin(), o.regions.end(),
                                                           [&](const fem::RegionSpec& r) { return r.name == it->first; });
      it = kept ? std::next(it) : o.materials.erase(it);
    }
  }
  for (const std::string& t : c.materials) {
    const auto colon = t.find(':');
    if (colon == std::string::npos || colon == 0) {
      throw UsageError("--material", "REGION:E,nu,rho (REGION: body or a --region name; SI units)", "'" + t + "'");
    }
    o.materials[t.substr(0, colon)] = fem::Material::parse(t.substr(colon + 1), "--material " + t.substr(0, colon));
  }
  if (!c.remote_points.empty()) {
    o.remote_points.clear();
    for (const std::string& t : c.remote_points) o.remote_points.push_back(fem::RemotePointSpec::parse(t, "--remote-point"));
  }
  if (!c.remote_points.empty() || !c.joints.empty()) o.joints.clear();
  for (const std::string& t : c.joints) o.joints.push_back(fem::JointSpec::parse(t, "--joint"));
  if (!c.remote_points.empty() || !c.joints.empty() || !c.stacks.empty()) o.stacks.clear();
  for (const std::string& t : c.stacks) o.stacks.push_back(fem::StackSpec::parse(t, "--stack"));
  for (const std::string& t : c.geo_parameters) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--geo-parameter", "NAME=VALUE (a DefineConstant of the .geo)", "'" + t + "'");
    const std::vector<double> v = parse_number_list(t.substr(eq + 1), "--geo-parameter " + t.substr(0, eq));
    if (v.size() != 1) throw UsageError("--geo-parameter", "NAME=VALUE (one number)", "'" + t + "'");
    o.geo_parameters[t.substr(0, eq)] = v.front();
  }
  if (!c.axial.empty()) {
    o.axial = c.axial == "none" ? "" : c.axial;
  } else if (std::none_of(o.remote_points.begin(), o.remote_points.end(),
                          [&](const fem::RemotePointSpec& p) { return o.axial.rfind(p.name + ":", 0) == 0; })) {
    o.axial.clear();  // the preset's remote point is gone
  }
  o.max_memory_GB = c.max_memory;
  o.tool_timeout_s = c.tool_timeout;
  if (!c.clamp.empty()) {
    o.clamp = c.clamp;
  } else if (std::none_of(o.remote_points.begin(), o.remote_points.end(),
                          [&](const fem::RemotePointSpec& p) { return p.name == o.clamp; }) &&
             !o.remote_points.empty()) {
    o.clamp = o.remote_points.front().name;
  }
  o.mesh_size_mm = c.mesh_size;
  o.element_order = c.order;
  o.modes = c.modes;
  o.clamped_modes = c.clamped_modes;
  o.verify = c.verify;
  o.keep_temp = c.keep_temp;
  o.out = c.out;
  o.stem = c.stem;
  o.gmsh = c.gmsh;
  o.ccx = c.ccx;
  o.geometry_tolerance_mm = c.tolerance;
  o.log = [](const std::string& line) { log_line("from-step: " + line); };
  return o;
}

// The super element's files among the outputs and the command that uses them.
struct SuperElementFiles {
  std::string k_file, m_file, dof_file;
  long clamp_node = -1;

  explicit SuperElementFiles(const fem::FromStepResult& r) {
    for (const auto& f : r.files) {
      const std::string name = f.filename().string();
      if (name.size() > 6 && name.compare(name.size() - 6, 6, "_K.mtx") == 0) k_file = f.string();
      if (name.size() > 6 && name.compare(name.size() - 6, 6, "_M.mtx") == 0) m_file = f.string();
      if (name.size() > 9 && name.compare(name.size() - 9, 9, "_dofs.txt") == 0) dof_file = f.string();
    }
    for (const fem::RemotePointResult& p : r.remote_points) {
      if (p.name == r.clamp) clamp_node = p.node;
    }
  }
  [[nodiscard]] std::string usage() const {
    return "piezobench superelement " + k_file + " " + m_file + " " + dof_file + " --fix " + std::to_string(clamp_node);
  }
};

nlohmann::json from_step_json(const FromStepCli& c, const fem::FromStepOptions& o, const fem::FromStepResult& r) {
  nlohmann::json points = nlohmann::json::array();
  for (const fem::RemotePointResult& p : r.remote_points) {
    points.push_back({{"name", p.name},
                      {"selector", p.selector.to_string()},
                      {"surfaces", p.surfaces},
                      {"node", p.node},
                      {"rot_node", p.rot_node},
                      {"position_m", {p.position_m.x(), p.position_m.y(), p.position_m.z()}},
                      {"area_m2", p.area_m2},
                      {"face_nodes", p.face_nodes}});
  }
  nlohmann::json materials = nlohmann::json::object();
  for (const auto& [name, m] : o.materials) {
    materials[name] = {{"E_Pa", m.youngs_modulus}, {"nu", m.poisson_ratio}, {"rho_kg_per_m3", m.density}};
  }
  nlohmann::json regions = nlohmann::json::object();
  for (const fem::RegionSpec& reg : o.regions) {
    regions[reg.name] = {{"box_mm", {reg.box.lo.x(), reg.box.lo.y(), reg.box.lo.z(), reg.box.hi.x(), reg.box.hi.y(), reg.box.hi.z()}}};
  }
  nlohmann::json joints = nlohmann::json::array();
  for (const fem::JointResult& j : r.joints) {
    joints.push_back({{"name", j.name}, {"node", j.node}, {"position_m", {j.position_m.x(), j.position_m.y(), j.position_m.z()}}});
  }
  nlohmann::json stacks = nlohmann::json::array();
  for (const fem::StackResult& st : r.stacks) {
    stacks.push_back({{"from", st.from}, {"to", st.to}, {"node_a", st.node_a}, {"node_b", st.node_b}, {"length_m", st.length_m},
                      {"axial_stiffness_N_per_m", st.axial_stiffness}, {"mass_kg", st.mass}});
  }
  const fem::MeshEstimate& e = r.estimate;
  const nlohmann::json estimate = {{"volume_mm3", e.volume_mm3}, {"area_mm2", e.area_mm2}, {"elements", e.elements},
                                   {"nodes", e.nodes}, {"dofs", e.dofs}, {"memory_GB", e.memory_GB}, {"seconds", e.seconds}};
  nlohmann::json seconds = nlohmann::json::object();
  for (const auto& [step, s] : r.seconds) seconds[step] = s;
  nlohmann::json files = nlohmann::json::array();
  for (const auto& f : r.files) files.push_back(f.string());
  const SuperElementFiles se_files(r);
  nlohmann::json doc = {
      {"step", c.step_file},
      {"out", o.out.string()},
      {"gmsh", {{"path", r.gmsh.path}, {"version", r.gmsh.version}}},
      {"ccx", {{"path", r.ccx.path}, {"version", r.ccx.version}}},
      {"mesh",
       {{"size_mm", o.mesh_size_mm},
        {"element", r.element_type},
        {"nodes", r.mesh_nodes},
        {"elements", r.mesh_elements},
        {"elements_per_region", r.region_elements},
        {"model_dofs", r.model_dofs},
        {"estimate", estimate}}},
      {"regions", regions},
      {"materials", materials},
      {"remote_points", points},
      {"joints", joints},
      {"stacks", stacks},
      {"geo_parameters", o.geo_parameters},
      {"reduction",
       {{"interface_dofs", r.reduction.interface_dofs},
        {"interior_dofs", r.reduction.interior_dofs},
        {"modes", o.modes},
        {"fixed_interface_Hz", io::to_json(r.reduction.fixed_interface_Hz)},
        {"factor_nonzeros", r.reduction.factor_nonzeros},
        {"eigensolver_restarts", r.reduction.eigensolver_iterations},
        {"solves", r.reduction.eigensolver_operations}}},
      {"super_element", {{"dofs", r.reduced.size()}, {"modal_dofs", r.reduced.modal_dofs()}, {"K", se_files.k_file}, {"M", se_files.m_file}, {"dof_list", se_files.dof_file}}},
      {"usage", se_files.usage()},
      {"clamp", r.clamp},
      {"modes_clamped_Hz", io::to_json(r.modes_clamped_Hz)},
      {"shell_modes_clamped_Hz", io::to_json(r.shell_modes_clamped_Hz)},
      {"axial", o.axial},
      {"axial_stiffness_N_per_m", r.axial_stiffness},
      {"shell_axial_stiffness_N_per_m", r.shell_axial_stiffness},
      {"free_modes_Hz", io::to_json(r.free_modes_Hz)},
      {"seconds", seconds},
      {"files", files},
      {"work_dir", r.work_dir.string()},
      {"warnings", r.reduced.warnings}};
  if (r.reference_modes_Hz) {
    doc["reference_modes_Hz"] = io::to_json(*r.reference_modes_Hz);
    // ccx's model has no stacks: compare with the reduced model before they are added.
    const Index n = std::min(r.reference_modes_Hz->size(), r.shell_modes_clamped_Hz.size());
    Eigen::VectorXd rel(n);
    for (Index i = 0; i < n; ++i) rel(i) = r.shell_modes_clamped_Hz(i) / (*r.reference_modes_Hz)(i) - 1.0;
    doc["relative_difference"] = io::to_json(rel);
  }
  return doc;
}

int run_from_step(const FromStepCli& c) {
  const fem::FromStepOptions o = from_step_options(c);
  const fem::FromStepResult r = fem::superelement_from_step(c.step_file, o);
  nlohmann::json doc = from_step_json(c, o, r);
  const std::filesystem::path summary = std::filesystem::path(o.out) / "from_step.json";
  doc["files"].push_back(summary.string());
  io::write_text_atomically(summary, doc.dump(2) + "\n");
  log_line("from-step: done in " + fmt::format("{:.1f}", r.seconds.back().second) + " s; summary " + summary.string());
  if (c.json) {
    print_json(doc);
    return 0;
  }
  fmt::print("super element of {}: {} DOF ({} interface, {} modal) in {}\n", c.step_file, r.reduced.size(), r.reduction.interface_dofs,
             r.reduced.modal_dofs(), o.out.string());
  fmt::print("mesh: {} nodes, {} {} elements, {} DOF after the rigid bodies\n", r.mesh_nodes, r.mesh_elements, r.element_type,
             r.model_dofs);
  for (const fem::RemotePointResult& p : r.remote_points) {
    fmt::print("remote point {:<10} node {:>7} ({}) at ({:.6g}, {:.6g}, {:.6g}) m, {} face nodes\n", p.name, p.node,
               p.selector.to_string(), p.position_m.x(), p.position_m.y(), p.position_m.z(), p.face_nodes);
  }
  fmt::print("modes with {} clamped [Hz]:", r.clamp);
  for (Index i = 0; i < r.modes_clamped_Hz.size(); ++i) fmt::print(" {:.6g}", r.modes_clamped_Hz(i));
  fmt::print("\n");
  if (r.axial_stiffness > 0.0) {
    fmt::print("static stiffness at {} ({} clamped): {:.4g} N/um with the stacks, {:.4g} N/um without\n", o.axial, r.clamp,
               1e-6 * r.axial_stiffness, 1e-6 * r.shell_axial_stiffness);
  }
  for (const fem::StackResult& st : r.stacks) {
    fmt::print("stack {} -> {}: beam of {:.4g} mm between nodes {} and {}, E A / L = {:.4g} N/um\n", st.from, st.to, 1e3 * st.length_m,
               st.node_a, st.node_b, 1e-6 * st.axial_stiffness);
  }
  if (r.reference_modes_Hz) {
    if (!r.stacks.empty()) {
      fmt::print("without the stacks    [Hz]:");
      for (Index i = 0; i < r.shell_modes_clamped_Hz.size(); ++i) fmt::print(" {:.6g}", r.shell_modes_clamped_Hz(i));
      fmt::print("\n");
    }
    fmt::print("ccx on the full mesh  [Hz]:");
    for (Index i = 0; i < r.reference_modes_Hz->size(); ++i) fmt::print(" {:.6g}", (*r.reference_modes_Hz)(i));
    fmt::print("\n");
  }
  fmt::print("use it: {}\n", SuperElementFiles(r).usage());
  for (const std::string& w : r.reduced.warnings) fmt::print("warning: {}\n", w);
  return 0;
}

CLI::App* add_from_step_command(CLI::App& se, Action& action) {
  auto c = std::make_shared<FromStepCli>();
  CLI::App* fs = se.add_subcommand(
      "from-step",
      "Make a super element from a STEP file: gmsh meshes, ccx assembles (*FREQUENCY,SOLVER=MATRIXSTORAGE), piezobench "
      "reduces (Craig-Bampton) and writes it (Matrix Market + DOF list, Simscape script) into --out. Defaults: APA95ML.step "
      "(docs/from-step.md)");
  fs->add_option("STEP_FILE", c->step_file, "the CAD geometry (STEP, mm), or a gmsh .geo script (OpenCASCADE, mm)")->required();
  fs->add_option("--mesh-size", c->mesh_size, "largest element size, mm")->capture_default_str();
  fs->add_option("--order", c->order, "element order: 2 (C3D10) or 1 (C3D4)")->capture_default_str();
  fs->add_option("--modes", c->modes, "fixed-interface modes kept")->capture_default_str();
  fs->add_option("--preset", c->preset,
                 "auto (apa300ml for a .geo input, else apa95ml); apa95ml: region stack (PZT) in a steel body, remote points "
                 "top, bottom, stack_a, stack_b; apa95ml-beam: the block removed and the stack a beam as in the Ansys model; apa300ml: data/geometry/apa300ml.geo, remote points top, bottom, stack_a, "
                 "stack_b, joint stack_mid and the three stacks as beams; none: one steel body, remote points from --remote-point")
      ->capture_default_str();
  fs->add_option("--joint", c->joints,
                 "NAME:FROM:TO:FRACTION: a 6-DOF node on the line FROM -> TO (remote points or joints), e.g. the junction "
                 "between stacks (repeatable; replaces the preset's)");
  fs->add_option("--stack", c->stacks,
                 "FROM:TO[:E,nu,rho,AREA]: a stack as a beam between two remote points or joints, added to the reduced model "
                 "(default section: Table 4.1, 48e9,0.31,7800,1e-4; repeatable; replaces the preset's)");
  fs->add_option("--geo-parameter", c->geo_parameters, "NAME=VALUE: a DefineConstant of a .geo input (mm), repeatable");
  fs->add_option("--max-memory", c->max_memory,
                 "refuse meshes whose estimated peak memory exceeds this, GB (0: half the memory, at most 8 GB)")
      ->capture_default_str();
  fs->add_option("--axial", c->axial,
                 "REMOTE_POINT:DIR whose static stiffness (--clamp fixed) is reported, with and without the stacks (presets: "
                 "top:y; none: no stiffness)");
  fs->add_option("--tool-timeout", c->tool_timeout, "stop gmsh or ccx after this many seconds (each run)")->capture_default_str();
  fs->add_option("--region", c->regions,
                 "NAME:box:x0,y0,z0,x1,y1,z1 (mm): cut this box out of the bodies as its own material region (repeatable; "
                 "replaces the preset's regions)");
  fs->add_option("--material", c->materials,
                 "REGION:E,nu,rho (Pa, -, kg/m^3) for body (the rest) or a region, or REGION:none to remove the region "
                 "(repeatable). Preset apa95ml: body 190e9,0.3,7800 (steel), stack 48e9,0.31,7800 (PZT)");
  fs->add_option("--remote-point", c->remote_points,
                 "NAME:SELECTOR with SELECTOR x|y|z=min|max|MM (planar faces in that plane), box:x0,y0,z0,x1,y1,z1 (faces "
                 "inside, mm) or surface:TAG[,TAG] (gmsh tags, see geometry.txt); repeatable, replaces the preset's");
  fs->add_option("--clamp", c->clamp, "remote point clamped for modes_clamped_Hz and --verify (default: bottom, else the first)");
  fs->add_option("--clamped-modes", c->clamped_modes, "number of clamped modes reported (and computed by ccx with --verify)")
      ->capture_default_str();
  fs->add_flag("--verify", c->verify, "also run ccx *FREQUENCY on the full mesh with --clamp fixed (reference_modes_Hz)");
  fs->add_flag("--keep-temp", c->keep_temp, "keep the work folder (gmsh mesh, matrix dumps, ccx results) in --out");
  fs->add_option("--out", c->out, "output folder")->capture_default_str();
  fs->add_option("--stem", c->stem, "file name stem of the super element (default: the STEP file's)");
  fs->add_option("--gmsh", c->gmsh, "gmsh executable (name in PATH or path)")->capture_default_str();
  fs->add_option("--ccx", c->ccx, "CalculiX ccx executable (name in PATH or path)")->capture_default_str();
  fs->add_option("--geometry-tolerance", c->tolerance, "gmsh boolean tolerance and flatness of planar faces, mm")->capture_default_str();
  fs->add_flag("--json", c->json, "print one JSON document on stdout (progress stays on stderr)");
  fs->callback([c, &action] { action = [c] { return run_from_step(*c); }; });
  return fs;
}

}  // namespace

void add_superelement_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<SuperElementCli>();
  CLI::App* se = app.add_subcommand(
      "superelement", "Import a super element (Ansys CMS text, CalculiX .sti/.mas/.dof, Matrix Market) and compute its "
                      "modes and frequency response; `superelement from-step` makes one from a STEP file");
  // The three files are required unless the from-step subcommand is used (checked in the callback).
  se->add_option("K_FILE", o->k_file, "stiffness: Ansys K text, CalculiX .sti or Matrix Market (required)")->check(input_file());
  se->add_option("M_FILE", o->m_file, "mass: Ansys M text, CalculiX .mas or Matrix Market (required)")->check(input_file());
  se->add_option("NODES_FILE", o->nodes_file,
                 "DOF list: Ansys master-DOF listing, CalculiX .dof or a piezobench DOF list (required)")
      ->check(input_file());
  se->add_option("--nlist", o->nlist_file,
                 "node coordinates: Ansys node list (default: out_NLIST.txt beside NODES_FILE) or a CalculiX deck with *NODE")
      ->check(input_file());
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
  CLI::App* from_step = add_from_step_command(*se, action);
  CLI::App* update = add_superelement_update_command(*se, action);
  se->callback([o, from_step, update, &action] {
    if (from_step->parsed() || update->parsed()) return;  // their own callbacks have set the action
    if (o->k_file.empty()) throw CLI::RequiredError("K_FILE");
    if (o->m_file.empty()) throw CLI::RequiredError("M_FILE");
    if (o->nodes_file.empty()) throw CLI::RequiredError("NODES_FILE");
    action = [o] { return run_superelement(*o); };
  });
}

}  // namespace piezobench::app
