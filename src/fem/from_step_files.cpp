#include "from_step_files.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::fem::detail {
using text::for_each_line;
using text::parse_double;
using text::parse_int;
using text::quote;
using text::tokens;
using text::trim;

namespace {

const char* const kAxes[3] = {"x", "y", "z"};

std::string gnum(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string bounds_text(const Box3& b) {
  return "x " + gnum(b.lo.x()) + " .. " + gnum(b.hi.x()) + ", y " + gnum(b.lo.y()) + " .. " + gnum(b.hi.y()) + ", z " + gnum(b.lo.z()) +
         " .. " + gnum(b.hi.z()) + " mm";
}

// "id, x, y, z" with 12 significant digits (ccx reads fields of at most 20 characters).
void node_line(std::string& buf, long id, const Eigen::Vector3d& p) {
  char line[120];
  std::snprintf(line, sizeof line, "%ld, %.12g, %.12g, %.12g\n", id, p.x(), p.y(), p.z());
  buf += line;
}

// Position tolerance of plane selectors: the geometry tolerance or 1e-4 of the model's size.
double plane_tolerance(const GeometryReport& g, double tolerance_mm) {
  return std::max(tolerance_mm, 1e-4 * (g.bounds.hi - g.bounds.lo).norm());
}

bool flat_along(const Box3& b, int axis, double tolerance_mm) { return b.hi(axis) - b.lo(axis) <= tolerance_mm; }

// Comma-separated ids of one data line of an INP block.
void parse_ids(std::string_view line, std::vector<long>& out, const std::string& source, std::size_t number) {
  for (const std::string_view tok : tokens(line, /*commas=*/true)) {
    const auto v = parse_int(tok);
    if (!v || *v < 0) throw InputError(source, "line " + std::to_string(number), "integer ids", quote(line));
    out.push_back(static_cast<long>(*v));
  }
}

}  // namespace

bool is_valid_name(const std::string& name) {
  if (name.empty() || name.size() > 40) return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; });
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string geometry_script(const std::string& step_name, const std::vector<RegionSpec>& regions, double tolerance_mm) {
  std::string s;
  s += "// written by piezobench superelement from-step\n";
  s += "SetFactory(\"OpenCASCADE\");\n";
  s += "Geometry.OCCTargetUnit = \"MM\";\n";
  s += "Geometry.ToleranceBoolean = " + format_number(tolerance_mm, 17) + ";\n";
  s += "Merge \"" + step_name + "\";\n";
  s += "pb_body() = Volume{:};\n";
  for (const RegionSpec& r : regions) {
    const Eigen::Vector3d d = r.box.hi - r.box.lo;
    s += "// region " + r.name + "\n";
    s += "If (#pb_body() > 0)\n";
    s += "  pb_box = newv;\n";
    s += "  Box(pb_box) = {" + format_number(r.box.lo.x(), 17) + ", " + format_number(r.box.lo.y(), 17) + ", " + format_number(r.box.lo.z(), 17) + ", " + format_number(d.x(), 17) +
         ", " + format_number(d.y(), 17) + ", " + format_number(d.z(), 17) + "};\n";
    s += "  pb_in() = BooleanIntersection{ Volume{pb_body()}; }{ Volume{pb_box}; Delete; };\n";
    s += "  If (#pb_in() > 0)\n";
    s += "    pb_all() = BooleanFragments{ Volume{pb_body()}; Delete; }{ Volume{pb_in()}; Delete; };\n";
    s += "  EndIf\n";
    s += "  pb_body() = Volume{:};\n";
    s += "EndIf\n";
  }
  return s;
}

