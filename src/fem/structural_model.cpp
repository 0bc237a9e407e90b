#include "piezobench/fem/structural_model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <set>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::fem {
namespace {

const char* const kSource = "model options";

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(sep, start);
    out.emplace_back(text::trim(std::string_view(text).substr(start, end == std::string::npos ? std::string::npos : end - start)));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

long parse_node(const std::string& token, const std::string& text, const std::string& field, const std::string& form) {
  const auto v = text::parse_int(token);
  if (!v || *v < 0) throw InputError("", field, form, "'" + text + "'");
  return static_cast<long>(*v);
}

Direction parse_direction(const std::string& token, const std::string& text, const std::string& field, const std::string& form) {
  const auto d = direction_from_string(token);
  if (!d) throw InputError("", field, form + " with DIR x|y|z|rx|ry|rz", "'" + text + "'");
  return *d;
}

double finite_number(const std::string& token, const std::string& text, const std::string& field, const std::string& form) {
  const auto v = text::parse_double(token);
  if (!v || !std::isfinite(*v)) throw InputError("", field, form, "'" + text + "'");
  return *v;
}

std::string node_dir(long node, Direction d) { return std::to_string(node) + ":" + to_string(d); }

}  // namespace

ForcePair ForcePair::parse(const std::string& text, const std::string& field) {
  const std::string form = "NODE_A:NODE_B:DIR or NODE:DIR";
  const auto p = split(text, ':');
  ForcePair f;
  if (p.size() == 3) {
    f.node_a = parse_node(p[0], text, field, form);
    f.node_b = parse_node(p[1], text, field, form);
    f.direction = parse_direction(p[2], text, field, form);
  } else if (p.size() == 2) {
    f.node_b = parse_node(p[0], text, field, form);
    f.direction = parse_direction(p[1], text, field, form);
  } else {
    throw InputError("", field, form, "'" + text + "'");
  }
  return f;
}

std::string ForcePair::to_string() const {
  return (node_a >= 0 ? std::to_string(node_a) + ":" : std::string()) + node_dir(node_b, direction);
}

DisplacementOutput DisplacementOutput::parse(const std::string& text, const std::string& field) {
  const std::string form = "NODE:DIR or NODE_A:NODE_B:DIR";
  const auto p = split(text, ':');
  DisplacementOutput o;
  if (p.size() == 2) {
    o.node_b = parse_node(p[0], text, field, form);
    o.direction = parse_direction(p[1], text, field, form);
  } else if (p.size() == 3) {
    o.node_a = parse_node(p[0], text, field, form);
    o.node_b = parse_node(p[1], text, field, form);
    o.direction = parse_direction(p[2], text, field, form);
  } else {
    throw InputError("", field, form, "'" + text + "'");
  }
  return o;
}

std::string DisplacementOutput::to_string() const {
  return (node_a >= 0 ? std::to_string(node_a) + ":" : std::string()) + node_dir(node_b, direction);
}

PointMass PointMass::parse(const std::string& text, const std::string& field) {
  const std::string form = "NODE:KG with KG >= 0";
  const auto p = split(text, ':');
  if (p.size() != 2) throw InputError("", field, form, "'" + text + "'");
  PointMass m;
  m.node = parse_node(p[0], text, field, form);
  m.mass = finite_number(p[1], text, field, form);
  if (m.mass < 0.0) throw InputError("", field, form, "'" + text + "'");
  return m;
}

std::string to_string(DampingKind k) {
  switch (k) {
    case DampingKind::kNone: return "none";
    case DampingKind::kModal: return "modal";
    case DampingKind::kRayleigh: return "rayleigh";
  }
  return "?";
}

std::optional<DampingKind> damping_kind_from_string(const std::string& text) {
  const std::string s = text::to_lower(text);
  if (s == "none") return DampingKind::kNone;
  if (s == "modal") return DampingKind::kModal;
  if (s == "rayleigh") return DampingKind::kRayleigh;
  return std::nullopt;
}

