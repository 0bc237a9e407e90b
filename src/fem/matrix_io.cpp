#include "piezobench/fem/matrix_io.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::fem {
namespace {

using text::quote;
using Triplet = Eigen::Triplet<double, int>;

std::string at_line(std::size_t line) { return "line " + std::to_string(line); }

// Builds the full symmetric matrix from one triangle's triplets (any mix of (i, j) and (j, i)
// positions); a position given twice is an InputError.
SparseMatrix symmetric_from_triangle(std::vector<Triplet>& triplets, Index n, const std::string& source) {
  for (Triplet& t : triplets) {
    if (t.row() > t.col()) t = Triplet(t.col(), t.row(), t.value());
  }
  SparseMatrix upper(n, n);
  // Duplicates are kept apart (not summed) by counting through a no-op functor; compare sizes.
  upper.setFromTriplets(triplets.begin(), triplets.end());
  if (upper.nonZeros() != static_cast<Index>(triplets.size())) {
    // Find one repeated position for the message.
    std::vector<std::pair<int, int>> pos;
    pos.reserve(triplets.size());
    for (const Triplet& t : triplets) pos.emplace_back(t.row(), t.col());
    std::sort(pos.begin(), pos.end());
    const auto it = std::adjacent_find(pos.begin(), pos.end());
    std::string where = it == pos.end() ? "" : " (entry " + std::to_string(it->first + 1) + " " + std::to_string(it->second + 1) + ")";
    throw InputError(source, "entries", "each entry of one triangle once", "a repeated entry" + where);
  }
  std::vector<Triplet>().swap(triplets);
  SparseMatrix full = upper.selfadjointView<Eigen::Upper>();
  full.makeCompressed();
  return full;
}

}  // namespace

SparseMatrix read_calculix_matrix(const std::filesystem::path& file, Index n, const ProgressCallback& progress) {
  const std::string source = file.string();
  const std::string text = read_file(file);
  std::vector<Triplet> triplets;
  triplets.reserve(text.size() / 30);
  std::size_t line = 0;
  std::size_t start = 0;
  const std::size_t size = text.size();
  std::size_t next_report = size / 10;
  while (start < size) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = size;
    ++line;
    std::string_view s(text.data() + start, end - start);
    if (!text::trim(s).empty()) {
      const std::string_view whole = s;
      const auto i = text::take_int(s);
      const auto j = i ? text::take_int(s) : std::nullopt;
      const auto v = j ? text::take_double(s) : std::nullopt;
      if (!v || !text::trim(s).empty()) {
        throw InputError(source, at_line(line), "'row col value' (1-based, CalculiX MATRIXSTORAGE)", quote(whole));
      }
      if (*i < 1 || *j < 1 || *i > n || *j > n) {
        throw InputError(source, at_line(line), "indices in 1.." + std::to_string(n) + " (the rows of the .dof file)",
                         quote(whole));
      }
      if (!std::isfinite(*v)) throw InputError(source, at_line(line), "a finite value", quote(whole));
      triplets.emplace_back(static_cast<int>(*i - 1), static_cast<int>(*j - 1), *v);
    }
    start = end + 1;
    if (progress && start >= next_report) {
      progress("reading " + file.filename().string(), static_cast<double>(std::min(start, size)) / static_cast<double>(size));
      next_report += size / 10;
    }
  }
  if (triplets.empty()) throw InputError(source, "entries", "'row col value' lines", "none (empty file)");
  SparseMatrix full = symmetric_from_triangle(triplets, n, source);
  // CalculiX stores every diagonal entry; a missing one means a truncated file.
  Eigen::VectorXi has_diagonal = Eigen::VectorXi::Zero(n);
  for (int k = 0; k < full.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(full, k); it; ++it) {
      if (it.row() == it.col()) has_diagonal(k) = 1;
    }
  }
  for (Index k = 0; k < n; ++k) {
    if (has_diagonal(k) == 0) {
      throw InputError(source, "entries", "a diagonal entry for each of the " + std::to_string(n) + " rows",
                       "none for row " + std::to_string(k + 1) + " (truncated file?)");
    }
  }
  return full;
}

