#include "piezobench/fem/superelement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/fem/matrix_io.hpp"

namespace piezobench::fem {
namespace {

using text::quote;

std::string list_nodes(const std::vector<long>& nodes) {
  std::string s;
  for (std::size_t i = 0; i < nodes.size() && i < 20; ++i) s += (i ? ", " : "") + std::to_string(nodes[i]);
  if (nodes.size() > 20) s += ", ... (" + std::to_string(nodes.size()) + " nodes)";
  return s;
}

// ---- Ansys CMS text ---------------------------------------------------------------------------

struct AnsysMatrix {
  Eigen::MatrixXd A;
  int significant_digits = 0;  // most mantissa digits seen in an entry
};

int mantissa_digits(std::string_view number) {
  int digits = 0;
  bool leading = true;
  for (char c : number) {
    if (c == 'e' || c == 'E' || c == 'd' || c == 'D') break;
    if (c >= '0' && c <= '9') {
      if (leading && c == '0') continue;
      leading = false;
      ++digits;
    }
  }
  return digits;
}

// `[ i, j]: value` entries after a `MAT_x:` header, in any layout of lines and blanks.
AnsysMatrix read_ansys_matrix(const std::filesystem::path& file, const std::string& expected_header) {
  const std::string source = file.string();
  const std::string text = read_file(file);
  std::string_view s(text);
  // Header: the first non-blank line.
  const std::size_t first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) throw InputError(source, "header", "'" + expected_header + "' then entries", "an empty file");
  std::size_t eol = s.find('\n', first);
  if (eol == std::string_view::npos) eol = s.size();
  const std::string_view header = text::trim(s.substr(first, eol - first));
  if (header.rfind("MAT_", 0) != 0) {
    throw InputError(source, "header", "a first line '" + expected_header + "' (Ansys CMS text export)", quote(header));
  }
  // Line number of the text after the header.
  std::size_t line = static_cast<std::size_t>(std::count(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(eol), '\n')) + 2;
  s.remove_prefix(std::min(s.size(), eol + 1));

