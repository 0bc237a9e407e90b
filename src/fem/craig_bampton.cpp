#include "piezobench/fem/craig_bampton.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Spectra/SymGEigsShiftSolver.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <set>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::fem {
namespace {

const char* const kCraigBamptonSource = "Craig-Bampton";
// CHOLMOD supernodal Cholesky; the subclass only exposes the factor's size.
class Factor : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  // CHOLMOD would print "not positive definite" on stderr; we report it as a NumericalError.
  Factor() { cholmod().print = 0; }
  [[nodiscard]] Index stored_entries() const {
    const cholmod_factor* L = m_cholmodFactor;
    if (L == nullptr) return 0;
    return L->is_super ? static_cast<Index>(L->xsize) : static_cast<Index>(L->nzmax);
  }
};

// Interior problems at most this large are solved densely (Spectra needs ncv <= n anyway).
constexpr Index kDenseInterior = 400;

void report(const ProgressCallback& progress, const std::string& step, double fraction) {
  if (progress) progress(step, std::clamp(fraction, 0.0, 1.0));
}

// Frees a sparse matrix's storage (assigning an empty matrix keeps the capacity).
void release_storage(SparseMatrix& A) { SparseMatrix().swap(A); }

// Gives the free pages of the heap back to the system before the next large allocation: the
// blocks freed so far (splitting, the constraint-mode solves) stay resident otherwise, and the
// peak memory of the reduction is the factor plus what is resident when the Lanczos basis grows.
void return_free_memory() {
#if defined(__GLIBC__)
  (void)malloc_trim(0);
#endif
}

// y = A x for a symmetric A stored as its lower triangle (compressed columns), as Spectra's B
// operator: one pass over the stored entries, each used for both triangles. Eigen's
// selfadjointView product does the same through row-block expressions and took a third of the
// Lanczos time; storing both triangles would cost 70 MB more at 150,000 DOF.
class LowerSymmetricProduct {
 public:
  using Scalar = double;
  explicit LowerSymmetricProduct(const SparseMatrix& lower) : A_(lower) {}
  [[nodiscard]] Index rows() const { return A_.rows(); }
  [[nodiscard]] Index cols() const { return A_.cols(); }
  void perform_op(const double* x, double* y) const {
    const Index n = A_.cols();
    const auto* outer = A_.outerIndexPtr();
    const auto* inner = A_.innerIndexPtr();
    const double* value = A_.valuePtr();
    std::fill(y, y + n, 0.0);
    for (Index j = 0; j < n; ++j) {
      const double xj = x[j];
      double yj = 0.0;
      auto p = outer[j];
      if (p < outer[j + 1] && inner[p] == j) yj += value[p++] * xj;  // the diagonal comes first
      for (; p < outer[j + 1]; ++p) {
        y[inner[p]] += value[p] * xj;
        yj += value[p] * x[inner[p]];
      }
      y[j] += yj;
    }
  }

 private:
  const SparseMatrix& A_;
};

// y = (K_ii - sigma M_ii)^-1 x through a CHOLMOD factor, as Spectra's shift-invert operator.
// K and M hold lower triangles (what CHOLMOD reads); K is used only for a nonzero shift (a zero
// shift uses the factor of K_ii as it is).
class ShiftInvertOp {
 public:
  using Scalar = double;
  ShiftInvertOp(const SparseMatrix& K, const SparseMatrix& M, const Factor& k_factor, const ProgressCallback& progress)
      : K_(K), M_(M), k_factor_(k_factor), progress_(progress) {}

  [[nodiscard]] Index rows() const { return M_.rows(); }
  [[nodiscard]] Index cols() const { return M_.cols(); }