std::vector<DofLabel> read_calculix_dofs(const std::filesystem::path& file) {
  const std::string text = read_file(file);
  std::vector<DofLabel> out;
  std::set<std::pair<long, int>> seen;
  text::for_each_line(text, [&](std::size_t line, std::string_view l) {
    const std::string_view t = text::trim(l);
    if (t.empty()) return true;
    const std::size_t dot = t.find('.');
    const auto node = dot == std::string_view::npos ? std::nullopt : text::parse_int(t.substr(0, dot));
    const auto dir = node ? text::parse_int(t.substr(dot + 1)) : std::nullopt;
    if (!dir || *node < 0 || *dir < 1 || *dir > 6) {
      throw InputError(file.string(), at_line(line), "'node.direction' with direction 1..6 (CalculiX .dof)", quote(t));
    }
    if (!seen.insert({static_cast<long>(*node), static_cast<int>(*dir)}).second) {
      throw InputError(file.string(), at_line(line), "each node.direction once", quote(t) + " repeated");
    }
    out.push_back(DofLabel::nodal(static_cast<long>(*node), static_cast<Direction>(*dir)));
    return true;
  });
  if (out.empty()) throw InputError(file.string(), "rows", "'node.direction' rows", "none (empty file)");
  return out;
}

SparseModel read_calculix_model(const std::filesystem::path& sti_file, const std::filesystem::path& mas_file,
                                const std::filesystem::path& dof_file, const std::filesystem::path& nodes_inp,
                                const ProgressCallback& progress) {
  SparseModel model;
  model.dofs = read_calculix_dofs(dof_file);
  const auto n = static_cast<Index>(model.dofs.size());
  model.K = read_calculix_matrix(sti_file, n, progress);
  model.M = read_calculix_matrix(mas_file, n, progress);
  model.source = sti_file.string();
  if (!nodes_inp.empty()) {
    model.coordinates = read_inp_nodes(nodes_inp);
    for (const DofLabel& d : model.dofs) {
      if (model.coordinates.find(d.node) == model.coordinates.end()) {
        throw InputError(nodes_inp.string(), "node " + std::to_string(d.node), "a *NODE line for every node of " +
                                                                                  dof_file.filename().string(),
                         "none");
      }
    }
  }
  return model;
}

namespace {

void read_inp_nodes_into(const std::filesystem::path& file, std::map<long, Eigen::Vector3d>& nodes, int depth) {
  if (depth > 10) throw InputError(file.string(), "*INCLUDE", "at most 10 nested includes", "more");
  const std::string text = read_file(file);
  bool in_node_block = false;
  text::for_each_line(text, [&](std::size_t line, std::string_view l) {
    const std::string_view t = text::trim(l);
    if (t.empty() || t.rfind("**", 0) == 0) return true;
    if (t.front() == '*') {
      const std::string keyword = text::to_lower(std::string(t));
      const auto comma = keyword.find(',');
      std::string name = keyword.substr(0, comma);
      name.erase(std::remove(name.begin(), name.end(), ' '), name.end());
      in_node_block = name == "*node";
      if (name == "*include") {
        const auto pos = keyword.find("input=");
        if (pos == std::string::npos) throw InputError(file.string(), at_line(line), "*INCLUDE,INPUT=file", quote(t));
        // Keep the original spelling of the file name.
        std::string included(text::trim(t.substr(pos + 6)));
        if (!included.empty() && included.front() == '"') included = included.substr(1, included.find('"', 1) - 1);
        read_inp_nodes_into(file.parent_path() / included, nodes, depth + 1);
      }
      return true;
    }
    if (!in_node_block) return true;
    const auto tok = text::tokens(t, /*commas=*/true);
    const auto id = tok.empty() ? std::nullopt : text::parse_int(tok[0]);
    if (!id || tok.size() < 2 || tok.size() > 4) {
      throw InputError(file.string(), at_line(line), "a node line 'id, x[, y[, z]]'", quote(t));
    }
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t k = 1; k < tok.size(); ++k) {
      const auto v = text::parse_double(tok[k]);
      if (!v || !std::isfinite(*v)) throw InputError(file.string(), at_line(line), "finite coordinates", quote(t));
      p(static_cast<Index>(k - 1)) = *v;
    }
    nodes[static_cast<long>(*id)] = p;
    return true;
  });
}

}  // namespace

