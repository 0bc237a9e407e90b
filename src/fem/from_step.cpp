#include "piezobench/fem/from_step.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <system_error>
#include <unistd.h>

#include "from_step_files.hpp"
#include "from_step_process.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/fem/matrix_io.hpp"
#include "piezobench/fem/structural_model.hpp"

namespace piezobench::fem {
namespace {

namespace fs = std::filesystem;

const char* const kMinGmsh = "4.0";
const char* const kMinCcx = "2.15";
const char* const kWorkDir = "from_step_work";

std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t at = text.find(sep, start);
    out.push_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) return out;
    start = at + 1;
  }
}

std::vector<double> parse_numbers(std::string_view text, std::size_t count, const std::string& field, const std::string& form,
                                  const std::string& whole) {
  const auto parts = split(text, ',');
  std::vector<double> out;
  for (const std::string_view p : parts) {
    const auto v = text::parse_double(p);
    if (!v || !std::isfinite(*v)) throw InputError("", field, form, "'" + whole + "'");
    out.push_back(*v);
  }
  if (out.size() != count) throw InputError("", field, form, "'" + whole + "'");
  return out;
}

std::string elapsed(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

// Removes the work folder when the run ends (also on errors) unless it is to be kept.
class WorkFolder {
 public:
  WorkFolder(fs::path path, bool keep) : path_(std::move(path)), keep_(keep) {
    std::error_code ec;
    fs::remove_all(path_, ec);
    fs::create_directories(path_, ec);
    if (ec) throw InputError(path_.string(), "folder", "a folder that can be created", ec.message());
  }
  ~WorkFolder() {
    if (keep_) return;
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  bool keep_;
};

class Runner {
 public:
  explicit Runner(const FromStepOptions& o) : o_(o) {
    const double gb = o.max_memory_GB > 0.0 ? o.max_memory_GB : default_max_memory_GB();
    limits_.seconds = o.tool_timeout_s;
    limits_.address_space_bytes = (2.0 * gb + 1.0) * 1e9;
  }

  void log(const std::string& line) const {
    if (o_.log) o_.log(line);
  }

  ToolInfo check_tool(const std::string& spec, const std::string& name, const std::string& flag, const std::string& min_version,
                      const std::string& package, const fs::path& work) const {
    const auto exe = detail::find_executable(spec);
    if (!exe) {
      const char* path = std::getenv("PATH");
      const std::string found = spec.find('/') != std::string::npos
                                    ? "'" + spec + "' is not an executable file"
                                    : "'" + spec + "' not found in PATH (" + std::string(path != nullptr ? path : "") + ")";
      throw InputError("--" + name, "executable",
                       "the " + name + " program (Debian package " + package + "; or --" + name + " /path/to/" + name + ")",
                       found);
    }
    const fs::path log = work / (name + "_version.log");
    detail::ProcessResult pr;
    try {
      pr = detail::run_process(*exe, {flag}, work, log);
    } catch (const std::system_error& e) {
      throw InputError("--" + name, "executable", "a program that can be started", exe->string() + ": " + e.what());
    }
    const std::string text = read_file(log);
    const auto version = detail::parse_version(text);
    if (!version || pr.signaled) {
      throw InputError("--" + name, "version",
                       name + " printing its version with '" + flag + "' (is " + exe->string() + " really " + name + "?)",
                       "'" + detail::last_lines(text, "", 2) + "'");
    }
    if (detail::compare_versions(*version, min_version) < 0) {
      throw InputError("--" + name, "version", name + " >= " + min_version, *version + " (" + exe->string() + ")");
    }
    return {exe->string(), *version};
  }

  // Runs a tool, forwarding the log lines that `keep` accepts to the progress log.
  detail::ProcessResult run(const ToolInfo& tool, const std::string& label, const std::vector<std::string>& args, const fs::path& cwd,
                            const fs::path& log, const std::function<bool(std::string_view)>& keep) const {
    const auto forward = [&](std::string_view line) {
      if (keep(line)) log_line_of(label, line);
    };
    detail::ProcessResult pr;
    try {
      pr = detail::run_process(tool.path, args, cwd, log, forward, limits_);
    } catch (const std::system_error& e) {
      throw InputError(tool.path, "executable", "a program that can be started", e.what());
    }
    if (pr.timed_out) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%g s", limits_.seconds);
      throw NumericalError(label, std::string("did not finish within ") + buf + " and was stopped (--tool-timeout; log: " + log.string() + ")",
                           true);
    }
    return pr;
  }

  void log_line_of(const std::string& label, std::string_view line) const {
    std::string_view t = text::trim(line);
    if (t.rfind("Info    : ", 0) == 0) t.remove_prefix(10);
    if (!t.empty()) log("  " + label + ": " + std::string(t));
  }

 private:
  const FromStepOptions& o_;
  detail::ProcessLimits limits_;
};

// gmsh's stages (not its per-curve and per-surface lines), errors and the final count.
bool keep_gmsh_line(std::string_view line) {
  if (line.find("Error") != std::string_view::npos) return true;
  if (line.find('%') != std::string_view::npos) return false;
  return line.find(": Meshing ") != std::string_view::npos || line.find(": Optimizing mesh") != std::string_view::npos ||
         line.find(": Done meshing") != std::string_view::npos || line.find(" nodes ") != std::string_view::npos;
}

bool keep_ccx_line(std::string_view line) {
  static const char* const keys[] = {"Determining", "Factoring", "Calculating the eigen", "Storing", "*ERROR", "Job finished"};
  return std::any_of(std::begin(keys), std::end(keys), [&](const char* k) { return line.find(k) != std::string_view::npos; });
}

void copy_into(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) throw InputError(to.string(), "file", "a writable output folder", ec.message());
}

void write_text(const fs::path& file, const std::string& text) {
  write_atomically(file, [&](std::ostream& out) { out << text; });
}

std::string sanitize_stem(const std::string& stem) {
  std::string s;
  for (const char c : stem) s += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-') ? c : '_';
  return s.empty() ? "superelement" : s;
}

}  // namespace

// ---- parsing --------------------------------------------------------------------------------

