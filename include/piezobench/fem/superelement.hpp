#pragma once
// Super elements: small dense structural models (stiffness K, mass M) whose first degrees of
// freedom belong to interface nodes and whose last ones are modal coordinates, as produced by a
// component-mode synthesis (Craig-Bampton: fixed-interface modes plus static constraint modes).
//
// Readers (each validates and throws InputError naming the file and the field):
//  - Ansys CMS text: K and M files of `[ i, j]: value` entries after a `MAT_K:` / `MAT_M:` header,
//    the Ansys listing of the master DOF (one `NODE LABEL` row per matrix row, labels UX UY UZ ROTX
//    ROTY ROTZ) and an Ansys node list (`NODE X Y Z ...`) for the coordinates.
//  - CalculiX matrix dumps of `*FREQUENCY,SOLVER=MATRIXSTORAGE` (.sti, .mas: upper triangle,
//    1-based `row col value`; .dof: `node.direction` per row), see matrix_io.hpp.
//  - Matrix Market (coordinate real symmetric or general) with a piezobench DOF list.
//
// Units: SI (N/m, N, m, kg, kg m^2); rotations in rad. Matrices are symmetric n x n.
#include <Eigen/Dense>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"

namespace piezobench::fem {

// The frequency [Hz] of an eigenvalue lambda = w^2 of K phi = w^2 M phi, signed:
// sign(lambda) sqrt|lambda| / 2 pi, so a negative value flags a negative eigenvalue.
[[nodiscard]] double eigenvalue_Hz(double lambda);

using Index = Eigen::Index;

// A nodal direction: translations x, y, z and rotations about x, y, z (CalculiX directions 1..6,
// Ansys labels UX UY UZ ROTX ROTY ROTZ).
enum class Direction { kX = 1, kY = 2, kZ = 3, kRx = 4, kRy = 5, kRz = 6 };
// "x", "y", "z", "rx", "ry", "rz".
[[nodiscard]] std::string to_string(Direction d);
// Accepts the to_string spellings, the Ansys labels (UX .. ROTZ) and the CalculiX numbers 1..6,
// case-insensitive; nullopt otherwise.
[[nodiscard]] std::optional<Direction> direction_from_string(const std::string& text);
// "UX" .. "ROTZ".
[[nodiscard]] std::string ansys_label(Direction d);
[[nodiscard]] inline bool is_rotation(Direction d) { return static_cast<int>(d) > 3; }

// The files a super element can be read from.
enum class SuperElementFormat { kAnsysText, kCalculix, kMatrixMarket };
// "ansys", "calculix", "matrix-market".
[[nodiscard]] std::string to_string(SuperElementFormat f);
[[nodiscard]] std::optional<SuperElementFormat> super_element_format_from_string(const std::string& text);
// Guesses the format from the file names and the first bytes of `k_file`: .sti/.mas/.dof ->
// CalculiX, .mtx or a "%%MatrixMarket" banner -> Matrix Market, otherwise Ansys text.
[[nodiscard]] SuperElementFormat detect_format(const std::filesystem::path& k_file);

// What one row/column of the matrices stands for: a nodal DOF, or a modal coordinate.
struct DofLabel {
  long node = -1;                        // node number (>= 0); -1 for a modal coordinate
  Direction direction = Direction::kX;   // nodal DOF only
  int mode = 0;                          // modal coordinate only: 1-based
  [[nodiscard]] bool is_modal() const { return node < 0; }
  static DofLabel nodal(long node, Direction d) { return DofLabel{node, d, 0}; }
  static DofLabel modal(int mode) { return DofLabel{-1, Direction::kX, mode}; }
  // "76423.UX" or "mode 3".
  [[nodiscard]] std::string to_string() const;
  friend bool operator==(const DofLabel&, const DofLabel&) = default;
};

struct SuperElement {
  Eigen::MatrixXd K;                              // n x n, symmetric
  Eigen::MatrixXd M;                              // n x n, symmetric positive definite
  std::vector<DofLabel> dofs;                     // n labels: nodal DOF first, then modal ones
  std::map<long, Eigen::Vector3d> coordinates;    // m; nodes without coordinates are absent
  std::string source;                             // file(s) it came from, for messages
  std::vector<std::string> warnings;              // things the user should know (precision, ...)

  [[nodiscard]] Index size() const { return K.rows(); }
  [[nodiscard]] Index modal_dofs() const;
  [[nodiscard]] Index nodal_dofs() const { return size() - modal_dofs(); }
  // Distinct nodes in order of first appearance.
  [[nodiscard]] std::vector<long> nodes() const;
  [[nodiscard]] bool has_node(long node) const;
  // Row of (node, d); nullopt when the element has no such DOF.
  [[nodiscard]] std::optional<Index> find(long node, Direction d) const;
  // Row of (node, d); InputError(source, field, ...) listing the nodes when absent.
  [[nodiscard]] Index index_of(long node, Direction d, const std::string& source, const std::string& field) const;