std::map<long, Eigen::Vector3d> read_inp_nodes(const std::filesystem::path& inp_file) {
  std::map<long, Eigen::Vector3d> nodes;
  read_inp_nodes_into(inp_file, nodes, 0);
  if (nodes.empty()) throw InputError(inp_file.string(), "*NODE", "node lines 'id, x, y, z'", "none");
  return nodes;
}

SparseMatrix read_matrix_market(const std::filesystem::path& file) {
  const std::string source = file.string();
  const std::string text = read_file(file);
  bool symmetric = false;
  bool have_banner = false, have_size = false;
  long long rows = 0, cols = 0, nnz = 0;
  std::vector<Triplet> triplets;
  text::for_each_line(text, [&](std::size_t line, std::string_view l) {
    if (!have_banner) {
      const auto t = text::tokens(l);
      if (t.size() != 5 || t[0] != "%%MatrixMarket") {
        throw InputError(source, "header", "'%%MatrixMarket matrix coordinate real symmetric|general'", quote(l));
      }
      const std::string object = text::to_lower(std::string(t[1])), format = text::to_lower(std::string(t[2])),
                        field = text::to_lower(std::string(t[3])), symmetry = text::to_lower(std::string(t[4]));
      if (object != "matrix" || format != "coordinate") {
        throw InputError(source, "header", "a 'matrix coordinate' file", std::string(t[1]) + " " + std::string(t[2]));
      }
      if (field != "real" && field != "integer" && field != "double") {
        throw InputError(source, "header", "a real or integer field", std::string(t[3]));
      }
      if (symmetry != "symmetric" && symmetry != "general") {
        throw InputError(source, "header", "symmetric or general storage", std::string(t[4]));
      }
      symmetric = symmetry == "symmetric";
      have_banner = true;
      return true;
    }
    const std::string_view t = text::trim(l);
    if (t.empty() || t.front() == '%') return true;
    const auto tok = text::tokens(t);
    if (!have_size) {
      const auto r = tok.size() == 3 ? text::parse_int(tok[0]) : std::nullopt;
      const auto c = r ? text::parse_int(tok[1]) : std::nullopt;
      const auto z = c ? text::parse_int(tok[2]) : std::nullopt;
      if (!z || *r < 1 || *c < 1 || *z < 0 || *r > 10000000 || *c > 10000000) {
        throw InputError(source, at_line(line), "the size line 'rows cols entries'", quote(t));
      }
      rows = *r;
      cols = *c;
      nnz = *z;
      if (symmetric && rows != cols) throw InputError(source, at_line(line), "a square symmetric matrix", quote(t));
      // Never more than the file can hold ("i j v\n" is at least 6 bytes): a declared count alone
      // does not allocate.
      triplets.reserve(static_cast<std::size_t>(std::min<long long>(nnz, static_cast<long long>(text.size() / 6 + 1))));
      have_size = true;
      return true;
    }
    const auto i = tok.size() == 3 ? text::parse_int(tok[0]) : std::nullopt;
    const auto j = i ? text::parse_int(tok[1]) : std::nullopt;
    const auto v = j ? text::parse_double(tok[2]) : std::nullopt;
    if (!v) throw InputError(source, at_line(line), "an entry 'row col value'", quote(t));
    if (*i < 1 || *j < 1 || *i > rows || *j > cols) {
      throw InputError(source, at_line(line), "indices within " + std::to_string(rows) + " x " + std::to_string(cols), quote(t));
    }
    if (!std::isfinite(*v)) throw InputError(source, at_line(line), "a finite value", quote(t));
    if (static_cast<long long>(triplets.size()) >= nnz) {
      throw InputError(source, at_line(line), std::to_string(nnz) + " entries (as the size line says)", "more");
    }
    triplets.emplace_back(static_cast<int>(*i - 1), static_cast<int>(*j - 1), *v);
    return true;
  });
  if (!have_banner) throw InputError(source, "header", "'%%MatrixMarket matrix coordinate ...'", "an empty file");
  if (!have_size) throw InputError(source, "size", "the size line 'rows cols entries'", "none (truncated file?)");
  if (static_cast<long long>(triplets.size()) != nnz) {
    throw InputError(source, "entries", std::to_string(nnz) + " entries (as the size line says)",
                     std::to_string(triplets.size()) + " (truncated file?)");
  }
  // The sparse matrix costs memory per row and column: its size is bounded by the entries the file
  // holds (a stiffness or mass matrix has at least its diagonal), not only by the size line.
  if (rows > 8 * nnz + 8 || cols > 8 * nnz + 8) {
    throw InputError(source, "size", "at most 8 rows and columns per entry (" + std::to_string(8 * nnz + 8) + " for " +
                     std::to_string(nnz) + " entries)", std::to_string(rows) + " x " + std::to_string(cols));
  }
  if (symmetric) return symmetric_from_triangle(triplets, static_cast<Index>(rows), source);
  SparseMatrix A(static_cast<Index>(rows), static_cast<Index>(cols));
  A.setFromTriplets(triplets.begin(), triplets.end());
  if (A.nonZeros() != static_cast<Index>(triplets.size())) {
    throw InputError(source, "entries", "each entry once", "a repeated entry");
  }
  return A;
}