Damping Damping::parse(const std::string& text, const std::string& field) {
  const std::string form = "none, modal:ZETA or rayleigh:ALPHA:BETA (non-negative numbers)";
  const auto p = split(text, ':');
  const auto kind = damping_kind_from_string(p[0]);
  Damping d;
  if (!kind) throw InputError("", field, form, "'" + text + "'");
  d.kind = *kind;
  if (d.kind == DampingKind::kNone && p.size() == 1) return d;
  if (d.kind == DampingKind::kModal && p.size() == 2) {
    d.zeta = finite_number(p[1], text, field, form);
  } else if (d.kind == DampingKind::kRayleigh && p.size() == 3) {
    d.alpha = finite_number(p[1], text, field, form);
    d.beta = finite_number(p[2], text, field, form);
  } else {
    throw InputError("", field, form, "'" + text + "'");
  }
  if (d.zeta < 0.0 || d.alpha < 0.0 || d.beta < 0.0) throw InputError("", field, form, "'" + text + "'");
  return d;
}

void ModelOptions::validate(const SuperElement& se) const {
  std::set<long> fixed;
  for (std::size_t k = 0; k < fixed_nodes.size(); ++k) {
    const std::string field = "fixed_nodes[" + std::to_string(k) + "]";
    if (!se.has_node(fixed_nodes[k])) {
      (void)se.index_of(fixed_nodes[k], Direction::kX, kSource, field);  // throws, listing the nodes
      throw InputError(kSource, field, "a node of the super element", "node " + std::to_string(fixed_nodes[k]));
    }
    if (!fixed.insert(fixed_nodes[k]).second) {
      throw InputError(kSource, field, "each node fixed once", "node " + std::to_string(fixed_nodes[k]) + " again");
    }
  }
  for (std::size_t k = 0; k < guided.size(); ++k) {
    const std::string field = "guided[" + std::to_string(k) + "]";
    (void)se.index_of(guided[k].node, guided[k].direction, kSource, field);
    if (is_rotation(guided[k].direction)) throw InputError(kSource, field, "a guide along x, y or z", to_string(guided[k].direction));
    if (fixed.count(guided[k].node) != 0) throw InputError(kSource, field, "a node that is not fixed", "node " + std::to_string(guided[k].node));
  }
  for (std::size_t k = 0; k < masses.size(); ++k) {
    const std::string field = "masses[" + std::to_string(k) + "]";
    const PointMass& m = masses[k];
    if (!(std::isfinite(m.mass) && m.mass >= 0.0)) throw InputError(kSource, field, "a mass >= 0 kg", format_number(m.mass, 17));
    if (!(std::isfinite(m.rotary_inertia) && m.rotary_inertia >= 0.0)) {
      throw InputError(kSource, field, "a rotary inertia >= 0 kg m^2", format_number(m.rotary_inertia, 17));
    }
    for (Direction d : {Direction::kX, Direction::kY, Direction::kZ}) (void)se.index_of(m.node, d, kSource, field);
  }
  for (std::size_t k = 0; k < forces.size(); ++k) {
    const std::string field = "forces[" + std::to_string(k) + "] (" + forces[k].to_string() + ")";
    if (forces[k].node_a >= 0) (void)se.index_of(forces[k].node_a, forces[k].direction, kSource, field);
    (void)se.index_of(forces[k].node_b, forces[k].direction, kSource, field);
    if (forces[k].node_a == forces[k].node_b) throw InputError(kSource, field, "two different nodes", "the same node twice");
  }
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const std::string field = "outputs[" + std::to_string(k) + "] (" + outputs[k].to_string() + ")";
    if (outputs[k].node_a >= 0) (void)se.index_of(outputs[k].node_a, outputs[k].direction, kSource, field);
    (void)se.index_of(outputs[k].node_b, outputs[k].direction, kSource, field);
    if (outputs[k].node_a == outputs[k].node_b) throw InputError(kSource, field, "two different nodes", "the same node twice");
  }
  const Damping& d = damping;
  if (!(std::isfinite(d.zeta) && d.zeta >= 0.0)) throw InputError(kSource, "damping.zeta", "a damping ratio >= 0", format_number(d.zeta, 17));
  if (!(std::isfinite(d.alpha) && d.alpha >= 0.0)) throw InputError(kSource, "damping.alpha", "a value >= 0 (1/s)", format_number(d.alpha, 17));
  if (!(std::isfinite(d.beta) && d.beta >= 0.0)) throw InputError(kSource, "damping.beta", "a value >= 0 (s)", format_number(d.beta, 17));
}