Box3 Box3::parse(const std::string& text, const std::string& field) {
  const auto v = parse_numbers(text, 6, field, "x0,y0,z0,x1,y1,z1 (mm)", text);
  Box3 b;
  b.lo = Eigen::Vector3d(std::min(v[0], v[3]), std::min(v[1], v[4]), std::min(v[2], v[5]));
  b.hi = Eigen::Vector3d(std::max(v[0], v[3]), std::max(v[1], v[4]), std::max(v[2], v[5]));
  if (((b.hi - b.lo).array() <= 0.0).any()) throw InputError("", field, "a box with a non-zero size along x, y and z", "'" + text + "'");
  return b;
}

bool Box3::contains(const Box3& other, double tolerance) const {
  return ((other.lo.array() >= lo.array() - tolerance) && (other.hi.array() <= hi.array() + tolerance)).all();
}

FaceSelector FaceSelector::parse(const std::string& text, const std::string& field) {
  const std::string form = "x|y|z=min|max|VALUE_MM, box:x0,y0,z0,x1,y1,z1 or surface:TAG[,TAG...]";
  FaceSelector s;
  const std::string t = text::to_lower(std::string(text::trim(text)));
  if (t.rfind("box:", 0) == 0) {
    s.kind = Kind::kBox;
    s.box = Box3::parse(t.substr(4), field);
    return s;
  }
  if (t.rfind("surface:", 0) == 0) {
    s.kind = Kind::kSurfaces;
    for (const std::string_view p : split(std::string_view(t).substr(8), ',')) {
      const auto tag = text::parse_int(p);
      if (!tag || *tag < 1) throw InputError("", field, form, "'" + text + "'");
      s.surfaces.push_back(static_cast<int>(*tag));
    }
    return s;
  }
  if (t.size() < 3 || t[1] != '=' || (t[0] != 'x' && t[0] != 'y' && t[0] != 'z')) throw InputError("", field, form, "'" + text + "'");
  s.kind = Kind::kPlane;
  s.axis = t[0] - 'x';
  const std::string at = t.substr(2);
  if (at == "max") {
    s.at = At::kMax;
  } else if (at == "min") {
    s.at = At::kMin;
  } else {
    const auto v = text::parse_double(at);
    if (!v || !std::isfinite(*v)) throw InputError("", field, form, "'" + text + "'");
    s.at = At::kValue;
    s.value = *v;
  }
  return s;
}

std::string FaceSelector::to_string() const {
  const auto g = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return std::string(buf);
  };
  switch (kind) {
    case Kind::kPlane:
      return std::string(1, static_cast<char>('x' + axis)) + "=" + (at == At::kMax ? "max" : at == At::kMin ? "min" : g(value));
    case Kind::kBox:
      return "box:" + g(box.lo.x()) + "," + g(box.lo.y()) + "," + g(box.lo.z()) + "," + g(box.hi.x()) + "," + g(box.hi.y()) + "," +
             g(box.hi.z());
    case Kind::kSurfaces: {
      std::string s = "surface:";
      for (std::size_t k = 0; k < surfaces.size(); ++k) {
        s += (k > 0 ? "," : "");
        s += std::to_string(surfaces[k]);
      }
      return s;
    }
  }
  return "";
}

RemotePointSpec RemotePointSpec::parse(const std::string& text, const std::string& field) {
  const auto colon = text.find(':');
  const std::string form = "NAME:SELECTOR, e.g. top:y=max (NAME: letters, digits, _)";
  if (colon == std::string::npos) throw InputError("", field, form, "'" + text + "'");
  RemotePointSpec r;
  r.name = std::string(text::trim(std::string_view(text).substr(0, colon)));
  if (!detail::is_valid_name(r.name)) throw InputError("", field, form, "'" + text + "'");
  r.selector = FaceSelector::parse(text.substr(colon + 1), field + " " + r.name);
  return r;
}

RegionSpec RegionSpec::parse(const std::string& text, const std::string& field) {
  const std::string form = "NAME:box:x0,y0,z0,x1,y1,z1 (mm; NAME: letters, digits, _)";
  const auto colon = text.find(':');
  if (colon == std::string::npos || text.compare(colon + 1, 4, "box:") != 0) throw InputError("", field, form, "'" + text + "'");
  RegionSpec r;
  r.name = std::string(text::trim(std::string_view(text).substr(0, colon)));
  if (!detail::is_valid_name(r.name) || text::to_lower(r.name) == "body") {
    throw InputError("", field, form + "; 'body' is the rest of the model", "'" + text + "'");
  }
  r.box = Box3::parse(text.substr(colon + 5), field + " " + r.name);
  return r;
}

Material Material::parse(const std::string& text, const std::string& field) {
  const std::string form = "E,nu,rho (Pa, -, kg/m^3), e.g. 190e9,0.3,7800, or none (the region is removed)";
  if (text::to_lower(std::string(text::trim(text))) == "none") {
    Material m;
    m.removed = true;
    return m;
  }
  const auto v = parse_numbers(text, 3, field, form, text);
  if (!(v[0] > 0.0) || !(v[1] > -1.0 && v[1] < 0.5) || !(v[2] > 0.0)) {
    throw InputError("", field, "E > 0, -1 < nu < 0.5, rho > 0", "'" + text + "'");
  }
  return {v[0], v[1], v[2]};
}

JointSpec JointSpec::parse(const std::string& text, const std::string& field) {
  const std::string form = "NAME:FROM:TO:FRACTION (FROM, TO: remote points or joints; 0 < FRACTION < 1)";
  const auto parts = split(text, ':');
  if (parts.size() != 4) throw InputError("", field, form, "'" + text + "'");
  JointSpec j;
  j.name = std::string(text::trim(parts[0]));
  j.from = std::string(text::trim(parts[1]));
  j.to = std::string(text::trim(parts[2]));
  const auto f = text::parse_double(text::trim(parts[3]));
  if (!detail::is_valid_name(j.name) || !detail::is_valid_name(j.from) || !detail::is_valid_name(j.to) || !f || !(*f > 0.0 && *f < 1.0)) {
    throw InputError("", field, form, "'" + text + "'");
  }
  j.fraction = *f;
  return j;
}

