#pragma once
// SISO transfer functions as polynomial ratios and as zeros, poles and gain.
#include <string>

#include "piezobench/lti/state_space.hpp"

namespace piezobench::lti {

// H(s) = num(s) / den(s) * exp(-s delay); coefficients in descending powers of s (z when discrete),
// as MATLAB's tf: num = {1, 2} is s + 2. Leading zeros of num are allowed and ignored.
struct TransferFunction {
  Vector num;                // the caller's units
  Vector den;                // the caller's units
  double sample_time = 0.0;  // s; 0 = continuous
  double delay = 0.0;        // s

  TransferFunction() = default;
  // numerator, denominator: the caller's units; ts: s.
  TransferFunction(Vector numerator, Vector denominator, double ts = 0.0, double delay_s = 0.0);  // validates

  [[nodiscard]] bool is_discrete() const { return sample_time > 0.0; }
  // Degree of the denominator.
  [[nodiscard]] Index order() const { return den.size() - 1; }
  // Throws InputError naming `source` and the field: empty or non-finite coefficients, a zero
  // leading denominator coefficient, an improper function (numerator degree above the
  // denominator's, after leading zeros of num are dropped), negative delay or sample time.
  void validate(const std::string& source = "") const;
};

// H(s) = gain * prod(s - zeros) / prod(s - poles) * exp(-s delay). Complex zeros and poles come in
// conjugate pairs (checked by validate) so that H is real.
struct Zpk {
  CVector zeros;  // rad/s (continuous) or z-plane (discrete)
  CVector poles;
  double gain = 1.0;         // output unit per input unit
  double sample_time = 0.0;  // s, 0 = continuous
  double delay = 0.0;        // s

  Zpk() = default;
  // k: output unit per input unit; ts: s.
  Zpk(CVector z, CVector p, double k, double ts = 0.0, double delay_s = 0.0);  // validates

  [[nodiscard]] bool is_discrete() const { return sample_time > 0.0; }
  // Throws InputError: non-finite values, unpaired complex values (a pair matches to 1e-8
  // relative), more zeros than poles, negative delay or sample time.
  void validate(const std::string& source = "") const;
};

}  // namespace piezobench::lti
