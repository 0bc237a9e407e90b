#include "piezobench/lti/interconnect.hpp"

#include <string>

#include "check.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::lti {
namespace {

// Sample time shared by two operands. A static gain (no states) declared continuous fits a discrete
// system as well, as in MATLAB.
double common_sample_time(const StateSpace& a, const StateSpace& b, const std::string& op) {
  if (a.sample_time == b.sample_time) return a.sample_time;
  if (a.states() == 0 && a.sample_time == 0.0) return b.sample_time;
  if (b.states() == 0 && b.sample_time == 0.0) return a.sample_time;
  throw InputError(op, "sample_time", "the same sample time for both systems (" + format_number(a.sample_time, 10) + " s)",
                   format_number(b.sample_time, 10) + " s");
}

void reject_delay(const StateSpace& sys, const std::string& op, const std::string& which) {
  if (sys.has_delay()) {
    throw InputError(op, which + ".input_delay/output_delay",
                     "no delay in this interconnection (approximate it with lti::pade(sys, order) first)",
                     "a delayed channel");
  }
}

Vector delays_or_zero(const Vector& delays, Index count) {
  return delays.size() == 0 ? Vector::Zero(count) : delays;
}

Matrix block_diagonal(const Matrix& a, const Matrix& b) {
  Matrix m = Matrix::Zero(a.rows() + b.rows(), a.cols() + b.cols());
  m.topLeftCorner(a.rows(), a.cols()) = a;
  m.bottomRightCorner(b.rows(), b.cols()) = b;
  return m;
}

void require_indices(const std::vector<Index>& idx, Index count, const std::string& op, const std::string& field,
                     bool unique) {
  for (std::size_t k = 0; k < idx.size(); ++k) {
    if (idx[k] < 0 || idx[k] >= count) {
      throw InputError(op, field + "[" + std::to_string(k) + "]",
                       "an index in [0, " + std::to_string(count) + ")", std::to_string(idx[k]));
    }
    if (unique) {
      for (std::size_t l = 0; l < k; ++l) {
        if (idx[l] == idx[k]) {
          throw InputError(op, field + "[" + std::to_string(k) + "]", "distinct indices",
                           std::to_string(idx[k]) + " repeated");
        }
      }
    }
  }
}

}  // namespace

StateSpace series(const StateSpace& first, const StateSpace& second) {
  first.validate("series: first");
  second.validate("series: second");
  const double ts = common_sample_time(first, second, "series");
  if (first.outputs() != second.inputs()) {
    throw InputError("series", "second.inputs", std::to_string(first.outputs()) + " (the outputs of first)",
                     std::to_string(second.inputs()));
  }
  const bool siso = first.inputs() == 1 && first.outputs() == 1 && second.outputs() == 1;
  if (!siso) {
    // Delays at the outer ports stay where they are; delays between the two blocks would have to
    // commute with a MIMO block, which they do not in general.
    if (first.output_delay.size() > 0 && (first.output_delay.array() != 0.0).any()) reject_delay(first, "series", "first");
    if (second.input_delay.size() > 0 && (second.input_delay.array() != 0.0).any()) reject_delay(second, "series", "second");
  }
  const Index n1 = first.states();
  const Index n2 = second.states();
  Matrix a = Matrix::Zero(n1 + n2, n1 + n2);
  a.topLeftCorner(n1, n1) = first.A;
  a.bottomLeftCorner(n2, n1) = second.B * first.C;
  a.bottomRightCorner(n2, n2) = second.A;
  Matrix b(n1 + n2, first.inputs());
  b << first.B, second.B * first.D;
  Matrix c(second.outputs(), n1 + n2);
  c << second.D * first.C, second.C;
  StateSpace out(a, b, c, second.D * first.D, ts);
  if (siso) {
    const double tau = first.channel_delay(0, 0) + second.channel_delay(0, 0);
    if (tau > 0.0) out.input_delay = Vector::Constant(1, tau);
  } else {
    out.input_delay = first.input_delay;
    out.output_delay = second.output_delay;
  }
  return out;
}