StackSpec StackSpec::parse(const std::string& text, const std::string& field) {
  const std::string form = "FROM:TO or FROM:TO:E,nu,rho,AREA (remote points or joints; SI units)";
  const auto parts = split(text, ':');
  if (parts.size() != 2 && parts.size() != 3) throw InputError("", field, form, "'" + text + "'");
  StackSpec st;
  st.from = std::string(text::trim(parts[0]));
  st.to = std::string(text::trim(parts[1]));
  if (!detail::is_valid_name(st.from) || !detail::is_valid_name(st.to)) throw InputError("", field, form, "'" + text + "'");
  if (parts.size() == 3) st.section = BeamSection::parse(std::string(parts[2]), field);
  return st;
}

std::string MeshEstimate::to_string() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "about %.2g elements, %.2g nodes, %.2g DOF, %.3g GB of memory and %.2g s (geometry: %.4g mm^3, %.4g mm^2)",
                elements, nodes, dofs, memory_GB, seconds, volume_mm3, area_mm2);
  return buf;
}

MeshEstimate estimate_mesh(double volume_mm3, double area_mm2, double mesh_size_mm, int element_order) {
  MeshEstimate e;
  e.volume_mm3 = volume_mm3;
  e.area_mm2 = area_mm2;
  const double h = mesh_size_mm;
  e.elements = 3.0 * volume_mm3 / (h * h * h) + 4.0 * area_mm2 / (h * h);
  e.nodes = (element_order == 2 ? 1.65 : 0.3) * e.elements;
  e.dofs = 3.0 * e.nodes;
  const double scale = e.dofs / 144000.0;  // the 2 mm APA95ML run (docs/performance.md)
  e.memory_GB = 0.2 + 1.3 * std::pow(scale, 1.2);
  e.seconds = 5.0 + 60.0 * std::pow(scale, 1.2);
  return e;
}

double default_max_memory_GB() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  const double total = pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) / 1e9 : 8.0;
  return std::min(8.0, 0.5 * total);
}

FromStepOptions FromStepOptions::apa300ml() {
  FromStepOptions o;
  o.materials["body"] = {200e9, 0.3, 7850.0};
  o.remote_points = {RemotePointSpec::parse("top:y=max", "default"), RemotePointSpec::parse("bottom:y=min", "default"),
                     RemotePointSpec::parse("stack_a:x=-30", "default"), RemotePointSpec::parse("stack_b:x=30", "default")};
  o.joints = {JointSpec::parse("stack_mid:stack_a:stack_b:0.6666666666666666", "default")};
  o.stacks = {StackSpec::parse("stack_a:stack_mid", "default"), StackSpec::parse("stack_mid:stack_b", "default")};
  o.clamp = "bottom";
  o.axial = "top:y";
  return o;
}

FromStepOptions FromStepOptions::apa95ml_beam() {
  FromStepOptions o = apa95ml();
  o.materials["stack"].removed = true;
  o.remote_points = {RemotePointSpec::parse("top:y=max", "default"), RemotePointSpec::parse("bottom:y=min", "default"),
                     RemotePointSpec::parse("stack_a:box:-34.8,-10.01,-11.26,-28.7,10.01,11.26", "default"),
                     RemotePointSpec::parse("stack_b:box:28.7,-10.01,-11.26,34.8,10.01,11.26", "default")};
  o.joints = {JointSpec::parse("j1:stack_a:stack_b:0.25", "default"), JointSpec::parse("j2:stack_a:stack_b:0.5", "default"),
              JointSpec::parse("j3:stack_a:stack_b:0.75", "default")};
  const BeamSection ansys{48e9, 0.31, 16840.0, 5.235e-5};
  for (const auto& [a, b] : {std::pair{"stack_a", "j1"}, {"j1", "j2"}, {"j2", "j3"}, {"j3", "stack_b"}}) o.stacks.push_back({a, b, ansys});
  return o;
}

FromStepOptions FromStepOptions::apa95ml() {
  FromStepOptions o;
  RegionSpec stack;
  stack.name = "stack";
  stack.box.lo = Eigen::Vector3d(-34.7793, -10.0, -11.25);
  stack.box.hi = Eigen::Vector3d(34.7793, 10.0, 11.25);
  o.regions = {stack};
  o.materials["body"] = {190e9, 0.3, 7800.0};
  o.materials["stack"] = {48e9, 0.31, 7800.0};
  o.remote_points = {RemotePointSpec::parse("top:y=max", "default"), RemotePointSpec::parse("bottom:y=min", "default"),
                     RemotePointSpec::parse("stack_a:x=-34.7793", "default"),
                     RemotePointSpec::parse("stack_b:x=34.7793", "default")};
  o.clamp = "bottom";
  o.axial = "top:y";
  return o;
}