  struct Entry {
    long long i, j;
    double v;
  };
  std::vector<Entry> entries;
  entries.reserve(text.size() / 20);
  long long n = 0;
  int digits = 0;
  const auto fail = [&](const std::string& expected, std::string_view found) {
    throw InputError(source, "line " + std::to_string(line), expected, found.empty() ? "end of file" : quote(found));
  };
  while (true) {
    // Skip blanks, counting lines.
    while (!s.empty() && text::is_space(s.front())) {
      if (s.front() == '\n') ++line;
      s.remove_prefix(1);
    }
    if (s.empty()) break;
    if (s.front() != '[') fail("an entry '[ i, j]: value'", s.substr(0, s.find('\n')));
    std::string_view at = s;
    s.remove_prefix(1);
    const auto i = text::take_int(s);
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    if (!i || s.empty() || s.front() != ',') fail("an entry '[ i, j]: value'", at.substr(0, at.find('\n')));
    s.remove_prefix(1);
    const auto j = text::take_int(s);
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    if (!j || s.size() < 2 || s[0] != ']' || s[1] != ':') fail("an entry '[ i, j]: value'", at.substr(0, at.find('\n')));
    s.remove_prefix(2);
    // Built with snprintf: GCC 12 warns falsely (-Wrestrict) on "[" + std::to_string(..) chains.
    const auto entry = [&i, &j] {
      char buf[64];
      std::snprintf(buf, sizeof buf, "[%lld,%lld]", *i, *j);
      return std::string(buf);
    };
    std::string_view number_start = s;
    const auto v = text::take_double(s);
    if (!v) fail("a number after '" + entry() + ":'", at.substr(0, at.find('\n')));
    if (!s.empty() && !text::is_space(s.front()) && s.front() != '[') {
      fail("a blank after the value of '" + entry() + "'", at.substr(0, at.find('\n')));
    }
    if (*i < 1 || *j < 1) throw InputError(source, entry(), "1-based indices", "an index < 1 at line " + std::to_string(line));
    if (!std::isfinite(*v)) throw InputError(source, entry(), "a finite value", format_number(*v, 17) + " at line " + std::to_string(line));
    digits = std::max(digits, mantissa_digits(number_start.substr(0, static_cast<std::size_t>(s.data() - number_start.data()))));
    n = std::max({n, *i, *j});
    entries.push_back({*i, *j, *v});
  }
  if (entries.empty()) throw InputError(source, "entries", "'[ i, j]: value' entries after the header", "none (truncated file?)");
  if (n > 100000) throw InputError(source, "entries", "indices of a dense super element (<= 100000)", std::to_string(n));
  // The count is checked before the n x n matrix is allocated, so a declared size never costs more
  // memory than the entries in the file (issue 21.5: '[15000,15000]: 1.0' took 1.77 GB).
  if (static_cast<long long>(entries.size()) != n * n) {
    // The first missing (or repeated) entry in row-major order, from the sorted indices.
    std::vector<long long> keys;
    keys.reserve(entries.size());
    for (const Entry& e : entries) keys.push_back((e.i - 1) * n + (e.j - 1));
    std::sort(keys.begin(), keys.end());
    long long expect = 0;
    for (const long long k : keys) {
      if (k != expect) break;
      ++expect;
    }
    if (expect < static_cast<long long>(keys.size()) && keys[static_cast<std::size_t>(expect)] < expect) {
      const long long k = keys[static_cast<std::size_t>(expect)];
      throw InputError(source, "[" + std::to_string(k / n + 1) + "," + std::to_string(k % n + 1) + "]", "each entry once", "a repeated entry");
    }
    throw InputError(source, "entries",
                     std::to_string(n * n) + " entries of a full " + std::to_string(n) + " x " + std::to_string(n) + " matrix",
                     std::to_string(entries.size()) + " (first missing: [" + std::to_string(expect / n + 1) + "," +
                         std::to_string(expect % n + 1) + "]; truncated file?)");
  }
  const auto nn = static_cast<Index>(n);
  Eigen::MatrixXd A = Eigen::MatrixXd::Constant(nn, nn, std::numeric_limits<double>::quiet_NaN());
  for (const Entry& e : entries) {
    double& slot = A(static_cast<Index>(e.i - 1), static_cast<Index>(e.j - 1));
    if (!std::isnan(slot)) {
      throw InputError(source, "[" + std::to_string(e.i) + "," + std::to_string(e.j) + "]", "each entry once", "a repeated entry");
    }
    slot = e.v;
  }
  return {std::move(A), digits};
}

struct AnsysListing {
  std::vector<DofLabel> masters;
  std::map<long, Eigen::Vector3d> coordinates;
};

// Master DOF rows `NODE LABEL` and node-list rows `NODE X Y Z [...]`; everything else (titles,
// banners) is ignored.
AnsysListing read_ansys_listing(const std::filesystem::path& file) {
  const std::string text = read_file(file);
  AnsysListing out;
  text::for_each_line(text, [&](std::size_t number, std::string_view line) {
    const auto t = text::tokens(line);
    if (t.size() < 2) return true;
    const auto node = text::parse_int(t[0]);
    if (!node) return true;
    if (t.size() == 2) {
      const auto d = direction_from_string(std::string(t[1]));
      if (!d || text::parse_int(t[1])) {
        throw InputError(file.string(), "line " + std::to_string(number), "a master DOF 'NODE UX|UY|UZ|ROTX|ROTY|ROTZ'", quote(line));
      }
      if (*node < 0) throw InputError(file.string(), "line " + std::to_string(number), "a node number >= 0", quote(line));
      out.masters.push_back(DofLabel::nodal(static_cast<long>(*node), *d));
      return true;
    }
    if (t.size() >= 4) {
      const auto x = text::parse_double(t[1]), y = text::parse_double(t[2]), z = text::parse_double(t[3]);
      if (x && y && z) {
        if (!std::isfinite(*x) || !std::isfinite(*y) || !std::isfinite(*z)) {
          throw InputError(file.string(), "node " + std::to_string(*node), "finite coordinates", quote(line));
        }
        out.coordinates[static_cast<long>(*node)] = Eigen::Vector3d(*x, *y, *z);
      }
    }
    return true;
  });
  return out;
}

// Rows past the nodal ones must be modal coordinates of a Craig-Bampton element: K diagonal there,
// with no coupling to the nodal DOF. Otherwise the DOF list does not describe the matrix.
void check_modal_block(const SuperElement& se, const std::string& list_source, const std::string& list_field) {
  const Index nb = se.nodal_dofs();
  const Index n = se.size();
  if (nb == n) return;
  for (Index i = nb; i < n; ++i) {
    const double kii = se.K(i, i);
    for (Index j = 0; j < n; ++j) {
      if (j == i) continue;
      const double kjj = se.K(j, j);
      const double scale = std::sqrt(std::abs(kii * kjj));
      if (std::abs(se.K(i, j)) > 1e-6 * scale + 1e-300) {
        throw InputError(list_source, list_field,
                         std::to_string(n) + " rows (the size of the matrices) of which the first " + std::to_string(nb) +
                             " are nodal and the rest modal coordinates (K diagonal there)",
                         std::to_string(nb) + " nodal DOF, but row " + std::to_string(i + 1) +
                             " of K is coupled to row " + std::to_string(j + 1) +
                             ": the DOF list does not match the matrices");
      }
    }
  }
}

void finish_import(SuperElement& se, const ImportOptions& options, const std::string& precision_note) {
  se.validate(options.symmetry_tolerance);
  // Symmetrize what the tolerance accepted so that the solvers see exactly symmetric matrices.
  se.K = 0.5 * (se.K + se.K.transpose()).eval();
  se.M = 0.5 * (se.M + se.M.transpose()).eval();
  if (!options.check_rigid_body_modes) return;
  const RigidBodyCheck check = check_rigid_body_modes(se);
  if (check.spoiled) se.warnings.push_back(check.message + precision_note);
  if (!check.performed) se.warnings.push_back(check.message);
}

void check_size(const std::string& source, Index n, const ImportOptions& options) {
  if (n > options.max_dense_size) {
    throw InputError(source, "size",
                     "a super element of at most " + std::to_string(options.max_dense_size) +
                         " DOF for the dense import (reduce large models with craig_bampton)",
                     std::to_string(n) + " DOF");
  }
}

}  // namespace

