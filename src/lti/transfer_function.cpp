#include "piezobench/lti/transfer_function.hpp"

#include <utility>

#include "check.hpp"
#include "spectral.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::lti {

using detail::require_delay;
using detail::require_finite;

TransferFunction::TransferFunction(Vector numerator, Vector denominator, double ts, double delay_s)
    : num(std::move(numerator)), den(std::move(denominator)), sample_time(ts), delay(delay_s) {
  validate();
}

void TransferFunction::validate(const std::string& source) const {
  if (num.size() == 0) throw InputError(source, "num", "at least one coefficient", "none");
  if (den.size() == 0) throw InputError(source, "den", "at least one coefficient", "none");
  require_finite(num, source, "num");
  require_finite(den, source, "den");
  if (den(0) == 0.0) {
    throw InputError(source, "den(0)", "a nonzero leading coefficient (descending powers)", "0");
  }
  Index lead = 0;
  while (lead < num.size() && num(lead) == 0.0) ++lead;
  const Index num_degree = lead == num.size() ? 0 : num.size() - 1 - lead;
  if (num_degree > den.size() - 1) {
    throw InputError(source, "num",
                     "a proper transfer function (numerator degree <= denominator degree " +
                         std::to_string(den.size() - 1) + ")",
                     "numerator degree " + std::to_string(num_degree));
  }
  detail::require_sample_time(sample_time, source);
  require_delay(delay, source, "delay");
}

Zpk::Zpk(CVector z, CVector p, double k, double ts, double delay_s)
    : zeros(std::move(z)), poles(std::move(p)), gain(k), sample_time(ts), delay(delay_s) {
  validate();
}

void Zpk::validate(const std::string& source) const {
  require_finite(zeros, source, "zeros");
  require_finite(poles, source, "poles");
  if (!std::isfinite(gain)) throw InputError(source, "gain", "a finite value", format_number(gain, 10));
  if (zeros.size() > poles.size()) {
    throw InputError(source, "zeros",
                     "at most as many zeros as poles (" + std::to_string(poles.size()) + ", a proper system)",
                     std::to_string(zeros.size()) + " zeros");
  }
  (void)detail::split_conjugates(zeros, source, "zeros");
  (void)detail::split_conjugates(poles, source, "poles");
  detail::require_sample_time(sample_time, source);
  require_delay(delay, source, "delay");
}

}  // namespace piezobench::lti