StateSpace parallel(const StateSpace& a, const StateSpace& b) {
  a.validate("parallel: a");
  b.validate("parallel: b");
  const double ts = common_sample_time(a, b, "parallel");
  if (a.inputs() != b.inputs() || a.outputs() != b.outputs()) {
    throw InputError("parallel", "b", "the size of a: " + detail::shape(a.outputs(), a.inputs()) + " (outputs x inputs)",
                     detail::shape(b.outputs(), b.inputs()));
  }
  // Identical delays on both branches factor out; anything else would need a delay inside a branch.
  const Vector ia = delays_or_zero(a.input_delay, a.inputs());
  const Vector ib = delays_or_zero(b.input_delay, b.inputs());
  const Vector oa = delays_or_zero(a.output_delay, a.outputs());
  const Vector ob = delays_or_zero(b.output_delay, b.outputs());
  if (ia != ib || oa != ob) reject_delay(a.has_delay() ? a : b, "parallel", a.has_delay() ? "a" : "b");
  Matrix bb(a.states() + b.states(), a.inputs());
  bb << a.B, b.B;
  Matrix cc(a.outputs(), a.states() + b.states());
  cc << a.C, b.C;
  StateSpace out(block_diagonal(a.A, b.A), bb, cc, a.D + b.D, ts);
  out.input_delay = a.input_delay.size() > 0 ? a.input_delay : b.input_delay;
  out.output_delay = a.output_delay.size() > 0 ? a.output_delay : b.output_delay;
  return out;
}

StateSpace scale(const StateSpace& sys, double k) {
  sys.validate("scale");
  if (!std::isfinite(k)) throw InputError("scale", "k", "a finite factor", format_number(k, 10));
  StateSpace out = sys;
  out.C *= k;
  out.D *= k;
  return out;
}

StateSpace append(const StateSpace& a, const StateSpace& b) {
  a.validate("append: a");
  b.validate("append: b");
  const double ts = common_sample_time(a, b, "append");
  StateSpace out(block_diagonal(a.A, b.A), block_diagonal(a.B, b.B), block_diagonal(a.C, b.C),
                 block_diagonal(a.D, b.D), ts);
  if (a.input_delay.size() > 0 || b.input_delay.size() > 0) {
    out.input_delay.resize(out.inputs());
    out.input_delay << delays_or_zero(a.input_delay, a.inputs()), delays_or_zero(b.input_delay, b.inputs());
  }
  if (a.output_delay.size() > 0 || b.output_delay.size() > 0) {
    out.output_delay.resize(out.outputs());
    out.output_delay << delays_or_zero(a.output_delay, a.outputs()), delays_or_zero(b.output_delay, b.outputs());
  }
  return out;
}

StateSpace select(const StateSpace& sys, const std::vector<Index>& outputs, const std::vector<Index>& inputs) {
  sys.validate("select");
  require_indices(outputs, sys.outputs(), "select", "outputs", /*unique=*/false);
  require_indices(inputs, sys.inputs(), "select", "inputs", /*unique=*/false);
  const auto no = static_cast<Index>(outputs.size());
  const auto ni = static_cast<Index>(inputs.size());
  Matrix b(sys.states(), ni);
  Matrix d(no, ni);
  Matrix c(no, sys.states());
  for (Index j = 0; j < ni; ++j) b.col(j) = sys.B.col(inputs[static_cast<std::size_t>(j)]);
  for (Index i = 0; i < no; ++i) {
    c.row(i) = sys.C.row(outputs[static_cast<std::size_t>(i)]);
    for (Index j = 0; j < ni; ++j) d(i, j) = sys.D(outputs[static_cast<std::size_t>(i)], inputs[static_cast<std::size_t>(j)]);
  }
  StateSpace out(sys.A, b, c, d, sys.sample_time);
  if (sys.input_delay.size() > 0) {
    out.input_delay.resize(ni);
    for (Index j = 0; j < ni; ++j) out.input_delay(j) = sys.input_delay(inputs[static_cast<std::size_t>(j)]);
  }
  if (sys.output_delay.size() > 0) {
    out.output_delay.resize(no);
    for (Index i = 0; i < no; ++i) out.output_delay(i) = sys.output_delay(outputs[static_cast<std::size_t>(i)]);
  }
  return out;
}