std::string to_string(Direction d) {
  switch (d) {
    case Direction::kX: return "x";
    case Direction::kY: return "y";
    case Direction::kZ: return "z";
    case Direction::kRx: return "rx";
    case Direction::kRy: return "ry";
    case Direction::kRz: return "rz";
  }
  return "?";
}

std::string ansys_label(Direction d) {
  switch (d) {
    case Direction::kX: return "UX";
    case Direction::kY: return "UY";
    case Direction::kZ: return "UZ";
    case Direction::kRx: return "ROTX";
    case Direction::kRy: return "ROTY";
    case Direction::kRz: return "ROTZ";
  }
  return "?";
}

std::optional<Direction> direction_from_string(const std::string& text) {
  const std::string s = text::to_lower(std::string(text::trim(text)));
  static const std::pair<const char*, Direction> names[] = {
      {"x", Direction::kX},     {"y", Direction::kY},     {"z", Direction::kZ},     {"rx", Direction::kRx},
      {"ry", Direction::kRy},   {"rz", Direction::kRz},   {"ux", Direction::kX},    {"uy", Direction::kY},
      {"uz", Direction::kZ},    {"rotx", Direction::kRx}, {"roty", Direction::kRy}, {"rotz", Direction::kRz},
      {"1", Direction::kX},     {"2", Direction::kY},     {"3", Direction::kZ},     {"4", Direction::kRx},
      {"5", Direction::kRy},    {"6", Direction::kRz}};
  for (const auto& [name, d] : names) {
    if (s == name) return d;
  }
  return std::nullopt;
}

std::string to_string(SuperElementFormat f) {
  switch (f) {
    case SuperElementFormat::kAnsysText: return "ansys";
    case SuperElementFormat::kCalculix: return "calculix";
    case SuperElementFormat::kMatrixMarket: return "matrix-market";
  }
  return "?";
}

