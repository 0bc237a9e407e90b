#pragma once
// A small station for the tests: flatness, capacitance, stroke and a hysteresis phase on the
// virtual bench, with the report's limits (docs/examples/station.toml has the whole sequence).
#include <string>

namespace piezobench::station::testdata {

inline const std::string kSmallStation = R"(name = "test station"
margin_relative = 0.01
[campaign.bench]
amplifier_gain = 20
[campaign.analysis]
fmin_Hz = 20.0

[[phases]]
name = "capacitance"
experiment = "capacitance"
[[phases.measurements]]
name = "capacitance_sensor_uF"
min = 4.0
max = 6.0
[[phases.measurements]]
name = "capacitance_actuator_uF"
min = 8.0
max = 12.0

[[phases]]
name = "stroke"
experiment = "stroke"
steps = ["mount the actuator"]
[[phases.measurements]]
name = "stroke_um"
min = 200.0
stop_on_fail = true

[[phases]]
name = "hysteresis-20V"
experiment = "hysteresis"
amplitude_V = 20.0
[[phases.measurements]]
name = "hysteresis_relative_width"
max = 0.5
)";

inline const std::string kSmallAnswers = R"(operator = "T. Tester"
[phases.stroke]
steps = ["confirm"]
)";

}  // namespace piezobench::station::testdata
