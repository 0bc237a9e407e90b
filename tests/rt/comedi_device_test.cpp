// The Comedi backend with the real comedilib against /dev/comedi0: the kernel's comedi_test driver
// (`modprobe comedi comedi_num_legacy_minors=4 && comedi_config /dev/comedi0 comedi_test`) or a
// card. Skipped with a message when the device does not exist (CI containers).
#include <gtest/gtest.h>

#include <filesystem>

#include "piezobench/rt/comedi_backend.hpp"
#include "piezobench/rt/loop.hpp"

namespace piezobench::rt {
namespace {

// comedi_test: subdevice 0 analog input (ranges +-10 V, +-5 V), subdevice 1 analog output. No
// counter: the encoder is read as an analog input here.
const char* kBench = R"(
[bench]
backend = "comedi"
sample_rate_Hz = 1000
[comedi]
device = "/dev/comedi0"
calibration = "none"
[amplifier]
gain_V_per_V = 20
[limits]
va_min_V = -20
va_max_V = 150
slew_rate_V_per_s = 1e5
watchdog_s = 0.5
[signals.u]
subdevice = 1
channel = 0
range = [-10, 10]
scale = 1.0
unit = "V"
[signals.d_e]
subdevice = 0
channel = 1
range = [-10, 10]
scale = 1e-5
unit = "m"
[signals.Vs]
subdevice = 0
channel = 0
range = [-10, 10]
scale = 1.0
unit = "V"
)";

TEST(ComediDevice, RunsTheLoopAgainstDevComedi0) {
  if (!std::filesystem::exists("/dev/comedi0")) {
    GTEST_SKIP() << "no /dev/comedi0: load the comedi_test driver (modprobe comedi comedi_num_legacy_minors=4; "
                    "comedi_config /dev/comedi0 comedi_test) or install a card to run this test";
  }
  ComediBackend backend(parse_bench_description(kBench, "comedi_test.toml"));
  LoopOptions lo;
  lo.duration = 0.2;
  lo.controller = false;
  lo.sched_fifo = lo.lock_memory = false;
  lo.limits = parse_bench_description(kBench, "comedi_test.toml").limits;
  lo.excitation = Eigen::VectorXd::Constant(1, 0.1);
  const LoopReport r = run_loop(backend, lo);
  EXPECT_EQ(r.cycles, 200u);
  EXPECT_EQ(r.io.errors, 0u);
  EXPECT_EQ(r.safe_state_reason, "none");
}

}  // namespace
}  // namespace piezobench::rt