  // Throws InputError naming `source` and the field (K, M, dofs) for: sizes that differ, non-finite
  // entries, labels that repeat or do not match the matrix size, nodal DOF after modal ones,
  // asymmetric K or M (see ImportOptions::symmetry_tolerance), a mass matrix that is not
  // positive definite.
  void validate(double symmetry_tolerance = 1e-6) const;
};

struct ImportOptions {
  // Entries i, j of K (or M) are symmetric when |a_ij - a_ji| <= symmetry_tolerance * max(|a_ij|,
  // |a_ji|) or both are below 1e-12 * max|a| (round-off noise around zeros). Default 1e-6.
  double symmetry_tolerance = 1e-6;
  // Check the free-free rigid-body modes (see check_rigid_body_modes) and warn when spoiled.
  bool check_rigid_body_modes = true;
  // Dense readers refuse models larger than this (use craig_bampton.hpp for large FE models).
  Index max_dense_size = 5000;
  // InputError naming the field when a value is out of range.
  void validate() const;
};

// Ansys CMS text export. `master_file` lists the master DOF (Ansys `NLIST`/`MLIST` output: rows
// `NODE LABEL`); it may also contain the node list. `nlist_file` (optional) is the Ansys node
// list with coordinates; when empty, `out_NLIST.txt` beside `master_file` is used if it exists,
// else the node list inside `master_file`, if any. Matrix rows past the master DOF are modal.
[[nodiscard]] SuperElement read_ansys_super_element(const std::filesystem::path& k_file,
                                                    const std::filesystem::path& m_file,
                                                    const std::filesystem::path& master_file,
                                                    const std::filesystem::path& nlist_file = {},
                                                    const ImportOptions& options = {});

// CalculiX MATRIXSTORAGE dumps (dense; only for small models). `nodes_inp` (optional) is a
// CalculiX/Abaqus input file whose *NODE blocks give coordinates (*INCLUDE is followed).
[[nodiscard]] SuperElement read_calculix_super_element(const std::filesystem::path& sti_file,
                                                       const std::filesystem::path& mas_file,
                                                       const std::filesystem::path& dof_file,
                                                       const std::filesystem::path& nodes_inp = {},
                                                       const ImportOptions& options = {});

// Matrix Market K and M with a piezobench DOF list (see write_dof_list in matrix_io.hpp).
[[nodiscard]] SuperElement read_matrix_market_super_element(const std::filesystem::path& k_file,
                                                            const std::filesystem::path& m_file,
                                                            const std::filesystem::path& dof_list,
                                                            const ImportOptions& options = {});

// Any of the three, by `format`; for CalculiX, `k_file` and `m_file` are the .sti and .mas files
// and `nodes_file` the .dof file (coordinates from `coordinates_file`, a .inp); for Ansys,
// `coordinates_file` is the node list (see read_ansys_super_element).
[[nodiscard]] SuperElement read_super_element(SuperElementFormat format, const std::filesystem::path& k_file,
                                              const std::filesystem::path& m_file,
                                              const std::filesystem::path& nodes_file,
                                              const std::filesystem::path& coordinates_file = {},
                                              const ImportOptions& options = {});

// The six rigid-body motions of a free-free super element should be modes at 0 Hz. Rounded
// entries (the Ansys text keeps 4 significant digits) leave K with no exact null space, and the
// rigid-body modes come out at tens or hundreds of Hz.
struct RigidBodyCheck {
  bool performed = false;            // false: no coordinates for some nodes, or too large
  bool free_free = false;            // the 6 lowest modes are rigid-body motions (>= 90 % of M-norm)
  bool spoiled = false;              // free_free and their frequencies are not ~0
  Eigen::VectorXd lowest_modes_Hz;   // 6 lowest free-free modes (sign(lambda) sqrt|lambda|/2pi)
  Eigen::VectorXd rigid_fraction;    // share of each of them in the rigid-body subspace (M-norm)
  double first_flexible_Hz = 0.0;    // 7th free-free mode
  std::string message;               // the warning text when spoiled (else a short note)
};

constexpr auto describe(core::Type<RigidBodyCheck>) {
  using S = RigidBodyCheck;
  using namespace core::shown;
  return core::fields<S>("RigidBodyCheck", "are a super element's six free-free rigid-body modes at ~0 Hz",
      core::field("performed", &S::performed, kNone, "false: no coordinates for some nodes, or too large"),
      core::field("free_free", &S::free_free, kNone, "the 6 lowest modes are rigid-body motions (>= 90 % of M-norm)"),
      core::field("spoiled", &S::spoiled, kNone, "free_free and their frequencies are not ~0"),
      core::field("lowest_modes_Hz", &S::lowest_modes_Hz, kHertz, "6 lowest free-free modes, sign(lambda) sqrt|lambda| / 2 pi"),
      core::field("rigid_fraction", &S::rigid_fraction, kRatio, "share of each of them in the rigid-body subspace (M-norm)"),
      core::field("first_flexible_Hz", &S::first_flexible_Hz, kHertz, "7th free-free mode"),
      core::field("message", &S::message, kNone, "the warning text when spoiled (else a short note)"));
}
// Spoiled when max |f_1..6| > relative_threshold * f_7. Rigid-body shapes are built from the node
// coordinates (translations, and rotations about the centroid; modal coordinates zero, which is
// exact for Craig-Bampton super elements).
[[nodiscard]] RigidBodyCheck check_rigid_body_modes(const SuperElement& se, double relative_threshold = 1e-3);

}  // namespace piezobench::fem
