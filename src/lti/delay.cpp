#include "piezobench/lti/delay.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "check.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::lti {
namespace {

void check_order(int order, const std::string& source) {
  if (order < 0) throw InputError(source, "order", "an approximation order >= 0", std::to_string(order));
}

// Denominator of the [N/N] Pade approximant of exp(-x) in ascending powers of x, q_0 = 1:
//   q_k = (2N - k)! N! / ((2N)! k! (N - k)!),
// built by the ratio q_k / q_{k-1} = (N - k + 1) / ((2N - k + 1) k), as MATLAB's pade.m does.
// The numerator is q(-x).
std::vector<double> pade_unit_denominator(int order) {
  std::vector<double> q(static_cast<size_t>(order) + 1, 1.0);
  for (int k = 1; k <= order; ++k) {
    q[static_cast<size_t>(k)] =
        q[static_cast<size_t>(k) - 1] * static_cast<double>(order - k + 1) / static_cast<double>((2 * order - k + 1) * k);
  }
  return q;
}

// State space of the continuous Pade approximant of exp(-s delay): the unit-delay approximant
// P(x) = q(-x)/q(x) realized in controllable canonical form, then time-scaled by x = s * delay
// (A = A1 / delay, B = B1 / delay), which keeps the companion coefficients O(1)..O(N!/(2N)!)^-1
// independent of the delay's size. D = (-1)^N.
StateSpace pade_state_space(double delay, int order) {
  if (order == 0 || delay == 0.0) return StateSpace::gain(Matrix::Ones(1, 1));
  const std::vector<double> q = pade_unit_denominator(order);
  const auto n = static_cast<Index>(order);
  const double lead = q[static_cast<size_t>(order)];
  // Monic denominator x^N + a_{N-1} x^{N-1} + ... + a_0 with a_k = q_k / q_N.
  Matrix a = Matrix::Zero(n, n);
  for (Index j = 0; j < n; ++j) a(0, j) = -q[static_cast<size_t>(n - 1 - j)] / lead;
  for (Index i = 1; i < n; ++i) a(i, i - 1) = 1.0;
  const Matrix b = Vector::Unit(n, 0);
  // Numerator / q_N = d * den + remainder, d = (-1)^N; remainder coefficient of x^k:
  //   ((-1)^k - (-1)^N) q_k / q_N  (k < N).
  const double d = (order % 2 == 0) ? 1.0 : -1.0;
  Matrix c = Matrix::Zero(1, n);
  for (Index j = 0; j < n; ++j) {
    const Index k = n - 1 - j;
    const double sign_k = (k % 2 == 0) ? 1.0 : -1.0;
    c(0, j) = (sign_k - d) * q[static_cast<size_t>(k)] / lead;
  }
  return StateSpace(a / delay, b / delay, c, Matrix::Constant(1, 1, d));
}

// d samples of pure delay, x[k+1] = shift(x[k]) + e1 u[k], y = x_d.
StateSpace unit_delays(Index d, double ts) {
  if (d == 0) return StateSpace::gain(Matrix::Ones(1, 1), ts);
  Matrix a = Matrix::Zero(d, d);
  for (Index i = 1; i < d; ++i) a(i, i - 1) = 1.0;
  const Matrix b = Vector::Unit(d, 0);
  const Matrix c = Vector::Unit(d, d - 1).transpose();
  return StateSpace(a, b, c, Matrix::Zero(1, 1), ts);
}

// Block-diagonal assembly of SISO delay blocks, one per channel.
StateSpace diagonal(const std::vector<StateSpace>& blocks, double ts) {
  Index n = 0;
  for (const auto& blk : blocks) n += blk.states();
  const auto k = static_cast<Index>(blocks.size());
  StateSpace out(Matrix::Zero(n, n), Matrix::Zero(n, k), Matrix::Zero(k, n), Matrix::Zero(k, k), ts);
  Index pos = 0;
  for (Index i = 0; i < k; ++i) {
    const StateSpace& blk = blocks[static_cast<size_t>(i)];
    const Index ni = blk.states();
    if (ni > 0) {  // a block of a matrix with no states would be an offset from a null pointer
      out.A.block(pos, pos, ni, ni) = blk.A;
      out.B.block(pos, i, ni, 1) = blk.B;
      out.C.block(i, pos, 1, ni) = blk.C;
    }
    out.D(i, i) = blk.D(0, 0);
    pos += ni;
  }
  return out;
}

}  // namespace

