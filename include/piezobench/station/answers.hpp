#pragma once
// The answers file (`qualify --answers FILE`, docs/station.md): the operator's answers for an
// unattended run, checked against the station file before anything moves.
//
//   operator = "A. Operator"
//   [phases.NAME]                      NAME: a phase of the station file
//   steps = ["confirm", "abort"]       one per operator step of the phase, in order
//   on_check_fail = ["retry", "continue"]  per failed try: retry the phase, continue with the
//                                      failure recorded, or abort (default when they run out:
//                                      continue)
//   sensor_uF = 4.95, actuator_uF = 9.9    capacitance typed in (source = "typed")
//   file = "probe.csv"                 flatness or capacitance read from a file (source = "file"),
//                                      relative to the answers file's folder
//
// Refused (InputError naming the file, the line and the key; exit 3): an unknown key, a phase the
// station does not have (a typo), an answer that is not one of the words above, fewer or more step
// answers than the phase has steps, a typed value or file the phase needs and the answers lack.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/station/station_file.hpp"

namespace piezobench::station {

enum class StepAnswer { kConfirm, kAbort };
enum class CheckAnswer { kRetry, kContinue, kAbort };

struct PhaseAnswers {
  std::vector<StepAnswer> steps;
  std::vector<CheckAnswer> on_check_fail;
  std::optional<double> sensor_uF, actuator_uF;
  std::optional<std::filesystem::path> file;  // resolved against the answers file's folder
};

struct Answers {
  std::filesystem::path file;
  std::string operator_name;
  std::map<std::string, PhaseAnswers> phases;
};

Answers read_answers(const std::filesystem::path& file, const StationFile& station);
Answers parse_answers(const std::string& text, const std::filesystem::path& file, const StationFile& station);

}  // namespace piezobench::station