void write_matrix_market(const std::filesystem::path& file, const Eigen::MatrixXd& A, const std::string& comment) {
  if (A.rows() != A.cols()) {
    throw InputError(file.string(), "matrix", "a square symmetric matrix", std::to_string(A.rows()) + " x " + std::to_string(A.cols()));
  }
  write_atomically(file, [&](std::ostream& out) {
    out << "%%MatrixMarket matrix coordinate real symmetric\n";
    if (!comment.empty()) {
      std::size_t start = 0;
      while (start <= comment.size()) {
        const std::size_t end = std::min(comment.find('\n', start), comment.size());
        out << "% " << comment.substr(start, end - start) << '\n';
        start = end + 1;
      }
    }
    Index nnz = 0;
    for (Index j = 0; j < A.cols(); ++j)
      for (Index i = j; i < A.rows(); ++i)
        if (A(i, j) != 0.0) ++nnz;
    out << A.rows() << ' ' << A.cols() << ' ' << nnz << '\n';
    for (Index j = 0; j < A.cols(); ++j)
      for (Index i = j; i < A.rows(); ++i)
        if (A(i, j) != 0.0) out << i + 1 << ' ' << j + 1 << ' ' << format_number(A(i, j), 17) << '\n';
  });
}

DofList read_dof_list(const std::filesystem::path& file) {
  const std::string text = read_file(file);
  DofList out;
  int expected_mode = 1;
  text::for_each_line(text, [&](std::size_t line, std::string_view l) {
    std::string_view t = text::trim(l);
    if (const auto hash = t.find('#'); hash != std::string_view::npos) t = text::trim(t.substr(0, hash));
    if (t.empty()) return true;
    const auto tok = text::tokens(t);
    if (text::to_lower(std::string(tok[0])) == "mode") {
      const auto k = tok.size() == 2 ? text::parse_int(tok[1]) : std::nullopt;
      if (!k || *k != expected_mode) {
        throw InputError(file.string(), at_line(line), "'MODE " + std::to_string(expected_mode) + "'", quote(t));
      }
      out.dofs.push_back(DofLabel::modal(expected_mode++));
      return true;
    }
    const auto node = text::parse_int(tok[0]);
    const auto dir = tok.size() >= 2 ? direction_from_string(std::string(tok[1])) : std::nullopt;
    if (!node || *node < 0 || !dir || (tok.size() != 2 && tok.size() != 5)) {
      throw InputError(file.string(), at_line(line), "'NODE LABEL [X Y Z]' or 'MODE k'", quote(t));
    }
    if (expected_mode > 1) throw InputError(file.string(), at_line(line), "nodal DOF before the modal ones", quote(t));
    out.dofs.push_back(DofLabel::nodal(static_cast<long>(*node), *dir));
    if (tok.size() == 5) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) {
        const auto v = text::parse_double(tok[static_cast<std::size_t>(k + 2)]);
        if (!v || !std::isfinite(*v)) throw InputError(file.string(), at_line(line), "finite coordinates X Y Z (m)", quote(t));
        p(k) = *v;
      }
      const auto [it, inserted] = out.coordinates.emplace(static_cast<long>(*node), p);
      if (!inserted && (it->second - p).norm() > 1e-12 * (1.0 + p.norm())) {
        throw InputError(file.string(), at_line(line), "the same coordinates as the node's earlier rows", quote(t));
      }
    }
    return true;
  });
  if (out.dofs.empty()) throw InputError(file.string(), "rows", "one row per DOF", "none");
  return out;
}

