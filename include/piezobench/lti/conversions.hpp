#pragma once
// Conversions between state space, transfer function and zpk forms, and polynomial helpers.
//
// tf/zpk -> ss builds a cascade of real first- and second-order sections from the zpk form (never
// the companion form of a high-order polynomial), which stays accurate for lightly damped poles.
// ss -> zpk takes the poles from eig(A), the zeros from lti::zeros (system pencil) and the gain from
// the frequency response at a point away from both.
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::lti {

// Roots of the polynomial with coefficients in descending powers (leading zeros dropped):
// eigenvalues of the balanced companion matrix (trailing zero coefficients give exact roots at 0),
// sorted as lti::poles. Zero-degree polynomial -> empty vector.
// coefficients: the caller's units.
CVector roots(const Vector& coefficients);
// Monic real polynomial whose roots are `r` (conjugate pairs required; the imaginary round-off of
// the product is dropped). Descending powers, size r.size() + 1.
Vector poly(const CVector& r);

Zpk to_zpk(const TransferFunction& tf);
Zpk to_zpk(const StateSpace& sys, Index output = 0, Index input = 0);
TransferFunction to_transfer_function(const Zpk& zpk);
TransferFunction to_transfer_function(const StateSpace& sys, Index output = 0, Index input = 0);
StateSpace to_state_space(const Zpk& zpk);
StateSpace to_state_space(const TransferFunction& tf);

}  // namespace piezobench::lti
