#include "piezobench/lti/state_space.hpp"

#include <utility>

#include "check.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::lti {

using detail::require_delay;
using detail::require_finite;
using detail::shape;

StateSpace::StateSpace(Matrix a, Matrix b, Matrix c, Matrix d, double ts)
    : A(std::move(a)), B(std::move(b)), C(std::move(c)), D(std::move(d)), sample_time(ts) {
  // A system without states may be given with empty B and C of any shape (e.g. 0x0): they carry no
  // information beyond the input and output counts, which D fixes.
  if (A.size() == 0 && A.rows() == A.cols()) {
    if (B.size() == 0) B.resize(0, D.cols());
    if (C.size() == 0) C.resize(D.rows(), 0);
  }
  // An empty D with states means no feedthrough.
  if (D.size() == 0 && A.rows() > 0) D = Matrix::Zero(C.rows(), B.cols());
  validate();
}

StateSpace StateSpace::gain(const Matrix& d, double ts) {
  return StateSpace(Matrix(0, 0), Matrix(0, d.cols()), Matrix(d.rows(), 0), d, ts);
}

bool StateSpace::has_delay() const {
  return (input_delay.size() > 0 && (input_delay.array() != 0.0).any()) ||
         (output_delay.size() > 0 && (output_delay.array() != 0.0).any());
}

double StateSpace::channel_delay(Index output, Index input) const {
  if (output < 0 || output >= outputs()) {
    throw InputError("", "output", "an index in [0, " + std::to_string(outputs()) + ")", std::to_string(output));
  }
  if (input < 0 || input >= inputs()) {
    throw InputError("", "input", "an index in [0, " + std::to_string(inputs()) + ")", std::to_string(input));
  }
  double tau = 0.0;
  if (input_delay.size() > 0) tau += input_delay(input);
  if (output_delay.size() > 0) tau += output_delay(output);
  return tau;
}

void StateSpace::validate(const std::string& source) const {
  const Index n = A.rows();
  if (A.cols() != n) throw InputError(source, "A", "a square matrix", shape(A.rows(), A.cols()));
  if (B.rows() != n) {
    throw InputError(source, "B", std::to_string(n) + " rows (one per state, as A)", std::to_string(B.rows()));
  }
  if (C.cols() != n) {
    throw InputError(source, "C", std::to_string(n) + " columns (one per state, as A)", std::to_string(C.cols()));
  }
  if (D.rows() != C.rows()) {
    throw InputError(source, "D", std::to_string(C.rows()) + " rows (one per output, as C)", std::to_string(D.rows()));
  }
  if (D.cols() != B.cols()) {
    throw InputError(source, "D", std::to_string(B.cols()) + " columns (one per input, as B)",
                     std::to_string(D.cols()));
  }
  require_finite(A, source, "A");
  require_finite(B, source, "B");
  require_finite(C, source, "C");
  require_finite(D, source, "D");
  detail::require_sample_time(sample_time, source);
  if (input_delay.size() != 0 && input_delay.size() != D.cols()) {
    throw InputError(source, "input_delay", "empty or " + std::to_string(D.cols()) + " entries (one per input)",
                     std::to_string(input_delay.size()) + " entries");
  }
  if (output_delay.size() != 0 && output_delay.size() != D.rows()) {
    throw InputError(source, "output_delay", "empty or " + std::to_string(D.rows()) + " entries (one per output)",
                     std::to_string(output_delay.size()) + " entries");
  }
  for (Index i = 0; i < input_delay.size(); ++i) require_delay(input_delay(i), source, detail::entry("input_delay", i));
  for (Index i = 0; i < output_delay.size(); ++i) {
    require_delay(output_delay(i), source, detail::entry("output_delay", i));
  }
}

}  // namespace piezobench::lti
