#pragma once
// Private to the lti module: eigenvalue sorting, conjugate pairing, the transmission-zero
// computation behind lti::zeros and lti::to_zpk, and a dense evaluation of H at one point.
#include <string>
#include <vector>

#include "piezobench/lti/state_space.hpp"

namespace piezobench::lti::detail {

// Sorts in place by increasing magnitude, then real part, then imaginary part (so a conjugate pair,
// whose moduli are bit-identical, is adjacent with the negative imaginary part first).
void sort_roots(CVector& v);

// Eigenvalues of a real square matrix, computed on D^-1 A D (balancing_scales), sorted as sort_roots.
CVector balanced_eigenvalues(const Matrix& a);

// Real values and conjugate pairs of a self-conjugate set. A value is real when
// |Im v| <= 8 eps |v|; a value with Im v > 0 is paired with the unused value closest to its
// conjugate, which must lie within 1e-8 |v| (values from eigen-solvers of real matrices are exact
// conjugates; the slack accepts pairs typed with a few rounded digits). Pairs are returned with
// Im > 0, averaged over the two members. Throws InputError(source, field, ...) for an unpaired value.
struct ConjugateSplit {
  std::vector<double> real;
  std::vector<Complex> pairs;
};
ConjugateSplit split_conjugates(const CVector& values, const std::string& source, const std::string& field);

// Finite invariant zeros of the system pencil [A - sI B; C D] (see analysis.hpp for the method),
// unsorted, and the normal rank of the transfer matrix (0 for a channel that is identically zero).
struct PencilZeros {
  CVector zeros;
  Index normal_rank = 0;
};
PencilZeros system_zeros(const Matrix& a, const Matrix& b, const Matrix& c, const Matrix& d);

// H(s) = D + C (sI - A)^-1 B by a dense complex LU with partial pivoting on the balanced
// realization. Throws NumericalError when sI - A is singular to working precision.
CMatrix evaluate_dense(const Matrix& a, const Matrix& b, const Matrix& c, const Matrix& d, Complex s);

}  // namespace piezobench::lti::detail
