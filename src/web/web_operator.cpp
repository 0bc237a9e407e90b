// The operator of a qualification followed in the page (web_operator.hpp): prompts answered in the
// page or on the terminal, whichever answers first.
#include "piezobench/web/web_operator.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <iostream>
#include <map>

#include "piezobench/core/error.hpp"

namespace piezobench::web {

namespace {

std::string key_of(const std::string& choice) { return choice == "confirm" ? "y" : choice.substr(0, 1); }

}  // namespace

WebOperator::WebOperator(LiveHub& hub, WebOperatorOptions options) : hub_(hub), options_(std::move(options)) {
  if (!options_.terminal_out) options_.terminal_out = &std::cerr;
}

std::string WebOperator::name() const { return options_.inner ? options_.inner->name() : options_.name; }

// A line typed on the terminal when one is complete; nothing otherwise (never blocks). The end of
// the input turns the terminal off.
std::optional<std::string> WebOperator::terminal_line() {
  if (options_.terminal_fd < 0) return std::nullopt;
  for (;;) {
    if (const std::size_t nl = pending_.find('\n'); nl != std::string::npos) {
      std::string line = pending_.substr(0, nl);
      pending_.erase(0, nl + 1);
      return line;
    }
    pollfd p{options_.terminal_fd, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) return std::nullopt;
    char buf[256];
    const ssize_t n = ::read(options_.terminal_fd, buf, sizeof buf);
    if (n <= 0) {
      options_.terminal_fd = -1;  // end of input: the page answers alone
      return std::nullopt;
    }
    pending_.append(buf, static_cast<std::size_t>(n));
    if (pending_.size() > 4096) pending_.clear();  // no line: typing noise
  }
}

std::string WebOperator::ask(const std::string& phase, const std::string& text, const std::vector<std::string>& choices) {
  const std::uint64_t id = hub_.open_prompt(phase, text, choices);
  std::string keys;
  for (const auto& c : choices) keys += fmt::format("{}[{}] {}", keys.empty() ? "" : ", ", key_of(c), c);
  *options_.terminal_out << fmt::format("operator, {} ({}; or answer in the page): ", text, keys) << std::flush;
  for (;;) {
    if (options_.stop && options_.stop->load()) {
      hub_.close_prompt(id);
      return "abort";
    }
    if (const auto a = hub_.wait_answer(id, std::chrono::milliseconds(50))) {
      hub_.close_prompt(id);
      *options_.terminal_out << fmt::format("{} (answered in the page)\n", *a) << std::flush;
      return *a;
    }
    if (const auto line = terminal_line()) {
      for (const auto& c : choices) {
        if (*line == key_of(c) || *line == c) {
          hub_.close_prompt(id);
          return c;
        }
      }
    }
  }
}

station::StepAnswer WebOperator::step(const station::PhaseSpec& phase, std::size_t index) {
  if (options_.inner) return options_.inner->step(phase, index);
  const std::string a = ask(phase.name, fmt::format("phase {} ({}/{}): {}", phase.name, index + 1, phase.steps.size(), phase.steps[index]),
                            {"confirm", "abort"});
  return a == "confirm" ? station::StepAnswer::kConfirm : station::StepAnswer::kAbort;
}

station::CheckAnswer WebOperator::check_failed(const station::PhaseSpec& phase, int try_number, const std::string& why) {
  if (options_.inner) return options_.inner->check_failed(phase, try_number, why);
  const std::string a = ask(phase.name, fmt::format("phase {} try {} failed its checks: {}", phase.name, try_number, why),
                            {"retry", "continue", "abort"});
  return a == "retry" ? station::CheckAnswer::kRetry : a == "continue" ? station::CheckAnswer::kContinue : station::CheckAnswer::kAbort;
}

station::PhaseValues WebOperator::values(const station::PhaseSpec& phase) {
  if (options_.inner) return options_.inner->values(phase);
  const std::vector<station::TypedValueField> fields = station::typed_value_fields(phase);
  if (fields.empty()) return {};
  // The page: one prompt with every field, refused there as the terminal refuses; the terminal:
  // the fields one by one, as TerminalOperator asks them. The first complete answer is taken.
  const std::uint64_t id = hub_.open_prompt(phase.name, fmt::format("phase {}: type the values", phase.name), {"confirm"}, fields,
                                            [phase](const std::map<std::string, std::string>& typed) { station::typed_values(phase, typed); });
  std::map<std::string, std::string> typed;
  std::size_t next = 0;
  const auto question = [&] {
    *options_.terminal_out << fmt::format("operator, phase {}: {} (or type it in the page): ", phase.name, fields[next].question) << std::flush;
  };
  question();
  for (;;) {
    if (options_.stop && options_.stop->load()) {
      hub_.close_prompt(id);
      throw InputError("operator", phase.name, "the typed values", "Ctrl-C");
    }
    std::map<std::string, std::string> from_page;
    if (hub_.wait_answer(id, std::chrono::milliseconds(50), &from_page)) {
      hub_.close_prompt(id);
      *options_.terminal_out << "(typed in the page)\n" << std::flush;
      return station::typed_values(phase, from_page);
    }
    if (const auto line = terminal_line()) {
      typed[fields[next].name] = *line;
      try {
        station::check_typed_value(phase, fields[next].name, *line);  // refused at once, as on the terminal
      } catch (...) {
        hub_.close_prompt(id);
        throw;
      }
      if (++next == fields.size()) {
        hub_.close_prompt(id);
        return station::typed_values(phase, typed);
      }
      question();
    }
  }
}

}  // namespace piezobench::web