TransferFunction pade(double delay, int order) {
  if (!std::isfinite(delay) || delay < 0.0) throw InputError("pade", "delay", "a finite delay >= 0 s", format_number(delay, 10));
  check_order(order, "pade");
  if (order == 0 || delay == 0.0) return TransferFunction(Vector::Ones(1), Vector::Ones(1));
  const std::vector<double> q = pade_unit_denominator(order);
  const auto n = static_cast<Index>(order);
  // Coefficient of s^k is q_k delay^k; normalized by the leading one (MATLAB returns a monic
  // denominator). Descending powers: index n - k.
  Vector den(n + 1);
  Vector numerator(n + 1);
  const double lead = q[static_cast<size_t>(order)] * std::pow(delay, order);
  for (Index k = 0; k <= n; ++k) {
    const double coef = q[static_cast<size_t>(k)] * std::pow(delay, static_cast<double>(k)) / lead;
    den(n - k) = coef;
    numerator(n - k) = (k % 2 == 0) ? coef : -coef;
  }
  return TransferFunction(numerator, den);
}

StateSpace pade(const StateSpace& sys, int order) {
  sys.validate("pade");
  check_order(order, "pade");
  if (!sys.has_delay()) return sys;
  const Index m = sys.inputs();
  const Index p = sys.outputs();
  const double ts = sys.sample_time;
  auto block = [&](double tau, const std::string& field) -> StateSpace {
    if (!sys.is_discrete()) return pade_state_space(tau, order);
    const double ratio = tau / ts;
    const double rounded = std::round(ratio);
    if (std::abs(ratio - rounded) > 1e-9 * std::max(1.0, rounded)) {
      throw InputError("pade", field, "a whole multiple of the sample time " + format_number(ts, 10) + " s", format_number(tau, 10) + " s");
    }
    return unit_delays(static_cast<Index>(rounded), ts);
  };
  std::vector<StateSpace> in_blocks;
  std::vector<StateSpace> out_blocks;
  for (Index j = 0; j < m; ++j) {
    const double tau = sys.input_delay.size() == m ? sys.input_delay(j) : 0.0;
    in_blocks.push_back(block(tau, "input_delay"));
  }
  for (Index i = 0; i < p; ++i) {
    const double tau = sys.output_delay.size() == p ? sys.output_delay(i) : 0.0;
    out_blocks.push_back(block(tau, "output_delay"));
  }
  const StateSpace pin = diagonal(in_blocks, ts);
  const StateSpace pout = diagonal(out_blocks, ts);
  const Index n = sys.states();
  const Index ni = pin.states();
  const Index no = pout.states();
  // Input side: w = Pin(u) feeds the system:  x' = A x + B (Cp xp + Dp u).
  // States ordered [x; x_in; x_out].
  StateSpace out;
  out.sample_time = ts;
  out.A = Matrix::Zero(n + ni + no, n + ni + no);
  out.B = Matrix::Zero(n + ni + no, m);
  out.C = Matrix::Zero(p, n + ni + no);
  out.A.block(0, 0, n, n) = sys.A;
  out.A.block(0, n, n, ni) = sys.B * pin.C;
  out.A.block(n, n, ni, ni) = pin.A;
  out.B.topRows(n) = sys.B * pin.D;
  out.B.middleRows(n, ni) = pin.B;
  // The undelayed output y = C x + D Cp xp + D Dp u drives the output blocks.
  Matrix cy = Matrix::Zero(p, n + ni);
  cy.leftCols(n) = sys.C;
  cy.rightCols(ni) = sys.D * pin.C;
  const Matrix dy = sys.D * pin.D;
  out.A.block(n + ni, 0, no, n + ni) = pout.B * cy;
  out.A.block(n + ni, n + ni, no, no) = pout.A;
  out.B.bottomRows(no) = pout.B * dy;
  out.C.leftCols(n + ni) = pout.D * cy;
  out.C.rightCols(no) = pout.C;
  out.D = pout.D * dy;
  return out;
}

}  // namespace piezobench::lti