void FromStepOptions::validate() const {
  const std::string src = "superelement from-step";
  if (!(std::isfinite(mesh_size_mm) && mesh_size_mm > 0.0)) {
    throw InputError(src, "--mesh-size", "a mesh size > 0 mm", format_number(mesh_size_mm, 17));
  }
  if (element_order != 1 && element_order != 2) throw InputError(src, "--order", "1 (C3D4) or 2 (C3D10)", std::to_string(element_order));
  if (modes < 0) throw InputError(src, "--modes", "a number of modes >= 0", std::to_string(modes));
  if (clamped_modes < 1) throw InputError(src, "--clamped-modes", "at least 1", std::to_string(clamped_modes));
  if (!(std::isfinite(geometry_tolerance_mm) && geometry_tolerance_mm > 0.0)) {
    throw InputError(src, "--geometry-tolerance", "a tolerance > 0 mm", format_number(geometry_tolerance_mm, 17));
  }
  if (remote_points.empty()) throw InputError(src, "--remote-point", "at least one remote point", "none");
  std::set<std::string> names;
  for (const RemotePointSpec& p : remote_points) {
    if (!detail::is_valid_name(p.name)) throw InputError(src, "--remote-point", "a name of letters, digits and _", "'" + p.name + "'");
    if (!names.insert(detail::upper(p.name)).second) throw InputError(src, "--remote-point", "distinct names", p.name + " twice");
  }
  if (names.count(detail::upper(clamp)) == 0) {
    std::string list;
    for (const RemotePointSpec& p : remote_points) {
      list += list.empty() ? "" : ", ";
      list += p.name;
    }
    throw InputError(src, "--clamp", "one of the remote points (" + list + ")", "'" + clamp + "'");
  }
  std::set<std::string> region_names{"BODY"};
  for (const RegionSpec& r : regions) {
    if (!detail::is_valid_name(r.name) || detail::upper(r.name) == "BODY") {
      throw InputError(src, "--region", "a name of letters, digits and _ other than body", "'" + r.name + "'");
    }
    if (!region_names.insert(detail::upper(r.name)).second) throw InputError(src, "--region", "distinct names", r.name + " twice");
    if (materials.count(r.name) == 0) throw InputError(src, "--material", "a material for the region " + r.name, "none");
  }
  if (materials.count("body") == 0) throw InputError(src, "--material", "a material for 'body' (the rest of the model)", "none");
  if (materials.at("body").removed) throw InputError(src, "--material body", "a material (only regions can be removed)", "none");
  std::set<std::string> nodes = names;
  for (const JointSpec& j : joints) {
    if (!detail::is_valid_name(j.name) || !(j.fraction > 0.0 && j.fraction < 1.0)) {
      throw InputError(src, "--joint " + j.name, "a name of letters, digits and _ and 0 < FRACTION < 1", "out of range");
    }
    for (const std::string& end : {j.from, j.to}) {
      if (nodes.count(detail::upper(end)) == 0) {
        throw InputError(src, "--joint " + j.name, "ends that are remote points or joints given before", "'" + end + "'");
      }
    }
    if (!nodes.insert(detail::upper(j.name)).second) throw InputError(src, "--joint", "a name no remote point or joint has", j.name);
  }
  for (const StackSpec& st : stacks) {
    const std::string field = "--stack " + st.from + ":" + st.to;
    for (const std::string& end : {st.from, st.to}) {
      if (nodes.count(detail::upper(end)) == 0) throw InputError(src, field, "ends that are remote points or joints", "'" + end + "'");
    }
    if (detail::upper(st.from) == detail::upper(st.to)) throw InputError(src, field, "two different ends", "the same twice");
    const BeamSection& b = st.section;
    if (!(b.youngs_modulus > 0.0) || !(b.poisson_ratio > -1.0 && b.poisson_ratio < 0.5) || !(b.density > 0.0) || !(b.area > 0.0)) {
      throw InputError(src, field, "E > 0, -1 < nu < 0.5, rho > 0, AREA > 0", "out of range");
    }
  }
  if (!axial.empty()) {
    const auto colon = axial.find(':');
    std::optional<Direction> dir;
    if (colon != std::string::npos) dir = direction_from_string(axial.substr(colon + 1));
    if (!dir || is_rotation(*dir) || names.count(detail::upper(axial.substr(0, colon))) == 0) {
      throw InputError(src, "--axial", "REMOTE_POINT:x|y|z (a remote point and a translation)", "'" + axial + "'");
    }
  }
  for (const auto& [name, value] : geo_parameters) {
    if (!detail::is_valid_name(name) || !std::isfinite(value)) throw InputError(src, "--geo-parameter", "NAME=VALUE (a finite number)", "'" + name + "'");
  }
  if (!(std::isfinite(max_memory_GB) && max_memory_GB >= 0.0)) {
    throw InputError(src, "--max-memory", "a memory limit >= 0 GB (0: automatic)", format_number(max_memory_GB, 17));
  }
  if (!(std::isfinite(tool_timeout_s) && tool_timeout_s > 0.0)) {
    throw InputError(src, "--tool-timeout", "a time limit > 0 s", format_number(tool_timeout_s, 17));
  }
  for (const auto& [name, m] : materials) {
    if (region_names.count(detail::upper(name)) == 0) {
      throw InputError(src, "--material", "a material for 'body' or a region given with --region", "'" + name + "'");
    }
    if (!m.removed && (!(m.youngs_modulus > 0.0) || !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) || !(m.density > 0.0))) {
      throw InputError(src, "--material " + name, "E > 0, -1 < nu < 0.5, rho > 0", "out of range");
    }
  }
}

// ---- the chain -------------------------------------------------------------------------------

namespace {

using PointSurfaces = std::vector<std::pair<std::string, std::vector<int>>>;  // remote point -> its faces

// The run's state from one step to the next: the result being filled, the work folder and what
// each step hands to the next (geometry, faces, mesh, interface points, the ccx dump).
class Chain {
 public:
  Chain(const fs::path& step_file, const FromStepOptions& o) : step_file_(step_file), o_(o), run_(o) {}

  void step_done(const std::string& step, double seconds) { r_.seconds.emplace_back(step, seconds); }

  // The STEP file, the output and work folders, the tools: everything checked before gmsh runs.
  void prepare() {
    std::error_code ec;
    if (!fs::is_regular_file(step_file_, ec)) {
      throw InputError(step_file_.string(), "file", "an existing STEP file", fs::exists(step_file_, ec) ? "not a regular file" : "no such file");
    }
    fs::create_directories(o_.out, ec);
    if (ec || !fs::is_directory(o_.out)) throw InputError(o_.out.string(), "--out", "a folder that can be created", ec.message());
    stem_ = sanitize_stem(o_.stem.empty() ? step_file_.stem().string() : o_.stem);
    work_.emplace(o_.out / kWorkDir, o_.keep_temp);
    w_ = work_->path();
    if (o_.keep_temp) r_.work_dir = w_;
    r_.gmsh = run_.check_tool(o_.gmsh, "gmsh", "--version", kMinGmsh, "gmsh", w_);
    r_.ccx = run_.check_tool(o_.ccx, "ccx", "-v", kMinCcx, "calculix-ccx", w_);
    run_.log("gmsh " + r_.gmsh.version + " (" + r_.gmsh.path + "), ccx " + r_.ccx.version + " (" + r_.ccx.path + ")");
  }

