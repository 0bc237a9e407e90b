#include "plant.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/discretize.hpp"

namespace piezobench::bench::detail {

lti::Vector balancing_scales(const lti::Matrix& m) {
  // B. N. Parlett and C. Reinsch, "Balancing a matrix for calculation of eigenvalues and
  // eigenvectors", Numer. Math. 13, 1969 (as LAPACK dgebal, without the permutation).
  const Eigen::Index n = m.rows();
  lti::Vector d = lti::Vector::Ones(n);
  lti::Matrix a = m;
  bool converged = false;
  for (int sweep = 0; sweep < 100 && !converged; ++sweep) {
    converged = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c = a.col(i).cwiseAbs().sum() - std::abs(a(i, i));
      const double r = a.row(i).cwiseAbs().sum() - std::abs(a(i, i));
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0, cc = c;
      const double target = r;
      while (cc < target / 2.0) cc *= 4.0, f *= 2.0;
      while (cc >= target * 2.0) cc /= 4.0, f /= 2.0;
      if ((c * f * f + r) / f < 0.95 * (c + r)) {  // scaling column i by f and row i by 1/f pays off
        converged = false;
        d(i) *= f;
        a.col(i) *= f;
        a.row(i) /= f;
      }
    }
  }
  return d;
}

double blocked_capacitance(const apa::TwoDofParams& p, double in_situ) {
  const double k_around = p.ke + p.ka * p.k1 / (p.ka + p.k1);
  return in_situ * k_around / (k_around + p.gs * p.gs * in_situ);
}

double actuator_blocked_capacitance(const apa::TwoDofParams& p, double in_situ) {
  const double cab = in_situ - p.ga * p.ga / (p.ka + p.ke * p.k1 / (p.ke + p.k1));
  if (!(cab > 0.0)) {
    throw InputError(
        "unit model", "capacitance_actuator",
        fmt::format("an in-situ capacitance above ga^2 / (ka + ke k1 / (ke + k1)) = {} F (open-circuit stacks)",
                    format_number(in_situ - cab)),
        fmt::format("{} F", format_number_exact(in_situ)));
  }
  return cab;
}

ContinuousPlant two_dof_plant(const apa::TwoDofParams& p, const Electrics& e) {
  p.validate("unit model");
  const double cb = blocked_capacitance(p, e.capacitance_sensor);
  const double alpha = p.gs * cb;
  const double ke_sc = p.ke - p.gs * alpha;
  if (!(ke_sc > 0.0)) {
    throw InputError(
        "unit model", "gs",
        fmt::format("a sensor stack whose short-circuit stiffness ke - gs^2 C_b stays positive (ke = {} N/m)",
                    format_number_exact(p.ke)),
        fmt::format("gs = {} V/m with C_b = {} F", format_number_exact(p.gs), format_number_exact(cb)));
  }
  const double den = p.ca + p.ce;
  const double wa = e.amplifier_bandwidth;
  // s: Vs += kappa dVa/dt (the drive current; none when the stacks are disconnected)
  const double kappa = e.actuator_open_circuit ? 0.0 : -e.ground_resistance * e.capacitance_actuator;

  ContinuousPlant c;
  c.A = lti::Matrix::Zero(6, 6);
  c.B = lti::Matrix::Zero(6, kInputs);
  c.C = lti::Matrix::Zero(kOutputs, 6);
  c.D = lti::Matrix::Zero(kOutputs, kInputs);
  // Node: (ca + ce) xn' = ga Va + F - ka xn + ke_sc (x - xn) + ce x' + alpha V.
  Eigen::RowVectorXd xnd = Eigen::RowVectorXd::Zero(6);
  xnd.head(5) << p.ga / den, ke_sc / den, p.ce / den, -(p.ka + ke_sc) / den, alpha / den;
  const double xnd_force = 1.0 / den;
  // Sensor tension T = ke_sc (x - xn) + ce (x' - xn') + alpha V.
  Eigen::RowVectorXd tension = Eigen::RowVectorXd::Zero(6);
  tension.head(5) << 0.0, ke_sc, p.ce, -ke_sc, alpha;
  tension -= p.ce * xnd;
  const double tension_force = -p.ce * xnd_force;

  if (e.actuator_open_circuit) {
    // C_ab Va' = -ga xn' - Va / R_ins: the charge stays (the insulation's leak, hours, keeps A
    // regular), so Va follows the node.
    const double cab = actuator_blocked_capacitance(p, e.capacitance_actuator);
    c.A.row(0) = (-p.ga / cab) * xnd;
    c.A(0, 0) -= 1.0 / (kStackInsulationResistance * cab);
    c.B(0, kInForce) = (-p.ga / cab) * xnd_force;
  } else {
    c.A(0, 0) = -wa;
    c.B(0, kInVa) = wa;
  }
  c.A(1, 2) = 1.0;
  // m x'' = -k1 x - c1 x' - T + F_mass
  c.A.row(2) = -tension / p.m;
  c.A(2, 1) -= p.k1 / p.m;
  c.A(2, 2) -= p.c1 / p.m;
  c.B(2, kInForce) = -tension_force / p.m;
  c.B(2, kInMass) = 1.0 / p.m;
  c.A.row(3) = xnd;
  c.B(3, kInForce) = xnd_force;
  // C_b V' = alpha (x' - xn') - V / R  ->  V' = gs (x' - xn') - V / (R C_b)
  c.A.row(4) = -p.gs * xnd;
  c.A(4, 2) += p.gs;
  c.A(4, 4) -= 1.0 / (e.hpf_resistance * cb);
  c.B(4, kInForce) = -p.gs * xnd_force;
  // What the ADC sees: V + kappa dVa/dt = V + kappa wa (va - Va), through the anti-aliasing
  // low-pass y' = w_aa (V + kappa wa (va - Va) - y).
  const double waa = e.adc_bandwidth;
  c.A(5, 4) = waa;
  c.A(5, 0) = -waa * kappa * wa;
  c.A(5, 5) = -waa;
  c.B(5, kInVa) = waa * kappa * wa;

  c.C(kOutVa, 0) = 1.0;
  c.C(kOutDe, 1) = 1.0;
  c.C(kOutVs, 5) = 1.0;
  c.C(kOutLoad, 3) = p.ka;
  return c;
}

