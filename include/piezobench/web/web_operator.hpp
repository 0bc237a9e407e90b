#pragma once
// The operator of a qualification followed in the station's page (`qualify --ui`): each prompt is
// shown in the page as buttons (confirm / abort; after a failed check retry / continue / abort) and
// on the terminal as TerminalOperator shows it; the first answer from either side is taken, with
// the same effect. The end of the terminal's input leaves the page alone to answer (a station run
// in the background). With an answers file (`inner`), the file answers and the page only shows.
// Typed values and files (capacitance, flatness) are asked in the page (a field each, checked and
// refused as the terminal refuses them, the prompt staying open) and on the terminal (one line
// each; a bad line refused as TerminalOperator refuses it), or the answers file gives them.
#include <atomic>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "piezobench/station/phase_runner.hpp"
#include "piezobench/web/live_hub.hpp"

namespace piezobench::web {

struct WebOperatorOptions {
  std::unique_ptr<station::Operator> inner;  // an answers file's operator, or null: page and terminal
  int terminal_fd = 0;                       // the terminal's answers (stdin); -1: the page only
  std::ostream* terminal_out = nullptr;      // the prompts (stderr when null)
  std::string name;                          // the operator's name without an answers file
  const std::atomic<bool>* stop = nullptr;   // Ctrl-C while waiting: abort
};

class WebOperator final : public station::Operator {
 public:
  WebOperator(LiveHub& hub, WebOperatorOptions options);
  station::StepAnswer step(const station::PhaseSpec& phase, std::size_t index) override;
  station::CheckAnswer check_failed(const station::PhaseSpec& phase, int try_number, const std::string& why) override;
  station::PhaseValues values(const station::PhaseSpec& phase) override;
  [[nodiscard]] std::string name() const override;

 private:
  // The chosen word ("confirm", "abort", "retry", "continue"): from the page, or the terminal's
  // key (first letter: y for confirm).
  std::string ask(const std::string& phase, const std::string& text, const std::vector<std::string>& choices);
  std::optional<std::string> terminal_line();
  LiveHub& hub_;
  WebOperatorOptions options_;
  std::string pending_;  // bytes read from the terminal, not yet a line
};

}  // namespace piezobench::web
