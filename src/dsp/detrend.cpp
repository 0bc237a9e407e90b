#include "piezobench/dsp/detrend.hpp"

#include "piezobench/core/error.hpp"

namespace piezobench::dsp {

std::string to_string(Detrend detrend) {
  switch (detrend) {
    case Detrend::kNone: return "none";
    case Detrend::kMean: return "mean";
    case Detrend::kLinear: return "linear";
  }
  return "unknown";
}

Detrend detrend_from_string(const std::string& name) {
  if (name == "none") return Detrend::kNone;
  if (name == "mean") return Detrend::kMean;
  if (name == "linear") return Detrend::kLinear;
  throw InputError("", "detrend", "one of none, mean, linear", "\"" + name + "\"");
}

void detrend_in_place(Eigen::Ref<Eigen::VectorXd> x, Detrend detrend) {
  const Eigen::Index n = x.size();
  if (detrend == Detrend::kNone || n == 0) return;
  const double mean = x.mean();
  if (detrend == Detrend::kMean || n == 1) {
    x.array() -= mean;
    return;
  }
  // Least-squares line a + b (t - tc), t = 0..n-1, tc = (n-1)/2: a = mean(x) because the centred
  // abscissae sum to zero, b = sum((t - tc) x) / sum((t - tc)^2), the latter n (n^2 - 1) / 12.
  const double tc = 0.5 * static_cast<double>(n - 1);
  double sxt = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) sxt += (static_cast<double>(i) - tc) * x(i);
  const double dn = static_cast<double>(n);
  const double stt = dn * (dn * dn - 1.0) / 12.0;
  const double slope = sxt / stt;
  for (Eigen::Index i = 0; i < n; ++i) x(i) -= mean + slope * (static_cast<double>(i) - tc);
}

}  // namespace piezobench::dsp
