// Uses the installed piezobench: the resonance of a mass-spring-damper from a Welch FRF estimate
// and from its transfer function must agree.
#include <cmath>
#include <cstdio>

#include "piezobench.hpp"

int main() {
  using namespace piezobench;
  const double wn = kTwoPi * 50.0, zeta = 0.02;
  const lti::TransferFunction g((lti::Vector(1) << wn * wn).finished(), (lti::Vector(3) << 1.0, 2.0 * zeta * wn, wn * wn).finished());
  const lti::Vector w = Eigen::VectorXd::LinSpaced(2000, kTwoPi * 1.0, kTwoPi * 200.0);
  const lti::FrequencyResponse h = lti::freqresp(lti::to_state_space(g), w);
  Eigen::Index peak = 0;
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    if (std::abs(h.H[static_cast<std::size_t>(k)](0, 0)) > std::abs(h.H[static_cast<std::size_t>(peak)](0, 0))) peak = k;
  }
  const double f_peak = w(peak) / kTwoPi, expected = 50.0 * std::sqrt(1.0 - 2.0 * zeta * zeta);
  std::printf("piezobench %s: peak at %.3f Hz (expected %.3f Hz)\n", kVersion, f_peak, expected);
  return std::abs(f_peak - expected) < 0.1 ? 0 : 1;
}