StateSpace feedback(const StateSpace& forward, const StateSpace& back, FeedbackSign sign) {
  std::vector<Index> feedin(static_cast<std::size_t>(forward.inputs()));
  std::vector<Index> feedout(static_cast<std::size_t>(forward.outputs()));
  for (std::size_t i = 0; i < feedin.size(); ++i) feedin[i] = static_cast<Index>(i);
  for (std::size_t i = 0; i < feedout.size(); ++i) feedout[i] = static_cast<Index>(i);
  return feedback(forward, back, feedin, feedout, sign);
}

StateSpace feedback(const StateSpace& forward, const StateSpace& back, const std::vector<Index>& feedin,
                    const std::vector<Index>& feedout, FeedbackSign sign) {
  forward.validate("feedback: forward");
  back.validate("feedback: back");
  const double ts = common_sample_time(forward, back, "feedback");
  reject_delay(forward, "feedback", "forward");
  reject_delay(back, "feedback", "back");
  require_indices(feedin, forward.inputs(), "feedback", "feedin", /*unique=*/true);
  require_indices(feedout, forward.outputs(), "feedback", "feedout", /*unique=*/true);
  const auto nin = static_cast<Index>(feedin.size());
  const auto nout = static_cast<Index>(feedout.size());
  if (back.inputs() != nout || back.outputs() != nin) {
    throw InputError("feedback", "back",
                     detail::shape(nin, nout) + " (outputs x inputs: one output per feedin, one input per feedout)",
                     detail::shape(back.outputs(), back.inputs()));
  }
  const Index n1 = forward.states();
  const Index n2 = back.states();
  const Index m = forward.inputs();
  const Index p = forward.outputs();
  const double sg = sign == FeedbackSign::kNegative ? -1.0 : 1.0;
  // G scatters back's outputs into forward's inputs, F gathers forward's outputs into back's inputs.
  Matrix g = Matrix::Zero(m, nin);
  for (Index k = 0; k < nin; ++k) g(feedin[static_cast<std::size_t>(k)], k) = 1.0;
  Matrix f = Matrix::Zero(nout, p);
  for (Index k = 0; k < nout; ++k) f(k, feedout[static_cast<std::size_t>(k)]) = 1.0;

  // y = C1 x1 + D1 u,  u = r + sg G (C2 x2 + D2 F y)   =>   (I - sg D1 G D2 F) y = C1 x1 + sg D1 G C2 x2 + D1 r
  const Matrix d1g = forward.D * g;
  const Matrix loop = Matrix::Identity(p, p) - sg * d1g * back.D * f;
  const Eigen::FullPivLU<Matrix> lu(loop);
  if (!lu.isInvertible()) {
    throw NumericalError("feedback", "I - sign * D_forward * D_back is singular (an algebraic loop with no solution)",
                         /*retry_may_help=*/false);
  }
  Matrix cx(p, n1 + n2);
  cx << forward.C, sg * d1g * back.C;
  const Matrix cy = lu.solve(cx);
  const Matrix dy = lu.solve(forward.D);
  // u = r + sg G (C2 x2 + D2 F y)
  Matrix cu = sg * g * back.D * f * cy;
  cu.rightCols(n2) += sg * g * back.C;
  const Matrix du = Matrix::Identity(m, m) + sg * g * back.D * f * dy;

  Matrix a = block_diagonal(forward.A, back.A);
  a.topRows(n1) += forward.B * cu;
  a.bottomRows(n2) += back.B * f * cy;
  Matrix b(n1 + n2, m);
  b << forward.B * du, back.B * f * dy;
  return StateSpace(a, b, cy, dy, ts);
}

}  // namespace piezobench::lti