  void set_shift(double sigma) {
    if (sigma == 0.0) {
      factor_ = &k_factor_;
      return;
    }
    report(progress_, "factorizing K_ii - sigma M_ii", 0.0);
    shifted_ = std::make_unique<Factor>();
    const SparseMatrix A = K_ - sigma * M_;
    shifted_->compute(A);
    if (shifted_->info() != Eigen::Success) {
      throw NumericalError("Craig-Bampton (CHOLMOD factorization of K_ii - sigma M_ii)",
                           "not positive definite for the shift " + format_number(sigma, 17) + " (rad/s)^2", true);
    }
    factor_ = shifted_.get();
  }

  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = factor_->solve(x);
    ++operations_;
    if (progress_ && operations_ % 20 == 0) {
      // The number of solves is not known in advance; Lanczos typically needs two to three bases.
      report(progress_, "fixed-interface modes (" + std::to_string(operations_) + " solves)",
             static_cast<double>(operations_) / static_cast<double>(operations_ + 100));
    }
  }
  [[nodiscard]] Index operations() const { return operations_; }

 private:
  const SparseMatrix& K_;
  const SparseMatrix& M_;
  const Factor& k_factor_;
  const ProgressCallback& progress_;
  const Factor* factor_ = nullptr;
  std::unique_ptr<Factor> shifted_;
  mutable Index operations_ = 0;
};

struct Partition {
  std::vector<DofLabel> labels;      // retained DOF labels of the super element
  std::vector<Index> boundary;       // model rows of the retained DOF (same order)
  std::vector<Index> interior;       // model rows of the interior DOF (ascending)
  std::vector<long> point_nodes;     // node numbering each interface point
};

Partition partition(const SparseModel& model, const std::vector<InterfacePoint>& interface) {
  std::map<std::pair<long, int>, Index> row_of;
  for (std::size_t i = 0; i < model.dofs.size(); ++i) {
    row_of[{model.dofs[i].node, static_cast<int>(model.dofs[i].direction)}] = static_cast<Index>(i);
  }
  const auto find = [&](long node, int dir) -> std::optional<Index> {
    const auto it = row_of.find({node, dir});
    if (it == row_of.end()) return std::nullopt;
    return it->second;
  };
  Partition p;
  std::vector<char> retained(static_cast<std::size_t>(model.size()), 0);
  const auto keep = [&](Index row, DofLabel label, const std::string& field) {
    if (retained[static_cast<std::size_t>(row)] != 0) {
      throw InputError(kCraigBamptonSource, field, "interface points that share no DOF", "DOF " + model.dofs[static_cast<std::size_t>(row)].to_string() + " twice");
    }
    retained[static_cast<std::size_t>(row)] = 1;
    p.boundary.push_back(row);
    p.labels.push_back(label);
  };
  if (interface.empty()) throw InputError(kCraigBamptonSource, "interface", "at least one interface point", "none");
  std::set<long> names;
  for (std::size_t k = 0; k < interface.size(); ++k) {
    const InterfacePoint& ip = interface[k];
    const std::string field = "interface[" + std::to_string(k) + "]";
    if (!names.insert(ip.node).second) throw InputError(kCraigBamptonSource, field, "each interface node once", "node " + std::to_string(ip.node) + " again");
    p.point_nodes.push_back(ip.node);
    if (ip.rot_node < 0) {
      bool any = false;
      for (int d = 1; d <= 6; ++d) {
        if (const auto row = find(ip.node, d)) {
          keep(*row, DofLabel::nodal(ip.node, static_cast<Direction>(d)), field);
          any = true;
        }
      }
      if (!any) throw InputError(model.source, field, "a node of the model (in the .dof list)", "node " + std::to_string(ip.node));
      continue;
    }
    for (int d = 1; d <= 3; ++d) {
      const auto t = find(ip.node, d);
      if (!t) {
        throw InputError(model.source, field, "a *RIGID BODY REF NODE with translations 1..3 in the model",
                         "node " + std::to_string(ip.node) + " lacks direction " + std::to_string(d));
      }
      keep(*t, DofLabel::nodal(ip.node, static_cast<Direction>(d)), field);
    }
    for (int d = 1; d <= 3; ++d) {
      const auto r = find(ip.rot_node, d);
      if (!r) {
        throw InputError(model.source, field, "a *RIGID BODY ROT NODE with translations 1..3 in the model",
                         "node " + std::to_string(ip.rot_node) + " lacks direction " + std::to_string(d));
      }
      if (names.count(ip.rot_node) != 0) {
        throw InputError(kCraigBamptonSource, field, "a ROT NODE that is not an interface node", "node " + std::to_string(ip.rot_node));
      }
      keep(*r, DofLabel::nodal(ip.node, static_cast<Direction>(d + 3)), field);
    }
  }
  for (Index i = 0; i < model.size(); ++i) {
    if (retained[static_cast<std::size_t>(i)] == 0) p.interior.push_back(i);
  }
  return p;
}