std::string report_script(const std::string& report_name) {
  const std::string f = "\"" + report_name + "\"";
  std::string s;
  s += "Printf(\"# gmsh entities: tag and bounding box (mm)\") > " + f + ";\n";
  s += "pb_v() = Volume{:};\n";
  s += "For pb_i In {0:#pb_v()-1}\n";
  s += "  pb_b() = BoundingBox Volume{pb_v(pb_i)};\n";
  s += "  Printf(\"V %g %.17g %.17g %.17g %.17g %.17g %.17g\", pb_v(pb_i), pb_b(0), pb_b(1), pb_b(2), pb_b(3), pb_b(4), pb_b(5)) >> " + f + ";\n";
  s += "EndFor\n";
  s += "pb_s() = Surface{:};\n";
  s += "For pb_i In {0:#pb_s()-1}\n";
  s += "  pb_b() = BoundingBox Surface{pb_s(pb_i)};\n";
  s += "  Printf(\"S %g %.17g %.17g %.17g %.17g %.17g %.17g\", pb_s(pb_i), pb_b(0), pb_b(1), pb_b(2), pb_b(3), pb_b(4), pb_b(5)) >> " + f + ";\n";
  s += "EndFor\n";
  s += "pb_vol = 0;\nFor pb_i In {0:#pb_v()-1}\n  pb_vol += Mass Volume{pb_v(pb_i)};\nEndFor\n";
  s += "pb_area = 0;\nFor pb_i In {0:#pb_s()-1}\n  pb_area += Mass Surface{pb_s(pb_i)};\nEndFor\n";
  s += "Printf(\"A %.17g %.17g\", pb_vol, pb_area) >> " + f + ";\n";
  s += "Printf(\"END\") >> " + f + ";\n";
  return s;
}

GeometryReport parse_geometry_report(const std::string& text, const std::string& source) {
  GeometryReport g;
  bool end = false;
  for_each_line(text, [&](std::size_t line, std::string_view l) {
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') return true;
    if (t == "END") {
      end = true;
      return false;
    }
    const auto tok = tokens(t);
    if (tok.size() == 3 && tok[0] == "A") {
      const auto v = parse_double(tok[1]), a = parse_double(tok[2]);
      if (!v || !a || !(*v >= 0.0) || !(*a >= 0.0)) throw InputError(source, "line " + std::to_string(line), "'A volume area'", quote(t));
      g.volume_mm3 = *v;
      g.area_mm2 = *a;
      return true;
    }
    if (tok.size() != 8 || (tok[0] != "V" && tok[0] != "S")) {
      throw InputError(source, "line " + std::to_string(line), "'V|S tag x0 y0 z0 x1 y1 z1'", quote(t));
    }
    GeoEntity e;
    const auto tag = parse_int(tok[1]);
    if (!tag) throw InputError(source, "line " + std::to_string(line), "an integer tag", quote(t));
    e.tag = static_cast<int>(*tag);
    double v[6];
    for (int k = 0; k < 6; ++k) {
      const auto x = parse_double(tok[static_cast<std::size_t>(k + 2)]);
      if (!x || !std::isfinite(*x)) throw InputError(source, "line " + std::to_string(line), "finite coordinates", quote(t));
      v[k] = *x;
    }
    e.box.lo = Eigen::Vector3d(v[0], v[1], v[2]);
    e.box.hi = Eigen::Vector3d(v[3], v[4], v[5]);
    (tok[0] == "V" ? g.volumes : g.surfaces).push_back(e);
    return true;
  });
  if (!end) throw InputError(source, "END", "the complete report of gmsh", "a truncated file");
  if (!g.volumes.empty()) {
    g.bounds = g.volumes.front().box;
    for (const GeoEntity& v : g.volumes) {
      g.bounds.lo = g.bounds.lo.cwiseMin(v.box.lo);
      g.bounds.hi = g.bounds.hi.cwiseMax(v.box.hi);
    }
  }
  return g;
}

std::map<std::string, std::vector<int>> assign_regions(const GeometryReport& g, const std::vector<RegionSpec>& regions,
                                                       double tolerance_mm) {
  std::map<std::string, std::vector<int>> out;
  for (const GeoEntity& v : g.volumes) {
    std::string name = "body";
    for (const RegionSpec& r : regions) {
      if (r.box.contains(v.box, tolerance_mm)) {
        name = r.name;
        break;
      }
    }
    out[name].push_back(v.tag);
  }
  for (const RegionSpec& r : regions) {
    if (out.count(r.name) == 0) {
      throw InputError("--region " + r.name, "box",
                       "a box that contains part of the bodies (bounding box of the model: " + bounds_text(g.bounds) + ")",
                       "no volume inside it");
    }
  }
  return out;
}