std::optional<SuperElementFormat> super_element_format_from_string(const std::string& text) {
  const std::string s = text::to_lower(text);
  if (s == "ansys") return SuperElementFormat::kAnsysText;
  if (s == "calculix" || s == "ccx") return SuperElementFormat::kCalculix;
  if (s == "matrix-market" || s == "mtx") return SuperElementFormat::kMatrixMarket;
  return std::nullopt;
}

SuperElementFormat detect_format(const std::filesystem::path& k_file) {
  const std::string ext = text::to_lower(k_file.extension().string());
  if (ext == ".sti" || ext == ".mas" || ext == ".dof") return SuperElementFormat::kCalculix;
  if (ext == ".mtx") return SuperElementFormat::kMatrixMarket;
  std::ifstream in(k_file);
  std::string first;
  if (in) std::getline(in, first);
  if (first.rfind("%%MatrixMarket", 0) == 0) return SuperElementFormat::kMatrixMarket;
  return SuperElementFormat::kAnsysText;
}

std::string DofLabel::to_string() const {
  if (is_modal()) return "mode " + std::to_string(mode);
  return std::to_string(node) + "." + ansys_label(direction);
}

Index SuperElement::modal_dofs() const {
  return static_cast<Index>(std::count_if(dofs.begin(), dofs.end(), [](const DofLabel& d) { return d.is_modal(); }));
}

std::vector<long> SuperElement::nodes() const {
  std::vector<long> out;
  std::set<long> seen;
  for (const DofLabel& d : dofs) {
    if (!d.is_modal() && seen.insert(d.node).second) out.push_back(d.node);
  }
  return out;
}

bool SuperElement::has_node(long node) const {
  return std::any_of(dofs.begin(), dofs.end(), [node](const DofLabel& d) { return !d.is_modal() && d.node == node; });
}

std::optional<Index> SuperElement::find(long node, Direction d) const {
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    if (!dofs[i].is_modal() && dofs[i].node == node && dofs[i].direction == d) return static_cast<Index>(i);
  }
  return std::nullopt;
}

Index SuperElement::index_of(long node, Direction d, const std::string& src, const std::string& field) const {
  if (const auto i = find(node, d)) return *i;
  if (!has_node(node)) {
    throw InputError(src, field, "a node of the super element (" + list_nodes(nodes()) + ")", "node " + std::to_string(node));
  }
  throw InputError(src, field, "a DOF that node " + std::to_string(node) + " has", "direction " + fem::to_string(d));
}

void SuperElement::validate(double symmetry_tolerance) const {
  const Index n = K.rows();
  if (n == 0) throw InputError(source, "K", "a non-empty matrix", "0 x 0");
  if (K.cols() != n) throw InputError(source, "K", "a square matrix", std::to_string(n) + " x " + std::to_string(K.cols()));
  if (M.rows() != n || M.cols() != n) {
    throw InputError(source, "M", "the size of K, " + std::to_string(n) + " x " + std::to_string(n),
                     std::to_string(M.rows()) + " x " + std::to_string(M.cols()));
  }
  if (static_cast<Index>(dofs.size()) != n) {
    throw InputError(source, "dofs", std::to_string(n) + " DOF labels (the matrix size)", std::to_string(dofs.size()));
  }
  bool seen_modal = false;
  std::set<std::pair<long, int>> seen;
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    const DofLabel& d = dofs[i];
    if (d.is_modal()) {
      seen_modal = true;
      continue;
    }
    if (seen_modal) throw InputError(source, "dofs", "nodal DOF before the modal ones", "nodal DOF " + d.to_string() + " after a modal one");
    if (!seen.insert({d.node, static_cast<int>(d.direction)}).second) {
      throw InputError(source, "dofs", "each nodal DOF once", d.to_string() + " twice (row " + std::to_string(i + 1) + ")");
    }
  }
  for (const auto& [name, A] : {std::pair<const char*, const Eigen::MatrixXd*>{"K", &K}, {"M", &M}}) {
    if (!A->allFinite()) {
      for (Index j = 0; j < n; ++j)
        for (Index i = 0; i < n; ++i)
          if (!std::isfinite((*A)(i, j)))
            throw InputError(source, std::string(name) + "[" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "]",
                             "a finite value", format_number((*A)(i, j), 17));
    }
    const double big = A->cwiseAbs().maxCoeff();
    for (Index j = 0; j < n; ++j) {
      for (Index i = j + 1; i < n; ++i) {
        const double a = (*A)(i, j), b = (*A)(j, i);
        const double m = std::max(std::abs(a), std::abs(b));
        if (std::abs(a - b) > symmetry_tolerance * m && m > 1e-12 * big) {
          throw InputError(source, std::string(name) + "[" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "]",
                           "a symmetric matrix (relative tolerance " + format_number(symmetry_tolerance, 17) + ")",
                           format_number(a, 17) + " against " + format_number(b, 17) + " at [" + std::to_string(j + 1) + "," +
                               std::to_string(i + 1) + "]");
        }
      }
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (M + M.transpose()));
  if (llt.info() != Eigen::Success) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (M + M.transpose()), Eigen::EigenvaluesOnly);
    throw InputError(source, "M", "a positive definite mass matrix",
                     "smallest eigenvalue " + format_number(es.eigenvalues()(0), 17) + " kg");
  }
}