// Blocks of a symmetric sparse matrix for the partition: A_ii (sparse, its lower triangle only),
// A_ib (sparse), A_bb (dense).
struct Blocks {
  SparseMatrix ii, ib;
  Eigen::MatrixXd bb;
};

Blocks split(const SparseMatrix& A, const Partition& p) {
  const Index n = A.rows();
  std::vector<Index> local(static_cast<std::size_t>(n));
  std::vector<char> is_b(static_cast<std::size_t>(n), 0);
  for (std::size_t k = 0; k < p.boundary.size(); ++k) {
    local[static_cast<std::size_t>(p.boundary[k])] = static_cast<Index>(k);
    is_b[static_cast<std::size_t>(p.boundary[k])] = 1;
  }
  for (std::size_t k = 0; k < p.interior.size(); ++k) local[static_cast<std::size_t>(p.interior[k])] = static_cast<Index>(k);
  const auto ni = static_cast<Index>(p.interior.size());
  const auto nb = static_cast<Index>(p.boundary.size());
  Blocks out;
  out.bb = Eigen::MatrixXd::Zero(nb, nb);
  std::vector<Eigen::Triplet<double, int>> tib;
  // A_ii keeps the column structure of A (interior columns in ascending order): fill it directly.
  SparseMatrix ii(ni, ni);
  Eigen::VectorXi counts = Eigen::VectorXi::Zero(ni);
  for (Index c = 0; c < n; ++c) {
    if (is_b[static_cast<std::size_t>(c)] != 0) continue;
    int count = 0;
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      count += is_b[static_cast<std::size_t>(it.row())] == 0 && it.row() >= c ? 1 : 0;
    }
    counts(local[static_cast<std::size_t>(c)]) = count;
  }
  ii.reserve(counts);
  for (Index c = 0; c < n; ++c) {
    const Index lc = local[static_cast<std::size_t>(c)];
    const bool cb = is_b[static_cast<std::size_t>(c)] != 0;
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      const Index r = it.row();
      const Index lr = local[static_cast<std::size_t>(r)];
      const bool rb = is_b[static_cast<std::size_t>(r)] != 0;
      if (!rb && !cb) {
        // Interior rows keep their order in local numbering, so r >= c is lr >= lc.
        if (r >= c) ii.insert(lr, lc) = it.value();
      } else if (!rb && cb) {
        tib.emplace_back(static_cast<int>(lr), static_cast<int>(lc), it.value());
      } else if (rb && cb) {
        out.bb(lr, lc) = it.value();
      }
    }
  }
  ii.makeCompressed();
  out.ii = std::move(ii);
  out.ib.resize(ni, nb);
  out.ib.setFromTriplets(tib.begin(), tib.end());
  return out;
}

}  // namespace

InterfacePoint InterfacePoint::parse(const std::string& text, const std::string& field) {
  const std::string form = "NODE or REF_NODE:ROT_NODE";
  InterfacePoint p;
  const auto colon = text.find(':');
  const auto node = text::parse_int(std::string_view(text).substr(0, colon));
  if (!node || *node < 0) throw InputError("", field, form, "'" + text + "'");
  p.node = static_cast<long>(*node);
  if (colon != std::string::npos) {
    const auto rot = text::parse_int(std::string_view(text).substr(colon + 1));
    if (!rot || *rot < 0 || *rot == *node) throw InputError("", field, form, "'" + text + "'");
    p.rot_node = static_cast<long>(*rot);
  }
  return p;
}

