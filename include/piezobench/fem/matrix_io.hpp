#pragma once
// Matrix files of finite element models: CalculiX MATRIXSTORAGE dumps, Matrix Market, node
// coordinates from CalculiX/Abaqus input decks, the piezobench DOF list and the Simscape-style
// export of a super element. Readers throw InputError naming the file and the field (a line
// number, an entry); writers write atomically (temporary file renamed over the target).
#include <Eigen/Sparse>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "piezobench/fem/superelement.hpp"

namespace piezobench::fem {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// A large sparse FE model (full symmetric storage: both triangles).
struct SparseModel {
  SparseMatrix K;                               // n x n, N/m
  SparseMatrix M;                               // n x n, kg
  std::vector<DofLabel> dofs;                   // n nodal labels
  std::map<long, Eigen::Vector3d> coordinates;  // m (may be empty)
  std::string source;
  [[nodiscard]] Index size() const { return K.rows(); }
};

// Progress of a long step: `step` names it, `fraction` in [0, 1].
using ProgressCallback = std::function<void(const std::string& step, double fraction)>;

// One symmetric matrix stored as its upper triangle, 1-based `row col value` lines (CalculiX
// .sti / .mas). `n` is the expected size (from the .dof file); an entry outside, a lower-triangle
// entry, a repeated entry, a malformed line or a non-finite value is an InputError naming
// the file and the line. Returns the full symmetric matrix.
[[nodiscard]] SparseMatrix read_calculix_matrix(const std::filesystem::path& file, Index n,
                                                const ProgressCallback& progress = {});
// The .dof file: one `node.direction` per matrix row (direction 1..6).
[[nodiscard]] std::vector<DofLabel> read_calculix_dofs(const std::filesystem::path& file);
// The .sti, .mas and .dof files together, with coordinates from `nodes_inp` when given.
// The stiffness and mass must have the same size as the .dof list.
[[nodiscard]] SparseModel read_calculix_model(const std::filesystem::path& sti_file,
                                              const std::filesystem::path& mas_file,
                                              const std::filesystem::path& dof_file,
                                              const std::filesystem::path& nodes_inp = {},
                                              const ProgressCallback& progress = {});
// *NODE blocks of a CalculiX/Abaqus deck (`id, x, y, z`), following *INCLUDE,INPUT=...
[[nodiscard]] std::map<long, Eigen::Vector3d> read_inp_nodes(const std::filesystem::path& inp_file);

// Matrix Market `matrix coordinate real|integer symmetric|general`. For symmetric files either
// triangle may be stored; the result has both. InputError for other kinds, a truncated file (fewer
// entries than announced), indices out of range, non-finite values.
[[nodiscard]] SparseMatrix read_matrix_market(const std::filesystem::path& file);
// Writes the lower triangle as `coordinate real symmetric` with 17 significant digits.
void write_matrix_market(const std::filesystem::path& file, const Eigen::MatrixXd& symmetric_matrix,
                         const std::string& comment = "");

// The piezobench DOF list: one line per matrix row, `NODE LABEL X Y Z` for nodal DOF (LABEL
// UX..ROTZ, coordinates in m, or `NODE LABEL` without coordinates) and `MODE k` for modal ones;
// `#` starts a comment.
struct DofList {
  std::vector<DofLabel> dofs;
  std::map<long, Eigen::Vector3d> coordinates;
};
[[nodiscard]] DofList read_dof_list(const std::filesystem::path& file);
void write_dof_list(const std::filesystem::path& file, const SuperElement& se);

// Writes `stem_K.mtx`, `stem_M.mtx` and `stem_dofs.txt` (our formats) into `dir`. Returns the
// files written.
std::vector<std::filesystem::path> write_super_element(const std::filesystem::path& dir, const std::string& stem,
                                                       const SuperElement& se);

// Simscape "Reduced Order Flexible Solid" form: frames (one per interface node, 6 DOF each in the
// order x y z rx ry rz, then the modal DOF), written as a MATLAB/Octave script `stem_simscape.m`
// defining K, M (n x n) and origins (frames x 3, m) plus `frame_nodes`. InputError when a node
// does not have all 6 DOF in that order, or lacks coordinates.
std::filesystem::path write_simscape(const std::filesystem::path& dir, const std::string& stem, const SuperElement& se);

}  // namespace piezobench::fem
