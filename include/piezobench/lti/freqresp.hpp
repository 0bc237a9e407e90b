#pragma once
// Frequency responses of LTI systems.
//
// State space: A is reduced once to upper Hessenberg form H = Q^T A Q (after balancing, and after
// reversing the state order when that brings A closer to upper Hessenberg form, as for the block
// lower-triangular realizations of cascades: the reduction is then exact or nearly so). At each
// frequency (sI - H) X = Q^T B is solved by Gaussian elimination on the Hessenberg matrix with
// adjacent-row pivoting, O(n^2) per frequency and input instead of a dense O(n^3) solve (Laub,
// "Efficient multivariable frequency response computations", IEEE TAC 26(2), 1981; SLICOT TB05AD).
// Backward stable, so relative accuracy is about cond(sI - A) * eps even for damping ratios of 0.1 %.
// Delays are applied exactly: H(s) * exp(-s tau). Discrete systems use z = exp(j w Ts).
#include <vector>

#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::lti {

struct FrequencyResponse {
  Vector omega;             // rad/s
  std::vector<CMatrix> H;   // H[k] is outputs x inputs at omega[k]

  // The response of one channel at every frequency.
  [[nodiscard]] CVector channel(Index output, Index input) const;
};

// Reusable evaluator: the Hessenberg reduction is done once in the constructor. Thread-safe for
// concurrent calls to evaluate().
class FrequencyResponseEvaluator {
 public:
  explicit FrequencyResponseEvaluator(const StateSpace& sys);
  // H at the complex point s (continuous) or z (discrete), without delays. Throws NumericalError
  // when s is (numerically) a pole.
  [[nodiscard]] CMatrix evaluate(Complex s_or_z) const;
  // H(j w) with delays, at every omega (rad/s); work is split over `threads` threads (0 = all cores).
  [[nodiscard]] FrequencyResponse response(const Vector& omega, int threads = 1) const;

 private:
  StateSpace sys_;
  Matrix hessenberg_;  // H = Q^T A Q (balanced)
  Matrix qtb_;         // Q^T B (balanced)
  Matrix cq_;          // C Q (balanced)
};

// H(j w) at every omega (rad/s) of a state-space system.
FrequencyResponse freqresp(const StateSpace& sys, const Vector& omega);
// SISO forms: a zpk is evaluated as a product of factors (accurate near lightly damped pairs);
// a transfer function through its zpk form.
// omega: rad/s.
CVector freqresp(const Zpk& zpk, const Vector& omega);
// omega: rad/s.
CVector freqresp(const TransferFunction& tf, const Vector& omega);

// n points logarithmically spaced from 10^lo to 10^hi (as MATLAB's logspace, without its special
// case for hi == pi); n = 1 gives 10^hi, n = 0 an empty vector; InputError for n < 0 or non-finite
// exponents.
Vector logspace(double lo_exponent, double hi_exponent, Index n);

}  // namespace piezobench::lti