  // model.step in the work folder: the STEP file, or a gmsh script (e.g. apa300ml.geo) exported to
  // STEP with its parameters, then as any STEP file.
  void import_model() {
    if (text::to_lower(step_file_.extension().string()) != ".geo") {
      if (!o_.geo_parameters.empty()) throw InputError(step_file_.string(), "--geo-parameter", "a .geo input (gmsh script)", "a STEP file");
      copy_into(step_file_, w_ / "model.step");
      return;
    }
    copy_into(step_file_, w_ / "model.geo");
    std::vector<std::string> args = {"-0", "model.geo"};
    std::string text;
    for (const auto& [name, value] : o_.geo_parameters) {
      args.insert(args.end(), {"-setnumber", name, format_number(value, 17)});
      text += " " + name + "=" + format_number(value, 17);
    }
    args.insert(args.end(), {"-o", "model.step"});
    run_.log("[0/6] exporting the gmsh script to STEP:" + (text.empty() ? std::string(" default parameters") : text));
    const fs::path export_log = o_.out / "gmsh_export.log";
    const auto e_run = run_.run(r_.gmsh, "gmsh", args, w_, export_log, [](std::string_view l) { return l.find("Error") != std::string_view::npos; });
    step_done("gmsh export", e_run.seconds);
    if (e_run.exit_code != 0 || !fs::exists(w_ / "model.step")) {
      throw InputError(step_file_.string(), "geo", "a gmsh script that gmsh exports to STEP",
                       "exit code " + std::to_string(e_run.exit_code) + ": " + detail::last_lines(read_file(export_log), "rror", 3) +
                           " (log: " + export_log.string() + ")");
    }
  }

  // 1. The geometry: volumes and faces with their bounding boxes, the volumes of each region.
  void read_geometry() {
    run_.log("[1/6] reading the geometry (gmsh, OpenCASCADE): " + step_file_.string());
    prelude_ = detail::geometry_script("model.step", o_.regions, o_.geometry_tolerance_mm);
    write_text(w_ / "geometry.geo", prelude_ + detail::report_script("geometry.txt"));
    const fs::path geometry_log = o_.out / "gmsh_geometry.log";
    const auto g_run = run_.run(r_.gmsh, "gmsh", {"-0", "geometry.geo", "-o", "geometry.geo_unrolled"}, w_, geometry_log,
                                [](std::string_view l) { return l.find("Error") != std::string_view::npos; });
    step_done("gmsh geometry", g_run.seconds);
    const std::string g_log = read_file(geometry_log);
    if (!fs::exists(w_ / "geometry.txt")) {
      // gmsh writes its report even when the STEP file does not load: this is not gmsh running a .geo script.
      throw InputError("--gmsh", "gmsh", "gmsh running the geometry script (it writes geometry.txt)",
                       "no report from " + r_.gmsh.path + " (exit code " + std::to_string(g_run.exit_code) + "; log: " +
                           geometry_log.string() + ")");
    }
    if (g_run.exit_code != 0) {
      const std::string errors = detail::last_lines(g_log, "Err", 3);
      throw InputError(step_file_.string(), "STEP", "a STEP file that gmsh loads (OpenCASCADE)",
                       "gmsh exit code " + std::to_string(g_run.exit_code) + (errors.empty() ? "" : ": " + errors) + " (log: " +
                           geometry_log.string() + ")");
    }
    geometry_ = detail::parse_geometry_report(read_file(w_ / "geometry.txt"), (w_ / "geometry.txt").string());
    if (geometry_.volumes.empty()) {
      const std::string errors = detail::last_lines(g_log, "ERR", 2);
      throw InputError(step_file_.string(), "STEP", "a STEP file with at least one solid",
                       "no volume" + (errors.empty() ? std::string() : " (" + errors + ")"));
    }
    copy_into(w_ / "geometry.txt", o_.out / "geometry.txt");
    assign_regions(g_run.seconds);
  }

  // What the mesh would cost, before gmsh starts on it: a UsageError naming the smallest mesh size
  // within the memory limit when it is over.
  void check_mesh_estimate() {
    r_.estimate = estimate_mesh(geometry_.volume_mm3, geometry_.area_mm2, o_.mesh_size_mm, o_.element_order);
    const double limit = o_.max_memory_GB > 0.0 ? o_.max_memory_GB : default_max_memory_GB();
    char buf[160];
    std::snprintf(buf, sizeof buf, "  estimate at %g mm: ", o_.mesh_size_mm);
    run_.log(buf + r_.estimate.to_string() + "; memory limit " + format_number(limit, 17) + " GB");
    if (r_.estimate.memory_GB <= limit) return;
    // The smallest mesh size within the limit (the estimate falls as h grows).
    double lo = o_.mesh_size_mm, hi = std::max(1.0, o_.mesh_size_mm);
    while (estimate_mesh(geometry_.volume_mm3, geometry_.area_mm2, hi, o_.element_order).memory_GB > limit && hi < 1e6) hi *= 2.0;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      (estimate_mesh(geometry_.volume_mm3, geometry_.area_mm2, mid, o_.element_order).memory_GB > limit ? lo : hi) = mid;
    }
    char hint[64];
    std::snprintf(hint, sizeof hint, "%.2g", hi * 1.05);
    std::snprintf(buf, sizeof buf, "--mesh-size %g mm: ", o_.mesh_size_mm);
    throw UsageError("superelement from-step: " + std::string(buf) + r_.estimate.to_string() + ", more than the limit of " +
                     format_number(limit, 17) + " GB for this machine. The mesh size is in millimetres: give --mesh-size " + hint +
                     " or more, or raise the limit with --max-memory GB (gmsh was not started)");
  }

  // 2. Remote points: the faces of each, a face belonging to one only.
  void select_remote_point_faces() {
    std::map<int, std::string> owner;
    for (const RemotePointSpec& p : o_.remote_points) {
      const std::vector<int> faces = detail::select_faces(p.selector, geometry_, o_.geometry_tolerance_mm);
      if (faces.empty()) {
        throw InputError("--remote-point " + p.name, "selector", "'" + p.selector.to_string() + "' to select at least one face",
                         "no face; " + detail::describe_planar_faces(geometry_, o_.geometry_tolerance_mm) +
                             " (all faces with their bounding boxes: " + (o_.out / "geometry.txt").string() + ")");
      }
      for (const int f : faces) {
        const auto [it, fresh] = owner.emplace(f, p.name);
        if (!fresh) {
          throw InputError("--remote-point " + p.name, "selector", "faces of no other remote point",
                           "surface " + std::to_string(f) + " also selected by " + it->second);
        }
      }
      point_surfaces_.emplace_back(p.name, faces);
      std::string list;
      for (const int f : faces) {
        list += list.empty() ? "" : ",";
        list += std::to_string(f);
      }
      run_.log("  remote point " + p.name + " (" + p.selector.to_string() + "): surface " + list);
    }
  }