void CraigBamptonOptions::validate() const {
  if (modes < 0) throw InputError("Craig-Bampton options", "modes", "a number of modes >= 0", std::to_string(modes));
  if (!(std::isfinite(shift) && shift <= 0.0)) {
    throw InputError("Craig-Bampton options", "shift", "a finite shift <= 0 (rad/s)^2", format_number(shift, 17));
  }
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    throw InputError("Craig-Bampton options", "tolerance", "a value in (0, 1)", format_number(tolerance, 17));
  }
  if (max_iterations < 1) throw InputError("Craig-Bampton options", "max_iterations", "a value >= 1", std::to_string(max_iterations));
  if (ncv < 0) throw InputError("Craig-Bampton options", "ncv", "0 (automatic) or a basis size", std::to_string(ncv));
}

namespace {

void check_model_sizes(const SparseModel& model) {
  if (model.K.rows() != model.K.cols() || model.M.rows() != model.K.rows() || model.M.cols() != model.K.cols() ||
      static_cast<Index>(model.dofs.size()) != model.K.rows()) {
    throw InputError(model.source, "size", "K, M and the DOF list of the same size",
                     std::to_string(model.K.rows()) + ", " + std::to_string(model.M.rows()) + " and " + std::to_string(model.dofs.size()));
  }
}

void factorize_interior(Factor& factor, const Blocks& k, const ProgressCallback& progress, CraigBamptonResult& out) {
  report(progress, "factorizing K_ii (CHOLMOD)", 0.0);
  factor.compute(k.ii);
  if (factor.info() != Eigen::Success) {
    throw NumericalError("Craig-Bampton (CHOLMOD Cholesky of K_ii)",
                         "K_ii is not positive definite: the interior is not held by the interface DOF (retain more "
                         "DOF, e.g. a whole interface face)",
                         false);
  }
  out.factor_nonzeros = factor.stored_entries();
  report(progress, "factorizing K_ii (CHOLMOD)", 1.0);
}

// Static constraint modes Psi = -K_ii^-1 K_ib.
Eigen::MatrixXd constraint_modes(Factor& factor, const Blocks& k, const ProgressCallback& progress) {
  report(progress, "constraint modes", 0.0);
  Eigen::MatrixXd Psi = -factor.solve(Eigen::MatrixXd(k.ib));
  if (factor.info() != Eigen::Success || !Psi.allFinite()) {
    throw NumericalError("Craig-Bampton (constraint modes)", "the solve with the factor of K_ii failed", false);
  }
  report(progress, "constraint modes", 1.0);
  return Psi;
}

// The fixed-interface modes: eigenvalues (rad^2/s^2) and mode shapes of the interior.
struct FixedInterfaceModes {
  Eigen::VectorXd lambda;
  Eigen::MatrixXd Phi;
};

// Small interiors: the dense generalized eigenproblem (the solver reads the lower triangles only).
void dense_fixed_interface_modes(const Blocks& k, const Blocks& m, Index nm, FixedInterfaceModes& modes) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(k.ii), Eigen::MatrixXd(m.ii));
  if (es.info() != Eigen::Success) {
    throw NumericalError("Craig-Bampton (dense fixed-interface eigenproblem)", "M_ii is not positive definite", false);
  }
  modes.lambda = es.eigenvalues().head(nm);
  modes.Phi = es.eigenvectors().leftCols(nm);
}

