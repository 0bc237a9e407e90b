#pragma once
// Linear time-invariant systems in state-space form, continuous or discrete, MIMO, with pure delays
// on the inputs and outputs.
#include <Eigen/Dense>
#include <string>

namespace piezobench::lti {

using Index = Eigen::Index;
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;
using CMatrix = Eigen::MatrixXcd;
using CVector = Eigen::VectorXcd;
using Complex = std::complex<double>;

// continuous (sample_time == 0):   dx/dt = A x + B u(t - tau_in),  y(t) = C x + D u(t - tau_in)
// discrete   (sample_time  > 0):   x[k+1] = A x[k] + B u[k],      y[k]  = C x[k] + D u[k]
// then every output i is delayed by output_delay(i) and every input j by input_delay(j) (seconds).
// A delay is exact in frequency responses (exp(-s tau)); lti::pade() turns it into states.
// Units are the caller's (SI in piezobench); poles are in rad/s (continuous) or the z-plane.
struct StateSpace {
  Matrix A;  // states x states
  Matrix B;  // states x inputs
  Matrix C;  // outputs x states
  Matrix D;  // outputs x inputs
  double sample_time = 0.0;  // s; 0 = continuous
  Vector input_delay;        // s, size inputs() or empty (no delay)
  Vector output_delay;       // s, size outputs() or empty (no delay)

  StateSpace() = default;
  // Validates (InputError, see validate()). Conveniences: without states, B and C may be given
  // empty (any shape); with states, an empty D means no feedthrough.
  // ts: s, 0 = continuous.
  StateSpace(Matrix a, Matrix b, Matrix c, Matrix d, double ts = 0.0);

  // A static gain y = D u (no states).
  // ts: s, 0 = continuous.
  static StateSpace gain(const Matrix& d, double ts = 0.0);

  [[nodiscard]] Index states() const { return A.rows(); }
  [[nodiscard]] Index inputs() const { return D.cols(); }
  [[nodiscard]] Index outputs() const { return D.rows(); }
  [[nodiscard]] bool is_discrete() const { return sample_time > 0.0; }
  [[nodiscard]] bool has_delay() const;
  // Total delay of channel (output, input): input_delay(input) + output_delay(output), s.
  [[nodiscard]] double channel_delay(Index output, Index input) const;

  // Throws InputError naming `source` and the field (A, B, C, D, sample_time, input_delay,
  // output_delay) for inconsistent sizes, non-finite entries, a negative sample time or delay.
  void validate(const std::string& source = "") const;
};

}  // namespace piezobench::lti
