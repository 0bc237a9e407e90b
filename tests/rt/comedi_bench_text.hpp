#pragma once
// The Comedi bench file of the rt tests (the report's bench, docs/hardware.md): amplifier 20 V/V,
// limits -20..150 V and 1e5 V/s; u on analog output 1.0, d_e on counter 2.0, Vs on analog input
// 0.2, all +-10 V. Tests derive the variants they need with replace_once.
#include <gtest/gtest.h>

#include <string>

namespace piezobench::test {

inline std::string comedi_bench_text(const std::string& device, const std::string& calibration) {
  return R"(
[bench]
backend = "comedi"
sample_rate_Hz = 10000
[comedi]
device = ")" + device + R"("
calibration = ")" + calibration + R"("
[amplifier]
gain_V_per_V = 20
[limits]
va_min_V = -20
va_max_V = 150
slew_rate_V_per_s = 1e5
[signals.u]
subdevice = 1
channel = 0
range = [-10, 10]
scale = 1.0
unit = "V"
[signals.d_e]
subdevice = 2
channel = 0
kind = "counter"
unit = "m"
[signals.Vs]
subdevice = 0
channel = 2
range = [-10, 10]
scale = 1.0
unit = "V"
)";
}

// `text` with the first `from` replaced by `to` (a test failure when `from` is not there).
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

}  // namespace piezobench::test
