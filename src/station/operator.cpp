// The operators of the phase runner: answers from a file, or prompts on the terminal.
#include <fmt/format.h>

#include <cmath>
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

std::vector<TypedValueField> typed_value_fields(const PhaseSpec& phase) {
  if (phase.source == ValueSource::kFile) return {{"file", "the " + phase.experiment + " file"}};
  if (phase.source == ValueSource::kTyped) {
    return {{"sensor_uF", "capacitance of the sensor stack(s), uF"}, {"actuator_uF", "capacitance of the actuator stack(s), uF"}};
  }
  return {};
}

namespace {

// The number a capacitance field holds (uF), or InputError.
double capacitance_uF(const PhaseSpec& phase, const std::string& field, const std::string& text) {
  try {
    std::size_t used = 0;
    const double x = std::stod(text, &used);
    if (used == text.size() && x > 0.0 && std::isfinite(x)) return x;
  } catch (const std::exception&) {
    // refused below
  }
  throw InputError("operator", phase.name + "." + field, "a capacitance > 0 in uF", "'" + text + "'");
}

}  // namespace

void check_typed_value(const PhaseSpec& phase, const std::string& field, const std::string& text) {
  if (field == "file") {
    if (text.empty()) throw InputError("operator", phase.name, "the file of the phase", "nothing");
  } else {
    (void)capacitance_uF(phase, field, text);
  }
}

PhaseValues typed_values(const PhaseSpec& phase, const std::map<std::string, std::string>& typed) {
  const auto text = [&](const std::string& field) {
    const auto it = typed.find(field);
    return it == typed.end() ? std::string() : it->second;
  };
  PhaseValues v;
  if (phase.source == ValueSource::kFile) {
    check_typed_value(phase, "file", text("file"));
    v.file = text("file");
  } else if (phase.source == ValueSource::kTyped) {
    v.sensor_uF = capacitance_uF(phase, "sensor_uF", text("sensor_uF"));
    v.actuator_uF = capacitance_uF(phase, "actuator_uF", text("actuator_uF"));
  }
  return v;
}

PhaseValues TerminalOperator::values(const PhaseSpec& phase) {
  std::map<std::string, std::string> typed;
  for (const TypedValueField& f : typed_value_fields(phase)) {
    typed[f.name] = ask(fmt::format("operator, phase {}: {}: ", phase.name, f.question));
    check_typed_value(phase, f.name, typed[f.name]);  // refused at once, before the next question
  }
  return typed_values(phase, typed);
}

}  // namespace piezobench::station