  // 3. The mesh (gmsh), its counts, the remote points' nodes, and mesh.inp for ccx.
  void mesh() {
    const char* const element = o_.element_order == 2 ? "C3D10" : "C3D4";
    {
      char buf[96];
      std::snprintf(buf, sizeof buf, "[2/6] meshing (gmsh, at most %g mm, %s)", o_.mesh_size_mm, element);
      run_.log(buf);
    }
    const std::string mesh_geo = prelude_ + detail::mesh_script(region_volumes_, point_surfaces_, o_.mesh_size_mm, o_.element_order);
    write_text(w_ / "mesh.geo", mesh_geo);
    write_text(o_.out / "mesh.geo", mesh_geo);
    const fs::path mesh_log = o_.out / "gmsh_mesh.log";
    const auto m_run = run_.run(r_.gmsh, "gmsh", {"-3", "mesh.geo", "-format", "inp", "-o", "gmsh.inp"}, w_, mesh_log, keep_gmsh_line);
    step_done("gmsh mesh", m_run.seconds);
    if (m_run.exit_code != 0 || !fs::exists(w_ / "gmsh.inp")) {
      throw NumericalError("gmsh meshing", "exit code " + std::to_string(m_run.exit_code) + ": " +
                                               detail::last_lines(read_file(mesh_log), "Error", 3) + " (log: " + mesh_log.string() + ")",
                           true);
    }
    const detail::GmshMesh gmsh_mesh = detail::read_gmsh_inp(w_ / "gmsh.inp");
    count_mesh(gmsh_mesh);
    place_remote_points(gmsh_mesh, mesh_log);
    detail::write_mesh_inp(w_ / "mesh.inp", gmsh_mesh, region_volumes_, points_);
    copy_into(w_ / "mesh.inp", o_.out / "mesh.inp");
    log_mesh(m_run.seconds);
  }

  // 4. K and M from ccx (*FREQUENCY,SOLVER=MATRIXSTORAGE).
  void assemble_matrices() {
    for (const auto& [name, vols] : region_volumes_) region_names_.push_back(name);
    const std::string deck = detail::ccx_deck("mesh.inp", o_.materials, region_names_, points_, nullptr, 0,
                                              "free-free K and M of " + step_file_.filename().string() + " (*FREQUENCY,SOLVER=MATRIXSTORAGE)");
    write_text(w_ / "matrices.inp", deck);
    write_text(o_.out / "matrices.inp", deck);
    run_.log("[3/6] assembling K and M (ccx *FREQUENCY,SOLVER=MATRIXSTORAGE)");
    const fs::path ccx_log = o_.out / "ccx_matrices.log";
    const auto c_run = run_.run(r_.ccx, "ccx", {"-i", "matrices"}, w_, ccx_log, keep_ccx_line);
    step_done("ccx matrices", c_run.seconds);
    if (c_run.exit_code != 0 || !fs::exists(w_ / "matrices.sti") || !fs::exists(w_ / "matrices.mas") || !fs::exists(w_ / "matrices.dof")) {
      throw NumericalError("ccx (*FREQUENCY,SOLVER=MATRIXSTORAGE)",
                           "exit code " + std::to_string(c_run.exit_code) + ": " + detail::last_lines(read_file(ccx_log), "ERROR", 3) +
                               " (log: " + ccx_log.string() + ", deck: " + (o_.out / "matrices.inp").string() + ")",
                           false);
    }
    run_.log("  " + elapsed(c_run.seconds));
  }

  // 5. Reading the dump and the Craig-Bampton reduction onto the remote points.
  void reduce() {
    run_.log("[4/6] reading the matrices");
    progress_start_ = std::chrono::steady_clock::now();
    const ProgressCallback progress = [this](const std::string& step, double fraction) { report_progress(step, fraction); };
    SparseModel model = read_calculix_model(w_ / "matrices.sti", w_ / "matrices.mas", w_ / "matrices.dof", w_ / "mesh.inp", progress);
    r_.model_dofs = model.size();
    step_done("read matrices", std::chrono::duration<double>(std::chrono::steady_clock::now() - progress_start_).count());
    if (!o_.keep_temp) {
      // The dumps are the largest files (hundreds of MB at 2 mm); they are read now.
      std::error_code ec;
      fs::remove(w_ / "matrices.sti", ec);
      fs::remove(w_ / "matrices.mas", ec);
    }
    run_.log("  " + std::to_string(model.size()) + " DOF, K with " + std::to_string(model.K.nonZeros()) + " nonzeros");

    run_.log("[5/6] Craig-Bampton reduction: " + std::to_string(6 * points_.size()) + " interface DOF, " + std::to_string(o_.modes) + " modes");
    std::vector<InterfacePoint> interface;
    for (const detail::DeckPoint& p : points_) interface.push_back({p.ref, p.rot});
    CraigBamptonOptions cb;
    cb.modes = o_.modes;
    progress_start_ = std::chrono::steady_clock::now();
    last_step_.clear();
    cb.progress = progress;
    r_.reduction = craig_bampton(std::move(model), interface, cb);  // K and M freed once split
    model = SparseModel{};  // free the large matrices
    r_.reduced = std::move(r_.reduction.reduced);
    r_.reduction.reduced = SuperElement{};
    r_.reduced.source = step_file_.filename().string() + " (gmsh " + r_.element_type + " mesh, ccx " + r_.ccx.version +
                        ", Craig-Bampton: " + std::to_string(r_.reduction.interface_dofs) + " interface DOF, " +
                        std::to_string(o_.modes) + " modes)";
    step_done("craig-bampton", r_.reduction.seconds);
    run_.log("  " + elapsed(r_.reduction.seconds));
  }

