#include "piezobench/dsp/unwrap.hpp"

#include <cmath>
#include <optional>

namespace piezobench::dsp {

std::vector<double> unwrap_phase(std::vector<double> phase, double period) {
  const double half = period / 2.0;
  std::optional<double> prev_raw, prev;  // the last finite value, as given and unwrapped
  for (double& p : phase) {
    if (!std::isfinite(p)) continue;
    const double raw = p;
    if (prev) {
      double step = raw - *prev_raw;
      while (step > half) step -= period;
      while (step < -half) step += period;
      p = *prev + step;
    }
    prev_raw = raw;
    prev = p;
  }
  return phase;
}

}  // namespace piezobench::dsp