StructuralModel assemble(const SuperElement& se, const ModelOptions& options) {
  options.validate(se);
  const Index n = se.size();
  Eigen::MatrixXd M = se.M;
  for (const PointMass& m : options.masses) {
    for (Direction d : {Direction::kX, Direction::kY, Direction::kZ}) M(*se.find(m.node, d), *se.find(m.node, d)) += m.mass;
    for (Direction d : {Direction::kRx, Direction::kRy, Direction::kRz}) {
      if (const auto i = se.find(m.node, d)) M(*i, *i) += m.rotary_inertia;
    }
  }
  const std::set<long> fixed(options.fixed_nodes.begin(), options.fixed_nodes.end());
  const auto held = [&](const DofLabel& d) {
    return std::any_of(options.guided.begin(), options.guided.end(),
                       [&](const Guide& g) { return g.node == d.node && g.direction != d.direction; });
  };
  StructuralModel out;
  std::vector<Index> position(static_cast<std::size_t>(n), -1);
  for (Index i = 0; i < n; ++i) {
    const DofLabel& d = se.dofs[static_cast<std::size_t>(i)];
    if (!d.is_modal() && (fixed.count(d.node) != 0 || held(d))) continue;
    position[static_cast<std::size_t>(i)] = static_cast<Index>(out.free_dofs.size());
    out.free_dofs.push_back(i);
  }
  const auto f = static_cast<Index>(out.free_dofs.size());
  if (f == 0) throw InputError(kSource, "fixed_nodes", "at least one free DOF", "every DOF fixed");
  out.K.resize(f, f);
  out.M.resize(f, f);
  for (Index j = 0; j < f; ++j) {
    for (Index i = 0; i < f; ++i) {
      out.K(i, j) = se.K(out.free_dofs[static_cast<std::size_t>(i)], out.free_dofs[static_cast<std::size_t>(j)]);
      out.M(i, j) = M(out.free_dofs[static_cast<std::size_t>(i)], out.free_dofs[static_cast<std::size_t>(j)]);
    }
  }
  // A load or a reading on a fixed DOF vanishes (the support takes it): its row is simply absent.
  const auto add = [&](Eigen::Ref<Eigen::VectorXd> v, long node, Direction d, double value) {
    const Index p = position[static_cast<std::size_t>(*se.find(node, d))];
    if (p >= 0) v(p) += value;
  };
  out.F = Eigen::MatrixXd::Zero(f, static_cast<Index>(options.forces.size()));
  for (std::size_t k = 0; k < options.forces.size(); ++k) {
    const ForcePair& fp = options.forces[k];
    add(out.F.col(static_cast<Index>(k)), fp.node_b, fp.direction, 1.0);
    if (fp.node_a >= 0) add(out.F.col(static_cast<Index>(k)), fp.node_a, fp.direction, -1.0);
    out.input_names.push_back((fp.node_a >= 0 ? "force " : "force on ") + fp.to_string());
  }
  Eigen::MatrixXd Tt = Eigen::MatrixXd::Zero(f, static_cast<Index>(options.outputs.size()));
  for (std::size_t k = 0; k < options.outputs.size(); ++k) {
    const DisplacementOutput& o = options.outputs[k];
    add(Tt.col(static_cast<Index>(k)), o.node_b, o.direction, 1.0);
    if (o.node_a >= 0) add(Tt.col(static_cast<Index>(k)), o.node_a, o.direction, -1.0);
    out.output_names.push_back(o.to_string());
  }
  out.T = Tt.transpose();
  switch (options.damping.kind) {
    case DampingKind::kNone: out.C = Eigen::MatrixXd::Zero(f, f); break;
    case DampingKind::kRayleigh: out.C = options.damping.alpha * out.M + options.damping.beta * out.K; break;
    case DampingKind::kModal: {
      // C = M Phi diag(2 zeta w_i) Phi^T M with mass-normalized Phi, so that Phi^T C Phi = diag(2 zeta w_i).
      const Modes m = modes(out.K, out.M);
      Eigen::VectorXd two_zeta_w(f);
      for (Index i = 0; i < f; ++i) {
        two_zeta_w(i) = 2.0 * options.damping.zeta * kTwoPi * std::max(0.0, m.frequencies_Hz(i));
      }
      const Eigen::MatrixXd MPhi = out.M * m.shapes;
      out.C = MPhi * two_zeta_w.asDiagonal() * MPhi.transpose();
      out.C = 0.5 * (out.C + out.C.transpose()).eval();
      break;
    }
  }
  return out;
}