namespace {

// expm([A B; 0 0] h) -> (Phi(h), Gamma(h)), computed on the balanced matrix: the bench's states
// span ten decades (volts, micrometres, metres per second), and the exponential is only accurate
// relative to the norm of its argument, which would leave the small entries of Gamma with
// relative errors of 1e-4 and more. The balancing is exact (powers of two).
std::pair<lti::Matrix, lti::Matrix> hold(const ContinuousPlant& p, double h) {
  const Eigen::Index n = p.states();
  const Eigen::Index m = p.B.cols();
  lti::Matrix aug = lti::Matrix::Zero(n + m, n + m);
  aug.topLeftCorner(n, n) = p.A * h;
  aug.topRightCorner(n, m) = p.B * h;
  const lti::Vector d = balancing_scales(aug);
  const lti::Matrix balanced = d.cwiseInverse().asDiagonal() * aug * d.asDiagonal();
  const lti::Matrix e = d.asDiagonal() * lti::expm(balanced) * d.cwiseInverse().asDiagonal();
  return {e.topLeftCorner(n, n), e.topRightCorner(n, m)};
}

}  // namespace

DiscretePlant discretize(const ContinuousPlant& plant, double ts, double fraction) {
  const Eigen::Index n = plant.states();
  DiscretePlant d;
  const auto [phi, gamma] = hold(plant, ts);
  d.Phi = phi;
  d.Gamma = lti::Matrix::Zero(n, kDiscreteInputs);
  d.Gamma.col(kForce) = gamma.col(kInForce);
  d.Gamma.col(kMass) = gamma.col(kInMass);
  if (fraction > 0.0) {
    const auto [phi_late, gamma_late] = hold(plant, (1.0 - fraction) * ts);
    const auto [phi_early, gamma_early] = hold(plant, fraction * ts);
    (void)phi_early;
    d.Gamma.col(kEarly) = phi_late * gamma_early.col(kInVa);
    d.Gamma.col(kLate) = gamma_late.col(kInVa);
  } else {
    d.Gamma.col(kLate) = gamma.col(kInVa);
  }
  return d;
}

namespace {

struct Block {
  bool complex = false;
  double sigma = 0.0;  // real part (or the real eigenvalue)
  double omega = 0.0;  // imaginary part (> 0)
};

// exp(J h) and int_0^h exp(J s) ds applied to the block's rows of B (1 or 2 rows, m columns).
void block_hold(const Block& blk, double h, const lti::Matrix& b_rows, lti::Matrix& phi, lti::Matrix& gamma) {
  if (!blk.complex) {
    const double l = blk.sigma;
    const double e = std::exp(l * h);
    const double integral = std::abs(l * h) < 1e-12 ? h : std::expm1(l * h) / l;
    phi = lti::Matrix::Constant(1, 1, e);
    gamma = integral * b_rows;
    return;
  }
  const double s = blk.sigma, w = blk.omega;
  const double e = std::exp(s * h);
  lti::Matrix j(2, 2);
  j << s, w, -w, s;
  phi.resize(2, 2);
  phi << e * std::cos(w * h), e * std::sin(w * h), -e * std::sin(w * h), e * std::cos(w * h);
  // J^-1 (exp(J h) - I); J is invertible (w > 0).
  lti::Matrix jinv(2, 2);
  jinv << s, -w, w, s;
  jinv /= s * s + w * w;
  gamma = jinv * (phi - lti::Matrix::Identity(2, 2)) * b_rows;
}

}  // namespace