std::vector<int> select_faces(const FaceSelector& selector, const GeometryReport& g, double tolerance_mm) {
  std::vector<int> out;
  switch (selector.kind) {
    case FaceSelector::Kind::kPlane: {
      const int a = selector.axis;
      const double at = selector.at == FaceSelector::At::kMax   ? g.bounds.hi(a)
                        : selector.at == FaceSelector::At::kMin ? g.bounds.lo(a)
                                                                : selector.value;
      const double tol = plane_tolerance(g, tolerance_mm);
      for (const GeoEntity& s : g.surfaces) {
        if (flat_along(s.box, a, tolerance_mm) && std::abs(0.5 * (s.box.lo(a) + s.box.hi(a)) - at) <= tol) out.push_back(s.tag);
      }
      break;
    }
    case FaceSelector::Kind::kBox:
      for (const GeoEntity& s : g.surfaces) {
        if (selector.box.contains(s.box, tolerance_mm)) out.push_back(s.tag);
      }
      break;
    case FaceSelector::Kind::kSurfaces:
      for (const int tag : selector.surfaces) {
        if (std::any_of(g.surfaces.begin(), g.surfaces.end(), [&](const GeoEntity& s) { return s.tag == tag; })) {
          out.push_back(tag);
        }
      }
      if (out.size() != selector.surfaces.size()) out.clear();  // all of them or nothing
      break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string describe_planar_faces(const GeometryReport& g, double tolerance_mm) {
  std::string out;
  for (int a = 0; a < 3; ++a) {
    std::set<double> at;
    for (const GeoEntity& s : g.surfaces) {
      if (flat_along(s.box, a, tolerance_mm)) at.insert(std::round(0.5 * (s.box.lo(a) + s.box.hi(a)) * 1e4) / 1e4);
    }
    out += std::string(out.empty() ? "" : "; ") + "planar faces normal to " + kAxes[a] + " at " + kAxes[a] + " = ";
    if (at.empty()) out += "(none)";
    std::size_t k = 0;
    for (const double v : at) {
      if (k++ > 0) out += ", ";
      if (k > 12) {
        out += "...";
        break;
      }
      out += gnum(v);
    }
  }
  return out + " (model: " + bounds_text(g.bounds) + ")";
}

std::string mesh_script(const std::map<std::string, std::vector<int>>& region_volumes,
                        const std::vector<std::pair<std::string, std::vector<int>>>& point_surfaces, double mesh_size_mm,
                        int element_order) {
  const auto list = [](const std::vector<int>& tags) {
    std::string s;
    for (const int t : tags) {
      s += s.empty() ? "" : ", ";
      s += std::to_string(t);
    }
    return s;
  };
  std::string s;
  for (const auto& [name, volumes] : region_volumes) {
    s += "Physical Volume(\"E_" + upper(name) + "\") = {" + list(volumes) + "};\n";
  }
  for (const auto& [name, surfaces] : point_surfaces) {
    s += "Physical Surface(\"F_" + upper(name) + "\") = {" + list(surfaces) + "};\n";
  }
  s += "Mesh.MeshSizeMax = " + format_number(mesh_size_mm, 17) + ";\n";
  s += "Mesh.MeshSizeFromCurvature = 0;\n";
  s += "Mesh.ElementOrder = " + std::to_string(element_order) + ";\n";
  s += "Mesh.SecondOrderLinear = 0;\n";
  s += "Mesh.Optimize = 1;\n";
  return s;
}

GmshMesh read_gmsh_inp(const std::filesystem::path& file) {
  const std::string source = file.string();
  const std::string text = read_file(file);
  GmshMesh mesh;
  enum class Block { kNone, kNode, kVolume, kSurface } block = Block::kNone;
  std::vector<std::vector<long>>* target = nullptr;
  std::size_t expected_nodes = 0;
  std::vector<long> ids;
  for_each_line(text, [&](std::size_t line, std::string_view l) {
    const std::string_view t = trim(l);
    if (t.empty() || t.rfind("**", 0) == 0) return true;
    if (t.front() == '*') {
      std::string key = upper(std::string(t));
      key.erase(std::remove(key.begin(), key.end(), ' '), key.end());
      block = Block::kNone;
      if (key == "*NODE" || key.rfind("*NODE,", 0) == 0) {
        block = Block::kNode;
      } else if (key.rfind("*ELEMENT,", 0) == 0) {
        const auto type_at = key.find("TYPE=");
        const auto set_at = key.find("ELSET=");
        if (type_at == std::string::npos || set_at == std::string::npos) {
          throw InputError(source, "line " + std::to_string(line), "*ELEMENT, type=..., ELSET=...", quote(t));
        }
        const std::string type = key.substr(type_at + 5, key.find(',', type_at) - type_at - 5);
        std::string set = key.substr(set_at + 6);
        set = set.substr(0, set.find(','));
        const auto tag_of = [&](const std::string& prefix) -> int {
          const auto v = set.rfind(prefix, 0) == 0 ? parse_int(std::string_view(set).substr(prefix.size())) : std::nullopt;
          if (!v) {
            throw InputError(source, "line " + std::to_string(line), "ELSET=" + prefix + "<tag> (gmsh)", quote(t));
          }
          return static_cast<int>(*v);
        };
        if (type == "C3D4" || type == "C3D10") {
          if (!mesh.volume_type.empty() && mesh.volume_type != type) {
            throw InputError(source, "line " + std::to_string(line), "one kind of volume element (" + mesh.volume_type + ")", type);
          }
          mesh.volume_type = type;
          block = Block::kVolume;
          expected_nodes = type == "C3D4" ? 4 : 10;
          target = &mesh.volume_elements[tag_of("VOLUME")];
        } else if (type == "CPS3" || type == "CPS6") {
          block = Block::kSurface;
          expected_nodes = type == "CPS3" ? 3 : 6;
          target = &mesh.surface_elements[tag_of("SURFACE")];
        }
      }
      return true;
    }
    switch (block) {
      case Block::kNone:
        break;
      case Block::kNode: {
        const auto tok = tokens(t, /*commas=*/true);
        const auto id = tok.empty() ? std::nullopt : parse_int(tok[0]);
        if (!id || tok.size() != 4) throw InputError(source, "line " + std::to_string(line), "a node line 'id, x, y, z'", quote(t));
        Eigen::Vector3d p;
        for (int k = 0; k < 3; ++k) {
          const auto v = parse_double(tok[static_cast<std::size_t>(k + 1)]);
          if (!v || !std::isfinite(*v)) throw InputError(source, "line " + std::to_string(line), "finite coordinates", quote(t));
          p(k) = *v;
        }
        mesh.nodes[static_cast<long>(*id)] = p;
        break;
      }
      case Block::kVolume:
      case Block::kSurface: {
        ids.clear();
        parse_ids(t, ids, source, line);
        if (ids.size() != expected_nodes + 1) {
          throw InputError(source, "line " + std::to_string(line),
                           "an element line with an id and " + std::to_string(expected_nodes) + " nodes", quote(t));
        }
        target->push_back(ids);
        break;
      }
    }
    return true;
  });
  if (mesh.nodes.empty() || mesh.volume_elements.empty()) {
    throw InputError(source, "elements", "nodes and volume elements (C3D4 or C3D10)", "none");
  }
  for (const auto& [tag, elements] : mesh.volume_elements) {
    for (const auto& e : elements) {
      for (std::size_t k = 1; k < e.size(); ++k) {
        if (mesh.nodes.count(e[k]) == 0) {
          throw InputError(source, "element " + std::to_string(e[0]), "nodes defined under *NODE", "node " + std::to_string(e[k]));
        }
      }
    }
  }
  return mesh;
}

FacePatch face_patch(const GmshMesh& mesh, const std::vector<int>& surfaces) {
  FacePatch p;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const int tag : surfaces) {
    const auto it = mesh.surface_elements.find(tag);
    if (it == mesh.surface_elements.end()) continue;
    for (const auto& e : it->second) {
      const Eigen::Vector3d& a = mesh.nodes.at(e[1]);
      const Eigen::Vector3d& b = mesh.nodes.at(e[2]);
      const Eigen::Vector3d& c = mesh.nodes.at(e[3]);
      const double area = 0.5 * (b - a).cross(c - a).norm();
      p.area += area;
      moment += area * (a + b + c) / 3.0;
      p.nodes.insert(p.nodes.end(), e.begin() + 1, e.end());
    }
  }
  if (p.area > 0.0) p.centroid = moment / p.area;
  std::sort(p.nodes.begin(), p.nodes.end());
  p.nodes.erase(std::unique(p.nodes.begin(), p.nodes.end()), p.nodes.end());
  return p;
}

void write_mesh_inp(const std::filesystem::path& file, const GmshMesh& mesh,
                    const std::map<std::string, std::vector<int>>& region_volumes, const std::vector<DeckPoint>& points) {
  std::vector<char> used;
  long max_node = 0;
  for (const auto& [id, p] : mesh.nodes) max_node = std::max(max_node, id);
  used.assign(static_cast<std::size_t>(max_node + 1), 0);
  for (const auto& [tag, elements] : mesh.volume_elements) {
    for (const auto& e : elements) {
      for (std::size_t k = 1; k < e.size(); ++k) used[static_cast<std::size_t>(e[k])] = 1;
    }
  }
  write_atomically(file, [&](std::ostream& out) {
    std::string buf;
    buf.reserve(1 << 20);
    const auto flush = [&] {
      out << buf;
      buf.clear();
    };
    buf += "** mesh of piezobench superelement from-step (gmsh), metres\n*NODE, NSET=NALL\n";
    for (const auto& [id, p] : mesh.nodes) {
      if (used[static_cast<std::size_t>(id)] == 0) continue;
      node_line(buf, id, 1e-3 * p);
      if (buf.size() > (1 << 20)) flush();
    }
    for (const auto& [region, volumes] : region_volumes) {
      buf += "*ELEMENT, TYPE=" + mesh.volume_type + ", ELSET=E_" + upper(region) + "\n";
      for (const int tag : volumes) {
        const auto it = mesh.volume_elements.find(tag);
        if (it == mesh.volume_elements.end()) continue;
        for (const auto& e : it->second) {
          for (std::size_t k = 0; k < e.size(); ++k) {
            buf += std::to_string(e[k]);
            buf += k + 1 < e.size() ? ", " : "\n";
          }
          if (buf.size() > (1 << 20)) flush();
        }
      }
    }
    for (const DeckPoint& pt : points) {
      buf += "*NSET, NSET=F_" + upper(pt.name) + "\n";
      for (std::size_t k = 0; k < pt.nodes.size(); ++k) {
        buf += std::to_string(pt.nodes[k]);
        buf += (k % 10 == 9 || k + 1 == pt.nodes.size()) ? "\n" : ", ";
      }
    }
    buf += "** remote points: REF NODE (translations) and ROT NODE (its translations are the rotations)\n*NODE, NSET=REMOTE\n";
    for (const DeckPoint& pt : points) {
      for (const long id : {pt.ref, pt.rot}) {
        node_line(buf, id, pt.position_m);
      }
    }
    flush();
  });
}

std::string ccx_deck(const std::string& mesh_inp_name, const std::map<std::string, Material>& materials,
                     const std::vector<std::string>& regions, const std::vector<DeckPoint>& points, const DeckPoint* clamp,
                     int modes, const std::string& title) {
  std::string s = "** " + title + "\n** written by piezobench superelement from-step; run with: ccx -i <this file without .inp>\n";
  s += "*INCLUDE, INPUT=" + mesh_inp_name + "\n";
  for (const std::string& r : regions) {
    const Material& m = materials.at(r);
    s += "*MATERIAL, NAME=M_" + upper(r) + "\n*ELASTIC\n" + format_number(m.youngs_modulus, 17) + ", " + format_number(m.poisson_ratio, 17) + "\n*DENSITY\n" +
         format_number(m.density, 17) + "\n";
    s += "*SOLID SECTION, ELSET=E_" + upper(r) + ", MATERIAL=M_" + upper(r) + "\n";
  }
  for (const DeckPoint& p : points) {
    s += "*RIGID BODY, NSET=F_" + upper(p.name) + ", REF NODE=" + std::to_string(p.ref) + ", ROT NODE=" + std::to_string(p.rot) + "\n";
  }
  if (clamp == nullptr) {
    s += "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n";
  } else {
    s += "*BOUNDARY\n" + std::to_string(clamp->ref) + ", 1, 3\n" + std::to_string(clamp->rot) + ", 1, 3\n";
    s += "*STEP\n*FREQUENCY\n" + std::to_string(modes) + "\n*END STEP\n";
  }
  return s;
}

std::vector<double> read_ccx_frequencies(const std::filesystem::path& dat_file) {
  const std::string text = read_file(dat_file);
  std::vector<double> out;
  bool table = false;
  for_each_line(text, [&](std::size_t, std::string_view l) {
    if (l.find("E I G E N V A L U E   O U T P U T") != std::string_view::npos) {
      table = true;
      return true;
    }
    if (!table) return true;
    const auto tok = tokens(l);
    if (tok.size() == 5 && parse_int(tok[0])) {
      const auto f = parse_double(tok[3]);
      if (!f) throw InputError(dat_file.string(), "eigenvalue table", "MODE EIGENVALUE RAD/TIME CYCLES/TIME IMAG", quote(l));
      out.push_back(*f);
    } else if (!out.empty() && tok.empty()) {
      return false;  // the table ends with a blank line
    }
    return true;
  });
  if (out.empty()) throw InputError(dat_file.string(), "eigenvalue table", "the E I G E N V A L U E   O U T P U T table of ccx", "none");
  return out;
}

}  // namespace piezobench::fem::detail
