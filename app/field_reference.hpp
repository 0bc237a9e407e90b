#pragma once
// docs/fields.md as the program writes it (`piezobench fields`): campaign's reference
// (campaign::field_reference_markdown) and the declared results of the modules campaign does not
// depend on, which only the program sees all of: rt's loop report (with its I/O and timing
// summaries), its actuator limits, and bench's tracking summary (`measure tracking --json`).
#include <string>

namespace piezobench::app {

std::string field_reference_markdown();

}  // namespace piezobench::app
