// The operators of the phase runner: answers from a file, or prompts on the terminal.
#include <fmt/format.h>

#include <istream>
#include <ostream>

#include "piezobench/core/error.hpp"
#include "piezobench/station/phase_runner.hpp"

namespace piezobench::station {

StepAnswer AnswersOperator::step(const PhaseSpec& phase, std::size_t index) {
  const auto it = answers_.phases.find(phase.name);
  // read_answers guarantees an answer per step; a station changed since is refused here.
  if (it == answers_.phases.end() || index >= it->second.steps.size()) {
    throw InputError(answers_.file.string(), "phases." + phase.name + ".steps", "an answer to: " + phase.steps[index], "none");
  }
  return it->second.steps[index];
}

CheckAnswer AnswersOperator::check_failed(const PhaseSpec& phase, int, const std::string&) {
  const auto it = answers_.phases.find(phase.name);
  std::size_t& used = check_answers_used_[phase.name];
  if (it == answers_.phases.end() || used >= it->second.on_check_fail.size()) return CheckAnswer::kContinue;
  return it->second.on_check_fail[used++];
}

PhaseValues AnswersOperator::values(const PhaseSpec& phase) {
  const auto it = answers_.phases.find(phase.name);
  if (it == answers_.phases.end()) return {};
  return {it->second.sensor_uF, it->second.actuator_uF, it->second.file};
}

std::string TerminalOperator::ask(const std::string& prompt) {
  out_ << prompt << std::flush;
  std::string line;
  if (!std::getline(in_, line)) return "";
  return line;
}

StepAnswer TerminalOperator::step(const PhaseSpec& phase, std::size_t index) {
  for (;;) {
    const std::string a = ask(fmt::format("operator, phase {} ({}/{}): {}; [y] confirm when done, [a] abort: ", phase.name, index + 1,
                                          phase.steps.size(), phase.steps[index]));
    if (a == "y" || a == "Y" || a == "yes") return StepAnswer::kConfirm;
    if (a == "a" || a == "abort" || in_.eof()) return StepAnswer::kAbort;
  }
}

CheckAnswer TerminalOperator::check_failed(const PhaseSpec& phase, int try_number, const std::string& why) {
  for (;;) {
    const std::string a =
        ask(fmt::format("operator, phase {} try {} failed its checks: {}; [r] retry, [c] continue with the failure, [a] abort: ", phase.name,
                        try_number, why));
    if (a == "r") return CheckAnswer::kRetry;
    if (a == "c") return CheckAnswer::kContinue;
    if (a == "a" || in_.eof()) return CheckAnswer::kAbort;
  }
}

PhaseValues TerminalOperator::values(const PhaseSpec& phase) {
  PhaseValues v;
  if (phase.source == ValueSource::kFile) {
    const std::string f = ask(fmt::format("operator, phase {}: the {} file: ", phase.name, phase.experiment));
    if (f.empty()) throw InputError("operator", phase.name, "the file of the phase", "nothing");
    v.file = f;
  } else if (phase.source == ValueSource::kTyped) {
    for (auto [what, out] : {std::pair{"sensor", &v.sensor_uF}, std::pair{"actuator", &v.actuator_uF}}) {
      const std::string s = ask(fmt::format("operator, phase {}: capacitance of the {} stack(s), uF: ", phase.name, what));
      try {
        std::size_t used = 0;
        const double x = std::stod(s, &used);
        if (used != s.size() || !(x > 0.0)) throw std::invalid_argument(s);
        *out = x;
      } catch (const std::exception&) {
        throw InputError("operator", phase.name + "." + what + "_uF", "a capacitance > 0 in uF", "'" + s + "'");
      }
    }
  }
  return v;
}

}  // namespace piezobench::station
