#pragma once
// Pure delays: exact in frequency responses (see freqresp.hpp), Pade approximants in state space.
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::lti {

// The [order/order] Pade approximant of exp(-s * delay) (continuous), as MATLAB's pade(T, N):
// all-pass, unit DC gain, monic denominator. order 0 (or delay 0) is the constant 1. Throws
// InputError for delay < 0 or order < 0.
TransferFunction pade(double delay, int order);
// The system with each input and output delay replaced by its Pade approximant of `order` in
// series (continuous systems). Discrete systems: delays that are whole multiples of Ts become
// exactly that many unit-delay states (order ignored); others throw InputError.
StateSpace pade(const StateSpace& sys, int order);

}  // namespace piezobench::lti