Modes modes(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(K, M);
  if (es.info() != Eigen::Success) {
    throw NumericalError("modes (generalized symmetric eigenproblem)", "the mass matrix is not positive definite or the "
                         "eigensolver did not converge", false);
  }
  Modes out;
  out.frequencies_Hz = es.eigenvalues().unaryExpr([](double l) { return eigenvalue_Hz(l); });
  out.shapes = es.eigenvectors();
  return out;
}

lti::StateSpace to_state_space(const StructuralModel& model) {
  const Index f = model.size();
  const Eigen::LLT<Eigen::MatrixXd> llt(model.M);
  if (llt.info() != Eigen::Success) {
    throw NumericalError("to_state_space (Cholesky of M)", "the mass matrix of the constrained model is not positive definite",
                         false);
  }
  const Index ni = model.F.cols();
  const Index no = model.T.rows();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * f, 2 * f);
  A.topRightCorner(f, f).setIdentity();
  A.bottomLeftCorner(f, f) = -llt.solve(model.K);
  A.bottomRightCorner(f, f) = -llt.solve(model.C);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(2 * f, ni);
  B.bottomRows(f) = llt.solve(model.F);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(no, 2 * f);
  C.leftCols(f) = model.T;
  return lti::StateSpace(std::move(A), std::move(B), std::move(C), Eigen::MatrixXd::Zero(no, ni));
}

lti::FrequencyResponse frequency_response(const StructuralModel& model, const Eigen::VectorXd& omega) {
  lti::FrequencyResponse r;
  r.omega = omega;
  std::vector<Eigen::MatrixXcd>& H = r.H;
  H.reserve(static_cast<std::size_t>(omega.size()));
  const Eigen::MatrixXcd F = model.F.cast<std::complex<double>>();
  const Eigen::MatrixXcd T = model.T.cast<std::complex<double>>();
  Eigen::MatrixXcd Z(model.size(), model.size());
  for (Index k = 0; k < omega.size(); ++k) {
    const double w = omega(k);
    if (!std::isfinite(w)) throw InputError("", "omega[" + std::to_string(k) + "]", "a finite frequency", format_number(w, 17));
    Z.real() = model.K - w * w * model.M;
    Z.imag() = w * model.C;
    const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(Z);
    Eigen::MatrixXcd h = T * lu.solve(F);
    if (!h.allFinite()) {
      throw NumericalError("frequency_response (dense LU of K - w^2 M + j w C)",
                           "the dynamic stiffness is singular at " + format_number(w / kTwoPi, 17) +
                               " Hz (an undamped resonance, or a free body at 0 Hz)",
                           true);
    }
    H.push_back(std::move(h));
  }
  return r;
}