// Large interiors: Spectra's shift-invert Lanczos with the factor of K_ii, then the modes in
// ascending order, the columns swapped in place (no second n x N matrix).
void lanczos_fixed_interface_modes(const Blocks& k, const Blocks& m, const Factor& factor, const CraigBamptonOptions& options,
                                   Index ni, FixedInterfaceModes& modes, CraigBamptonResult& out) {
  const Index nm = options.modes;
  ShiftInvertOp op(k.ii, m.ii, factor, options.progress);
  LowerSymmetricProduct bop(m.ii);
  const Index ncv = std::min<Index>(ni, options.ncv > 0 ? std::max<Index>(options.ncv, nm + 1) : std::max<Index>(2 * nm + 1, nm + 20));
  Spectra::SymGEigsShiftSolver<ShiftInvertOp, LowerSymmetricProduct, Spectra::GEigsMode::ShiftInvert> eigs(
      op, bop, nm, ncv, options.shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, options.max_iterations, options.tolerance, Spectra::SortRule::SmallestAlge);
  out.eigensolver_iterations = eigs.num_iterations();
  out.eigensolver_operations = op.operations();
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw NumericalError("Craig-Bampton (Spectra shift-invert Lanczos)",
                         "the " + std::to_string(nm) + " fixed-interface modes did not converge in " +
                             std::to_string(options.max_iterations) + " restarts (ncv " + std::to_string(ncv) + ")",
                         true);
  }
  modes.lambda = eigs.eigenvalues();
  modes.Phi = eigs.eigenvectors();
  for (Index i = 0; i < nm; ++i) {
    Index smallest = i;
    for (Index j = i + 1; j < nm; ++j) smallest = modes.lambda(j) < modes.lambda(smallest) ? j : smallest;
    std::swap(modes.lambda(i), modes.lambda(smallest));
    modes.Phi.col(i).swap(modes.Phi.col(smallest));
  }
}

// The reduced K and M over the interface DOF then the modal DOF, symmetrized.
void reduced_matrices(const Blocks& k, const Blocks& m, const Eigen::MatrixXd& Psi, const FixedInterfaceModes& modes, Index nb, Index nm,
                      SuperElement& se) {
  const Index n = nb + nm;
  se.K = Eigen::MatrixXd::Zero(n, n);
  se.M = Eigen::MatrixXd::Zero(n, n);
  se.K.topLeftCorner(nb, nb) = k.bb + k.ib.transpose() * Psi;
  const Eigen::MatrixXd MiiPsi = m.ii.selfadjointView<Eigen::Lower>() * Psi;
  const Eigen::MatrixXd Mib = Eigen::MatrixXd(m.ib);
  const Eigen::MatrixXd MibtPsi = Mib.transpose() * Psi;
  se.M.topLeftCorner(nb, nb) = m.bb + MibtPsi + MibtPsi.transpose() + Psi.transpose() * MiiPsi;
  if (nm > 0) {
    se.K.bottomRightCorner(nm, nm) = modes.lambda.asDiagonal();
    se.M.bottomRightCorner(nm, nm).setIdentity();
    const Eigen::MatrixXd Mbq = (Mib + MiiPsi).transpose() * modes.Phi;
    se.M.topRightCorner(nb, nm) = Mbq;
    se.M.bottomLeftCorner(nm, nb) = Mbq.transpose();
  }
  se.K = 0.5 * (se.K + se.K.transpose()).eval();
  se.M = 0.5 * (se.M + se.M.transpose()).eval();
}

// The super element's labels, coordinates and source; validated and its rigid-body modes checked.
void finish_super_element(const SparseModel& model, const Partition& p, Index nb, Index nm, SuperElement& se) {
  se.dofs = p.labels;
  for (Index i = 0; i < nm; ++i) se.dofs.push_back(DofLabel::modal(static_cast<int>(i + 1)));
  for (long node : p.point_nodes) {
    const auto it = model.coordinates.find(node);
    if (it != model.coordinates.end()) se.coordinates[node] = it->second;
  }
  se.source = model.source + " (Craig-Bampton: " + std::to_string(nb) + " interface DOF, " + std::to_string(nm) + " modes)";
}