  // Clamped modes and axial stiffness of the reduced shell, then of the model with its joints and
  // stacks (nodes and beams added to the reduced model, exact: their ends are interface DOF).
  void clamped_properties() {
    for (const detail::DeckPoint& p : points_) {
      if (detail::upper(p.name) == detail::upper(o_.clamp)) clamp_ = &p;
    }
    r_.clamp = clamp_->name;
    bc_.fixed_nodes = {clamp_->ref};
    const Modes shell = modes(assemble(r_.reduced, bc_));
    r_.shell_modes_clamped_Hz = Eigen::VectorXd(shell.frequencies_Hz.head(std::min<Index>(o_.clamped_modes, shell.frequencies_Hz.size())));
    r_.shell_axial_stiffness = axial_stiffness_of(r_.reduced);
    if (!o_.joints.empty() || !o_.stacks.empty()) add_joints_and_stacks();
    r_.axial_stiffness = axial_stiffness_of(r_.reduced);
    const Modes clamped = modes(assemble(r_.reduced, bc_));
    r_.modes_clamped_Hz = clamped.frequencies_Hz.head(std::min<Index>(o_.clamped_modes, clamped.frequencies_Hz.size()));
    const Modes free = modes(r_.reduced.K, r_.reduced.M);
    r_.free_modes_Hz = free.frequencies_Hz.head(std::min<Index>(6 + o_.clamped_modes, free.frequencies_Hz.size()));
  }

  // 6. Outputs: the super element, its Simscape form and the inputs and logs of the tools.
  void write_outputs() {
    run_.log("[6/6] writing the super element into " + o_.out.string());
    r_.files = write_super_element(o_.out, stem_, r_.reduced);
    r_.files.push_back(write_simscape(o_.out, stem_, r_.reduced));
    for (const char* f : {"geometry.txt", "mesh.geo", "mesh.inp", "matrices.inp", "gmsh_geometry.log", "gmsh_mesh.log", "ccx_matrices.log"}) {
      r_.files.push_back(o_.out / f);
    }
  }

  // The reference: ccx *FREQUENCY on the full mesh with the same clamp.
  void verify() {
    const std::string ref_deck = detail::ccx_deck("mesh.inp", o_.materials, region_names_, points_, clamp_, o_.clamped_modes,
                                                  "reference: remote point " + clamp_->name + " clamped, ccx *FREQUENCY on the full mesh");
    write_text(w_ / "reference.inp", ref_deck);
    write_text(o_.out / "reference.inp", ref_deck);
    run_.log("[verify] ccx *FREQUENCY on the full mesh, " + clamp_->name + " clamped, " + std::to_string(o_.clamped_modes) + " modes");
    const fs::path ref_log = o_.out / "ccx_reference.log";
    const auto v_run = run_.run(r_.ccx, "ccx", {"-i", "reference"}, w_, ref_log, keep_ccx_line);
    step_done("ccx reference", v_run.seconds);
    if (v_run.exit_code != 0 || !fs::exists(w_ / "reference.dat")) {
      throw NumericalError("ccx (*FREQUENCY, reference)",
                           "exit code " + std::to_string(v_run.exit_code) + ": " + detail::last_lines(read_file(ref_log), "ERROR", 3) +
                               " (log: " + ref_log.string() + ")",
                           false);
    }
    const std::vector<double> f = detail::read_ccx_frequencies(w_ / "reference.dat");
    copy_into(w_ / "reference.dat", o_.out / "reference.dat");
    r_.reference_modes_Hz = Eigen::Map<const Eigen::VectorXd>(f.data(), static_cast<Index>(f.size()));
    for (const char* name : {"reference.inp", "reference.dat", "ccx_reference.log"}) r_.files.push_back(o_.out / name);
    run_.log("  " + elapsed(v_run.seconds));
  }

  FromStepResult take_result() { return std::move(r_); }

 private:
  // The volumes of each region, logged; the removed regions are left out of the mesh.
  void assign_regions(double geometry_seconds) {
    region_volumes_ = detail::assign_regions(geometry_, o_.regions, o_.geometry_tolerance_mm);
    std::string msg = "  " + std::to_string(geometry_.volumes.size()) + " volume(s), " + std::to_string(geometry_.surfaces.size()) + " faces;";
    for (const auto& [name, vols] : region_volumes_) {
      msg += " " + name + ": " + std::to_string(vols.size()) + " volume(s)" + (o_.materials.at(name).removed ? " (removed)" : "") + ";";
    }
    run_.log(msg + " " + elapsed(geometry_seconds));
    for (auto it = region_volumes_.begin(); it != region_volumes_.end();) {
      it = o_.materials.at(it->first).removed ? region_volumes_.erase(it) : std::next(it);
    }
  }

  // Elements and nodes of the mesh, in all and per region; the highest node number.
  void count_mesh(const detail::GmshMesh& mesh) {
    r_.element_type = mesh.volume_type;
    for (const auto& [id, p] : mesh.nodes) max_node_ = std::max(max_node_, id);
    std::set<long> used_nodes;
    for (const auto& [tag, elements] : mesh.volume_elements) {
      r_.mesh_elements += static_cast<Index>(elements.size());
      for (const auto& e : elements) used_nodes.insert(e.begin() + 1, e.end());
    }
    r_.mesh_nodes = static_cast<Index>(used_nodes.size());
    for (const auto& [name, vols] : region_volumes_) {
      Index n = 0;
      for (const int v : vols) {
        const auto it = mesh.volume_elements.find(v);
        if (it != mesh.volume_elements.end()) n += static_cast<Index>(it->second.size());
      }
      r_.region_elements[name] = n;
    }
  }

  // Each remote point on the meshed nodes of its faces (a node belonging to one only): its
  // reference and rotation nodes after the mesh's, at the faces' centroid.
  void place_remote_points(const detail::GmshMesh& mesh, const fs::path& mesh_log) {
    std::map<long, std::string> node_owner;
    for (std::size_t k = 0; k < point_surfaces_.size(); ++k) {
      const auto& [name, faces] = point_surfaces_[k];
      const detail::FacePatch patch = detail::face_patch(mesh, faces);
      if (patch.nodes.size() < 3 || !(patch.area > 0.0)) {
        throw InputError("--remote-point " + name, "faces", "meshed faces with at least 3 nodes",
                         std::to_string(patch.nodes.size()) + " nodes (log: " + mesh_log.string() + ")");
      }
      for (const long n : patch.nodes) {
        const auto [it, fresh] = node_owner.emplace(n, name);
        if (!fresh) {
          throw InputError("--remote-point " + name, "faces", "faces that do not touch the faces of another remote point",
                           "node " + std::to_string(n) + " shared with " + it->second + " (a *RIGID BODY node can belong to one only)");
        }
      }
      detail::DeckPoint dp;
      dp.name = name;
      dp.ref = max_node_ + 1 + 2 * static_cast<long>(k);
      dp.rot = dp.ref + 1;
      dp.position_m = 1e-3 * patch.centroid;
      dp.nodes = patch.nodes;
      points_.push_back(dp);
      RemotePointResult rp;
      rp.name = name;
      rp.selector = o_.remote_points[k].selector;
      rp.surfaces = faces;
      rp.node = dp.ref;
      rp.rot_node = dp.rot;
      rp.position_m = dp.position_m;
      rp.area_m2 = 1e-6 * patch.area;
      rp.face_nodes = static_cast<Index>(patch.nodes.size());
      r_.remote_points.push_back(rp);
    }
  }