ModalPlant discretize_modal(const ContinuousPlant& plant, double ts, double fraction) {
  const Eigen::Index n = plant.states();
  // Eigenvectors of the balanced matrix (states span many decades), mapped back: S = D S_b.
  const lti::Vector bal = balancing_scales(plant.A);
  const lti::Matrix balanced = bal.cwiseInverse().asDiagonal() * plant.A * bal.asDiagonal();
  Eigen::EigenSolver<lti::Matrix> es(balanced, true);
  if (es.info() != Eigen::Success) throw NumericalError("modal discretization", "the eigenvalue solver did not converge", false);
  const Eigen::VectorXcd lambda = es.eigenvalues();
  const Eigen::MatrixXcd vectors = es.eigenvectors();
  const double scale = plant.A.cwiseAbs().maxCoeff();

  std::vector<Block> real_blocks, complex_blocks;
  std::vector<Eigen::VectorXd> real_columns, complex_columns;
  for (Eigen::Index j = 0; j < n; ++j) {
    const std::complex<double> l = lambda(j);
    if (std::abs(l.imag()) <= 1e-10 * std::abs(l) + 1e-14 * scale) {
      real_blocks.push_back({false, l.real(), 0.0});
      Eigen::VectorXd v = vectors.col(j).real();
      real_columns.push_back(v / v.norm());
    } else if (l.imag() > 0.0) {
      complex_blocks.push_back({true, l.real(), l.imag()});
      const Eigen::VectorXcd v = vectors.col(j) / vectors.col(j).norm();
      complex_columns.push_back(v.real());
      complex_columns.push_back(v.imag());
    }
  }
  if (static_cast<Eigen::Index>(real_blocks.size() + 2 * complex_blocks.size()) != n) {
    throw NumericalError("modal discretization", "the eigenvalues of the bench model do not form conjugate pairs", false);
  }
  lti::Matrix s(n, n);
  Eigen::Index col = 0;
  for (const auto& v : real_columns) s.col(col++) = v;
  for (const auto& v : complex_columns) s.col(col++) = v;
  const Eigen::PartialPivLU<lti::Matrix> lu(s);
  lti::Matrix s_inv = lu.inverse();
  // Back to the original coordinates: x = D x_b = D S_b z.
  s = bal.asDiagonal() * s;
  s_inv = s_inv * bal.cwiseInverse().asDiagonal();
  // The modal form must reproduce A: otherwise A is (nearly) defective and this basis is useless.
  lti::Matrix lam = lti::Matrix::Zero(n, n);
  Eigen::Index r = 0;
  for (const auto& blk : real_blocks) {
    lam(r, r) = blk.sigma;
    ++r;
  }
  for (const auto& blk : complex_blocks) {
    lam(r, r) = blk.sigma;
    lam(r, r + 1) = blk.omega;
    lam(r + 1, r) = -blk.omega;
    lam(r + 1, r + 1) = blk.sigma;
    r += 2;
  }
  const double mismatch = (s * lam * s_inv - plant.A).norm() / plant.A.norm();
  if (!(mismatch < 1e-8)) {
    throw NumericalError("modal discretization",
                         fmt::format("the bench model is not diagonalizable to working precision (relative error {})",
                                     format_number(mismatch, 2)),
                         true);
  }
  const lti::Matrix bm = s_inv * plant.B;

  ModalPlant m;
  m.real_blocks = static_cast<int>(real_blocks.size());
  m.complex_blocks = static_cast<int>(complex_blocks.size());
  m.Gamma = lti::Matrix::Zero(n, kDiscreteInputs);
  m.C = plant.C * s;
  m.D = plant.D;
  r = 0;
  auto do_block = [&](const Block& blk) {
    const Eigen::Index size = blk.complex ? 2 : 1;
    const lti::Matrix rows = bm.middleRows(r, size);
    lti::Matrix phi, gamma;
    block_hold(blk, ts, rows, phi, gamma);
    m.a.push_back(phi(0, 0));
    m.b.push_back(blk.complex ? phi(0, 1) : 0.0);
    m.Gamma.block(r, kForce, size, 1) = gamma.col(kInForce);
    m.Gamma.block(r, kMass, size, 1) = gamma.col(kInMass);
    if (fraction > 0.0) {
      lti::Matrix phi_late, gamma_late, phi_early, gamma_early;
      block_hold(blk, (1.0 - fraction) * ts, rows, phi_late, gamma_late);
      block_hold(blk, fraction * ts, rows, phi_early, gamma_early);
      m.Gamma.block(r, kEarly, size, 1) = phi_late * gamma_early.col(kInVa);
      m.Gamma.block(r, kLate, size, 1) = gamma_late.col(kInVa);
    } else {
      m.Gamma.block(r, kLate, size, 1) = gamma.col(kInVa);
    }
    r += size;
  };
  for (const auto& blk : real_blocks) do_block(blk);
  for (const auto& blk : complex_blocks) do_block(blk);
  return m;
}

}  // namespace piezobench::bench::detail