void ImportOptions::validate() const {
  if (!(symmetry_tolerance >= 0.0 && symmetry_tolerance < 1.0)) {
    throw InputError("import options", "symmetry_tolerance", "a value in [0, 1)", format_number(symmetry_tolerance, 17));
  }
  if (max_dense_size < 1) throw InputError("import options", "max_dense_size", "a size >= 1", std::to_string(max_dense_size));
}

SuperElement read_ansys_super_element(const std::filesystem::path& k_file, const std::filesystem::path& m_file,
                                      const std::filesystem::path& master_file, const std::filesystem::path& nlist_file,
                                      const ImportOptions& options) {
  options.validate();
  AnsysMatrix k = read_ansys_matrix(k_file, "MAT_K:");
  AnsysMatrix m = read_ansys_matrix(m_file, "MAT_M:");
  if (k.A.rows() != m.A.rows()) {
    throw InputError(m_file.string(), "size", "the size of K (" + std::to_string(k.A.rows()) + ")",
                     std::to_string(m.A.rows()) + " (truncated file?)");
  }
  const Index n = k.A.rows();
  check_size(k_file.string(), n, options);
  const AnsysListing listing = read_ansys_listing(master_file);
  if (listing.masters.empty()) {
    throw InputError(master_file.string(), "master DOF", "rows 'NODE UX|UY|UZ|ROTX|ROTY|ROTZ' (Ansys master DOF listing)", "none");
  }
  if (static_cast<Index>(listing.masters.size()) > n) {
    throw InputError(master_file.string(), "master DOF",
                     "at most " + std::to_string(n) + " rows (the size of K in " + k_file.filename().string() + ")",
                     std::to_string(listing.masters.size()) + " rows");
  }
  SuperElement se;
  se.source = k_file.string();
  se.K = std::move(k.A);
  se.M = std::move(m.A);
  se.dofs = listing.masters;
  for (Index i = static_cast<Index>(listing.masters.size()); i < n; ++i) {
    se.dofs.push_back(DofLabel::modal(static_cast<int>(i - static_cast<Index>(listing.masters.size()) + 1)));
  }
  // Duplicated master rows are a listing problem: name that file.
  std::set<std::pair<long, int>> seen;
  for (const DofLabel& d : listing.masters) {
    if (!seen.insert({d.node, static_cast<int>(d.direction)}).second) {
      throw InputError(master_file.string(), "master DOF", "each DOF once", d.to_string() + " twice");
    }
  }
  check_modal_block(se, master_file.string(), "master DOF");

  // Coordinates: explicit node list, else out_NLIST.txt beside the listing, else the listing.
  std::filesystem::path nlist = nlist_file;
  if (nlist.empty()) {
    const auto beside = master_file.parent_path() / "out_NLIST.txt";
    if (std::filesystem::exists(beside)) nlist = beside;
  }
  std::map<long, Eigen::Vector3d> coordinates = listing.coordinates;
  std::string coordinates_source = master_file.string();
  if (!nlist.empty()) {
    AnsysListing nodes = read_ansys_listing(nlist);
    if (nodes.coordinates.empty()) {
      throw InputError(nlist.string(), "node list", "rows 'NODE X Y Z' (Ansys NLIST output)", "none");
    }
    coordinates = std::move(nodes.coordinates);
    coordinates_source = nlist.string();
  }
  if (!coordinates.empty()) {
    for (long node : se.nodes()) {
      const auto it = coordinates.find(node);
      if (it == coordinates.end()) {
        throw InputError(coordinates_source, "node " + std::to_string(node),
                         "coordinates for every node of the master DOF listing", "no row for this node");
      }
      se.coordinates[node] = it->second;
    }
  }
  const std::string note = " (the Ansys text keeps " + std::to_string(std::max(k.significant_digits, m.significant_digits)) +
                           " significant digits)";
  finish_import(se, options, note);
  return se;
}