void write_dof_list(const std::filesystem::path& file, const SuperElement& se) {
  write_atomically(file, [&](std::ostream& out) {
    out << "# piezobench DOF list: one row per matrix row\n"
        << "# NODE LABEL X Y Z (nodal DOF, labels UX UY UZ ROTX ROTY ROTZ, coordinates in m) or MODE k\n";
    if (!se.source.empty()) out << "# from " << se.source << '\n';
    for (const DofLabel& d : se.dofs) {
      if (d.is_modal()) {
        out << "MODE " << d.mode << '\n';
        continue;
      }
      out << d.node << ' ' << ansys_label(d.direction);
      const auto it = se.coordinates.find(d.node);
      if (it != se.coordinates.end()) {
        out << ' ' << format_number(it->second.x(), 17) << ' ' << format_number(it->second.y(), 17) << ' ' << format_number(it->second.z(), 17);
      }
      out << '\n';
    }
  });
}

std::vector<std::filesystem::path> write_super_element(const std::filesystem::path& dir, const std::string& stem,
                                                       const SuperElement& se) {
  const auto k = dir / (stem + "_K.mtx");
  const auto m = dir / (stem + "_M.mtx");
  const auto d = dir / (stem + "_dofs.txt");
  const std::string comment = "piezobench super element" + (se.source.empty() ? std::string() : " from " + se.source) +
                              "\nDOF order: see " + d.filename().string();
  write_matrix_market(k, se.K, "stiffness (N/m, N, N m)\n" + comment);
  write_matrix_market(m, se.M, "mass (kg, kg m, kg m^2)\n" + comment);
  write_dof_list(d, se);
  return {k, m, d};
}

std::filesystem::path write_simscape(const std::filesystem::path& dir, const std::string& stem, const SuperElement& se) {
  const std::vector<long> nodes = se.nodes();
  // Every frame needs 6 consecutive DOF x y z rx ry rz.
  for (std::size_t f = 0; f < nodes.size(); ++f) {
    for (int k = 0; k < 6; ++k) {
      const auto row = static_cast<std::size_t>(6 * f + static_cast<std::size_t>(k));
      if (row >= se.dofs.size() || se.dofs[row].is_modal() || se.dofs[row].node != nodes[f] ||
          static_cast<int>(se.dofs[row].direction) != k + 1) {
        throw InputError(se.source, "dofs",
                         "6 DOF per node in the order x y z rx ry rz (Simscape frames; use rigid-body interface points)",
                         "node " + std::to_string(nodes[f]) + " does not have them at rows " + std::to_string(6 * f + 1) +
                             ".." + std::to_string(6 * f + 6));
      }
    }
    if (se.coordinates.find(nodes[f]) == se.coordinates.end()) {
      throw InputError(se.source, "node " + std::to_string(nodes[f]), "coordinates (the frame origin)", "none");
    }
  }
  const auto file = dir / (stem + "_simscape.m");
  const auto write_matrix = [](std::ostream& out, const char* name, const Eigen::MatrixXd& A) {
    out << name << " = [\n";
    for (Index i = 0; i < A.rows(); ++i) {
      for (Index j = 0; j < A.cols(); ++j) out << (j ? " " : "  ") << format_number(A(i, j), 17);
      out << '\n';
    }
    out << "];\n";
  };
  write_atomically(file, [&](std::ostream& out) {
    out << "% Reduced Order Flexible Solid data written by piezobench"
        << (se.source.empty() ? std::string() : " from " + se.source) << "\n"
        << "% frames: one per interface node, 6 DOF each (x y z rx ry rz), then " << se.modal_dofs()
        << " modal DOF. SI units.\n";
    out << "frame_nodes = [";
    for (std::size_t f = 0; f < nodes.size(); ++f) out << (f ? "; " : "") << nodes[f];
    out << "];\n";
    Eigen::MatrixXd origins(static_cast<Index>(nodes.size()), 3);
    for (std::size_t f = 0; f < nodes.size(); ++f) origins.row(static_cast<Index>(f)) = se.coordinates.at(nodes[f]).transpose();
    write_matrix(out, "origins", origins);
    write_matrix(out, "K", se.K);
    write_matrix(out, "M", se.M);
  });
  return file;
}

}  // namespace piezobench::fem
