#include "field_reference.hpp"

#include "piezobench/bench/tracking.hpp"
#include "piezobench/campaign/field_reference.hpp"
#include "piezobench/campaign/field_table.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/safety.hpp"

namespace piezobench::app {

std::string field_reference_markdown() {
  return campaign::field_reference_markdown([](std::string& out, std::set<std::string>& done) {
    campaign::field_table<bench::TrackingSummary>(out, done);  // `measure tracking --json`'s tracking
    campaign::field_table<rt::LoopReport>(out, done);          // `rt --json`, `measure --json`'s runs (IoStats, TimingSummary)
    campaign::field_table<rt::ActuatorLimits>(out, done);      // `rt --json`'s limits
  });
}

}  // namespace piezobench::app