SuperElement read_calculix_super_element(const std::filesystem::path& sti_file, const std::filesystem::path& mas_file,
                                         const std::filesystem::path& dof_file, const std::filesystem::path& nodes_inp,
                                         const ImportOptions& options) {
  options.validate();
  const std::vector<DofLabel> labels = read_calculix_dofs(dof_file);
  check_size(dof_file.string(), static_cast<Index>(labels.size()), options);
  SparseModel model = read_calculix_model(sti_file, mas_file, dof_file, nodes_inp);
  SuperElement se;
  se.source = sti_file.string();
  se.K = Eigen::MatrixXd(model.K);
  se.M = Eigen::MatrixXd(model.M);
  se.dofs = std::move(model.dofs);
  for (long node : se.nodes()) {
    const auto it = model.coordinates.find(node);
    if (it != model.coordinates.end()) se.coordinates[node] = it->second;
  }
  finish_import(se, options, "");
  return se;
}

SuperElement read_matrix_market_super_element(const std::filesystem::path& k_file, const std::filesystem::path& m_file,
                                              const std::filesystem::path& dof_list, const ImportOptions& options) {
  options.validate();
  const SparseMatrix k = read_matrix_market(k_file);
  check_size(k_file.string(), k.rows(), options);
  const SparseMatrix m = read_matrix_market(m_file);
  if (k.rows() != k.cols()) {
    throw InputError(k_file.string(), "size", "a square matrix", std::to_string(k.rows()) + " x " + std::to_string(k.cols()));
  }
  if (m.rows() != k.rows() || m.cols() != k.cols()) {
    throw InputError(m_file.string(), "size", "the size of K, " + std::to_string(k.rows()) + " x " + std::to_string(k.cols()),
                     std::to_string(m.rows()) + " x " + std::to_string(m.cols()));
  }
  DofList list = read_dof_list(dof_list);
  if (static_cast<Index>(list.dofs.size()) != k.rows()) {
    throw InputError(dof_list.string(), "rows", std::to_string(k.rows()) + " DOF (the size of K in " + k_file.filename().string() + ")",
                     std::to_string(list.dofs.size()));
  }
  SuperElement se;
  se.source = k_file.string();
  se.K = Eigen::MatrixXd(k);
  se.M = Eigen::MatrixXd(m);
  se.dofs = std::move(list.dofs);
  for (long node : se.nodes()) {
    const auto it = list.coordinates.find(node);
    if (it != list.coordinates.end()) se.coordinates[node] = it->second;
  }
  check_modal_block(se, dof_list.string(), "rows");
  finish_import(se, options, "");
  return se;
}

SuperElement read_super_element(SuperElementFormat format, const std::filesystem::path& k_file,
                                const std::filesystem::path& m_file, const std::filesystem::path& nodes_file,
                                const std::filesystem::path& coordinates_file, const ImportOptions& options) {
  switch (format) {
    case SuperElementFormat::kAnsysText:
      return read_ansys_super_element(k_file, m_file, nodes_file, coordinates_file, options);
    case SuperElementFormat::kCalculix:
      return read_calculix_super_element(k_file, m_file, nodes_file, coordinates_file, options);
    case SuperElementFormat::kMatrixMarket:
      return read_matrix_market_super_element(k_file, m_file, nodes_file, options);
  }
  throw InputError("", "format", "ansys, calculix or matrix-market", "an unknown format");
}