  void log_mesh(double mesh_seconds) const {
    std::string msg = "  " + std::to_string(r_.mesh_nodes) + " nodes, " + std::to_string(r_.mesh_elements) + " " + r_.element_type +
                      " elements (about " + std::to_string(3 * r_.mesh_nodes) + " DOF);";
    for (const auto& [name, n] : r_.region_elements) msg += " " + name + " " + std::to_string(n) + ";";
    run_.log(msg + " " + elapsed(mesh_seconds));
    for (const RemotePointResult& rp : r_.remote_points) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "  remote point %s: node %ld (rotations on node %ld) at (%.6g, %.6g, %.6g) m, %lld face nodes",
                    rp.name.c_str(), rp.node, rp.rot_node, rp.position_m.x(), rp.position_m.y(), rp.position_m.z(),
                    static_cast<long long>(rp.face_nodes));
      run_.log(buf);
    }
  }

  // A progress line per step of the reader and the reduction, at most one a second per step.
  void report_progress(const std::string& step, double fraction) {
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - progress_start_).count();
    const std::string key = step.substr(0, step.find(" ("));
    if (key == last_step_ && (fraction >= 1.0 || now - last_report_ < 1.0)) return;
    last_step_ = key;
    last_report_ = now;
    char buf[160];
    std::snprintf(buf, sizeof buf, "  %6.1f s  %s", now, step.c_str());
    run_.log(buf);
  }

  // Static stiffness at `axial`, clamp fixed: 1 / (K_ff^-1)_jj (the modal DOF are uncoupled from the
  // interface in K, so this is the full model's static stiffness there).
  double axial_stiffness_of(const SuperElement& se) const {
    if (o_.axial.empty()) return 0.0;
    const auto colon = o_.axial.find(':');
    long node = -1;
    for (const detail::DeckPoint& p : points_) {
      if (detail::upper(p.name) == detail::upper(o_.axial.substr(0, colon))) node = p.ref;
    }
    ModelOptions mo = bc_;
    mo.forces = {ForcePair{-1, node, *direction_from_string(o_.axial.substr(colon + 1))}};
    mo.outputs = {DisplacementOutput{-1, node, mo.forces[0].direction}};
    const StructuralModel sm = assemble(se, mo);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(sm.K);
    const double compliance = (sm.T * ldlt.solve(sm.F))(0, 0);
    return compliance > 0.0 ? 1.0 / compliance : 0.0;
  }

  void add_joints_and_stacks() {
    std::map<std::string, std::pair<long, Eigen::Vector3d>> at;  // upper-case name -> node, position (m)
    for (const detail::DeckPoint& p : points_) at[detail::upper(p.name)] = {p.ref, p.position_m};
    long next = points_.back().rot + 1;
    for (const JointSpec& j : o_.joints) {
      const auto& a = at.at(detail::upper(j.from));
      const auto& b = at.at(detail::upper(j.to));
      const Eigen::Vector3d x = a.second + j.fraction * (b.second - a.second);
      add_node(r_.reduced, next, x);
      at[detail::upper(j.name)] = {next, x};
      r_.joints.push_back({j.name, next, x});
      run_.log("  joint " + j.name + ": node " + std::to_string(next) + " at " + format_number(j.fraction, 17) + " of " + j.from + " -> " + j.to);
      ++next;
    }
    for (const StackSpec& st : o_.stacks) {
      const long a = at.at(detail::upper(st.from)).first, b = at.at(detail::upper(st.to)).first;
      const BeamMatrices bm = add_beam(r_.reduced, a, b, st.section, "--stack " + st.from + ":" + st.to);
      r_.stacks.push_back({st.from, st.to, a, b, bm.length, bm.axial_stiffness, st.section.density * st.section.area * bm.length});
      char buf[200];
      std::snprintf(buf, sizeof buf, "  stack %s -> %s: beam of %.4g mm, E A / L = %.4g N/um, %.3g g", st.from.c_str(), st.to.c_str(),
                    1e3 * bm.length, 1e-6 * bm.axial_stiffness, 1e3 * r_.stacks.back().mass);
      run_.log(buf);
    }
    r_.reduced.source += ", " + std::to_string(o_.stacks.size()) + " stack beam(s)";
  }

  const fs::path& step_file_;
  const FromStepOptions& o_;
  FromStepResult r_;
  Runner run_;
  std::optional<WorkFolder> work_;  // removed with the Chain unless keep_temp
  fs::path w_;                      // its path
  std::string stem_;
  detail::GeometryReport geometry_;
  std::string prelude_;             // the geometry script, which the mesh script continues
  std::map<std::string, std::vector<int>> region_volumes_;  // the meshed regions' volumes
  PointSurfaces point_surfaces_;
  long max_node_ = 0;               // the mesh's highest node number
  std::vector<detail::DeckPoint> points_;
  std::vector<std::string> region_names_;
  const detail::DeckPoint* clamp_ = nullptr;
  ModelOptions bc_;                 // the clamp fixed
  std::chrono::steady_clock::time_point progress_start_;
  double last_report_ = -1.0;
  std::string last_step_;
};

}  // namespace

FromStepResult superelement_from_step(const fs::path& step_file, const FromStepOptions& o) {
  o.validate();
  const auto t_start = std::chrono::steady_clock::now();
  Chain chain(step_file, o);
  chain.prepare();
  chain.import_model();
  chain.read_geometry();
  chain.check_mesh_estimate();
  chain.select_remote_point_faces();
  chain.mesh();
  chain.assemble_matrices();
  chain.reduce();
  chain.clamped_properties();
  chain.write_outputs();
  if (o.verify) chain.verify();
  chain.step_done("total", std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count());
  return chain.take_result();
}

}  // namespace piezobench::fem