lti::FrequencyResponse frequency_response(const StructuralModel& model, const Modes& modes, const Eigen::VectorXd& omega) {
  const Index f = model.size();
  if (modes.shapes.rows() != f || modes.shapes.cols() != f || modes.frequencies_Hz.size() != f) {
    throw InputError("", "modes", "all " + std::to_string(f) + " modes of the model",
                     std::to_string(modes.shapes.rows()) + " x " + std::to_string(modes.shapes.cols()) + " shapes");
  }
  const Eigen::MatrixXd& phi = modes.shapes;
  Eigen::VectorXd c = Eigen::VectorXd::Zero(f);
  if (model.C.size() > 0 && model.C.cwiseAbs().maxCoeff() > 0.0) {
    Eigen::MatrixXd modal_c = phi.transpose() * model.C * phi;
    c = modal_c.diagonal();
    modal_c.diagonal().setZero();
    // Not diagonal in the modes (or not finite): the dense solution.
    if (!(modal_c.cwiseAbs().maxCoeff() <= kModalCouplingTolerance * c.cwiseAbs().maxCoeff())) return frequency_response(model, omega);
  }
  const Eigen::VectorXd lambda = modes.frequencies_Hz.unaryExpr([](double hz) {
    const double w = kTwoPi * hz;
    return std::copysign(w * w, hz);
  });
  // H(w) = sum_m (T phi_m)(phi_m^T F) / (lambda_m - w^2 + j w c_m). With the outer products as the
  // columns of P (outputs * inputs x modes), the responses at every frequency are two real matrix
  // products, P Re(1/d) and P Im(1/d), instead of a complex product per frequency.
  const Eigen::MatrixXd t_phi = model.T * phi;
  const Eigen::MatrixXd phi_f = phi.transpose() * model.F;
  const Index outputs = t_phi.rows(), inputs = phi_f.cols(), n = omega.size();
  Eigen::MatrixXd p(outputs * inputs, f);
  for (Index m = 0; m < f; ++m) {
    Eigen::Map<Eigen::MatrixXd>(p.col(m).data(), outputs, inputs) = t_phi.col(m) * phi_f.row(m);
  }
  Eigen::MatrixXd inv_re(f, n), inv_im(f, n);
  for (Index k = 0; k < n; ++k) {
    const double w = omega(k);
    if (!std::isfinite(w)) throw InputError("", "omega[" + std::to_string(k) + "]", "a finite frequency", format_number(w, 17));
    for (Index i = 0; i < f; ++i) {
      // 1 / (a + j b), scaled so that a^2 + b^2 neither overflows nor underflows.
      const double a = lambda(i) - w * w, b = w * c(i);
      const double scale = std::max(std::abs(a), std::abs(b));
      const double as = a / scale, bs = b / scale;
      const double d = (as * as + bs * bs) * scale;
      inv_re(i, k) = as / d;
      inv_im(i, k) = -bs / d;
    }
  }
  const Eigen::MatrixXd h_re = p * inv_re, h_im = p * inv_im;
  lti::FrequencyResponse r;
  r.omega = omega;
  r.H.reserve(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) {
    Eigen::MatrixXcd h(outputs, inputs);
    for (Index j = 0; j < inputs; ++j) {
      for (Index i = 0; i < outputs; ++i) h(i, j) = {h_re(i + j * outputs, k), h_im(i + j * outputs, k)};
    }
    if (!h.allFinite()) {
      throw NumericalError("frequency_response (modal superposition)",
                           "the dynamic stiffness is singular at " + format_number(omega(k) / kTwoPi, 17) +
                               " Hz (an undamped resonance, or a free body at 0 Hz)",
                           true);
    }
    r.H.push_back(std::move(h));
  }
  return r;
}

}  // namespace piezobench::fem