RigidBodyCheck check_rigid_body_modes(const SuperElement& se, double relative_threshold) {
  RigidBodyCheck out;
  const Index n = se.size();
  if (n < 7) {
    out.message = "rigid-body check skipped: fewer than 7 DOF";
    return out;
  }
  if (n > 3000) {
    out.message = "rigid-body check skipped: more than 3000 DOF";
    return out;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  const std::vector<long> nodes = se.nodes();
  for (long node : nodes) {
    const auto it = se.coordinates.find(node);
    if (it == se.coordinates.end()) {
      out.message = "rigid-body check skipped: node " + std::to_string(node) + " has no coordinates";
      return out;
    }
    centroid += it->second;
  }
  if (nodes.empty()) {
    out.message = "rigid-body check skipped: no nodal DOF";
    return out;
  }
  centroid /= static_cast<double>(nodes.size());
  // Rigid-body shapes: columns 0-2 translations, 3-5 rotations about the centroid. A rotation theta
  // about axis k moves a point at r by e_k x r, and turns its rotational DOF by e_k.
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, 6);
  for (Index i = 0; i < n; ++i) {
    const DofLabel& d = se.dofs[static_cast<std::size_t>(i)];
    if (d.is_modal()) continue;
    const int dir = static_cast<int>(d.direction) - 1;
    const Eigen::Vector3d r = se.coordinates.at(d.node) - centroid;
    for (int k = 0; k < 3; ++k) {
      if (dir < 3) {
        R(i, k) = dir == k ? 1.0 : 0.0;
        const Eigen::Vector3d v = Eigen::Vector3d::Unit(k).cross(r);
        R(i, 3 + k) = v(dir);
      } else {
        R(i, 3 + k) = dir - 3 == k ? 1.0 : 0.0;
      }
    }
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(se.K, se.M);
  if (es.info() != Eigen::Success) {
    out.message = "rigid-body check skipped: the free-free eigenproblem failed";
    return out;
  }
  out.performed = true;
  const Eigen::MatrixXd MR = se.M * R;
  const Eigen::MatrixXd RMR = R.transpose() * MR;
  const Eigen::LDLT<Eigen::MatrixXd> rmr(RMR);
  out.lowest_modes_Hz.resize(6);
  out.rigid_fraction.resize(6);
  for (Index k = 0; k < 6; ++k) {
    out.lowest_modes_Hz(k) = eigenvalue_Hz(es.eigenvalues()(k));
    // M-orthogonal projection of the (mass-normalized) mode on span(R): its squared M-norm.
    const Eigen::VectorXd b = MR.transpose() * es.eigenvectors().col(k);
    const Eigen::VectorXd c = rmr.solve(b);
    out.rigid_fraction(k) = b.dot(c);
  }
  out.first_flexible_Hz = eigenvalue_Hz(es.eigenvalues()(6));
  out.free_free = (out.rigid_fraction.array() > 0.9).all();
  const double worst = out.lowest_modes_Hz.cwiseAbs().maxCoeff();
  out.spoiled = out.free_free && worst > relative_threshold * std::abs(out.first_flexible_Hz);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "the six free-free rigid-body modes come out between %.4g Hz and %.4g Hz instead of 0 Hz "
                "(first flexible mode %.5g Hz): the matrices are too imprecise for an exact rigid-body null space; "
                "free-free and low-frequency results are unreliable, constrain an interface (--fix) or use a file "
                "written with more digits",
                out.lowest_modes_Hz.minCoeff(), out.lowest_modes_Hz.maxCoeff(), out.first_flexible_Hz);
  if (out.spoiled) {
    out.message = buf;
  } else if (out.free_free) {
    out.message = "the six free-free rigid-body modes are at 0 Hz within the file's precision";
  } else {
    out.message = "the super element is not free-free (its lowest modes are not rigid-body motions)";
  }
  return out;
}

double eigenvalue_Hz(double lambda) { return std::copysign(std::sqrt(std::abs(lambda)), lambda) / kTwoPi; }

}  // namespace piezobench::fem