void check_super_element(SuperElement& se) {
  try {
    se.validate();
  } catch (const InputError& e) {
    throw NumericalError("Craig-Bampton (reduced matrices)", e.what(), false);
  }
  const RigidBodyCheck check = check_rigid_body_modes(se);
  if (check.spoiled) se.warnings.push_back(check.message);
}

// craig_bampton; with `release` (the same object as `model`), its K and M are freed as soon as
// their blocks are copied.
CraigBamptonResult reduce(const SparseModel& model, SparseModel* release, const std::vector<InterfacePoint>& interface,
                          const CraigBamptonOptions& options) {
  options.validate();
  const auto start = std::chrono::steady_clock::now();
  check_model_sizes(model);
  const Partition p = partition(model, interface);
  const auto ni = static_cast<Index>(p.interior.size());
  const auto nb = static_cast<Index>(p.boundary.size());
  const Index nm = options.modes;
  if (ni == 0) throw InputError(kCraigBamptonSource, "interface", "fewer retained DOF than the model has", "every DOF retained");
  if (nm >= ni) {
    throw InputError(kCraigBamptonSource, "modes", "fewer modes than interior DOF (" + std::to_string(ni) + ")", std::to_string(nm));
  }
  CraigBamptonResult out;
  out.interior_dofs = ni;
  out.interface_dofs = nb;

  // Memory: at 150,000 DOF the factor of K_ii takes 0.77 GB, K and M 0.14 GB each (both
  // triangles), K_ii and M_ii half as much (one triangle). K and M are freed once split when the
  // caller gives them up, K_ii once factored (unless a nonzero shift needs it again).
  report(options.progress, "partitioning", 0.0);
  Blocks k = split(model.K, p);
  if (release != nullptr) release_storage(release->K);
  Blocks m = split(model.M, p);
  if (release != nullptr) release_storage(release->M);
  return_free_memory();
  Factor factor;
  factorize_interior(factor, k, options.progress, out);
  const Eigen::MatrixXd Psi = constraint_modes(factor, k, options.progress);
  const bool dense_interior = ni <= kDenseInterior;
  if (options.shift == 0.0 && !dense_interior) release_storage(k.ii);
  return_free_memory();

  FixedInterfaceModes modes;
  modes.lambda.resize(nm);
  if (nm > 0) {
    report(options.progress, "fixed-interface modes", 0.0);
    if (dense_interior) {
      dense_fixed_interface_modes(k, m, nm, modes);
    } else {
      lanczos_fixed_interface_modes(k, m, factor, options, ni, modes, out);
    }
    // Mass-normalize explicitly (whatever the solver's convention).
    const Eigen::MatrixXd MPhi = m.ii.selfadjointView<Eigen::Lower>() * modes.Phi;
    for (Index i = 0; i < nm; ++i) modes.Phi.col(i) /= std::sqrt(modes.Phi.col(i).dot(MPhi.col(i)));
    report(options.progress, "fixed-interface modes", 1.0);
  }

  report(options.progress, "reduced matrices", 0.0);
  reduced_matrices(k, m, Psi, modes, nb, nm, out.reduced);
  finish_super_element(model, p, nb, nm, out.reduced);
  out.fixed_interface_Hz = modes.lambda.unaryExpr([](double l) { return eigenvalue_Hz(l); });
  check_super_element(out.reduced);
  report(options.progress, "reduced matrices", 1.0);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

CraigBamptonResult craig_bampton(const SparseModel& model, const std::vector<InterfacePoint>& interface,
                                 const CraigBamptonOptions& options) {
  return reduce(model, nullptr, interface, options);
}

CraigBamptonResult craig_bampton(SparseModel&& model, const std::vector<InterfacePoint>& interface,
                                 const CraigBamptonOptions& options) {
  return reduce(model, &model, interface, options);
}

}  // namespace piezobench::fem
