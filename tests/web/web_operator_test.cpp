#include "piezobench/web/web_operator.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace piezobench::web {
namespace {

using namespace std::chrono_literals;

station::PhaseSpec phase_with_step() {
  station::PhaseSpec p;
  p.name = "stroke", p.experiment = "stroke";
  p.steps = {"mount the actuator"};
  return p;
}

// Answers the hub's next prompt from "the page" once it is open.
std::thread page_answers(LiveHub& hub, const std::string& choice) {
  return std::thread([&hub, choice] {
    for (int i = 0; i < 400; ++i) {
      const nlohmann::json s = nlohmann::json::parse(hub.state_json());
      if (!s["prompt"].is_null()) {
        EXPECT_EQ(hub.answer(s["prompt"]["id"].get<std::uint64_t>(), choice).status, AnswerResult::Status::kTaken);
        return;
      }
      std::this_thread::sleep_for(5ms);
    }
    ADD_FAILURE() << "no prompt opened";
  });
}

struct Pipe {
  int fd[2] = {-1, -1};
  Pipe() { EXPECT_EQ(::pipe(fd), 0); }
  ~Pipe() {
    ::close(fd[0]);
    if (fd[1] >= 0) ::close(fd[1]);
  }
};

TEST(WebOperator, ThePagesAnswerHasTheTerminalsEffect) {
  LiveHub hub;
  Pipe terminal;  // nothing typed
  std::ostringstream out;
  WebOperatorOptions o;
  o.terminal_fd = terminal.fd[0], o.terminal_out = &out;
  WebOperator op(hub, std::move(o));
  std::thread page = page_answers(hub, "abort");
  EXPECT_EQ(op.step(phase_with_step(), 0), station::StepAnswer::kAbort);
  page.join();
  page = page_answers(hub, "retry");
  EXPECT_EQ(op.check_failed(phase_with_step(), 1, "saturation"), station::CheckAnswer::kRetry);
  page.join();
  EXPECT_NE(out.str().find("phase stroke (1/1): mount the actuator"), std::string::npos);
  EXPECT_NE(out.str().find("[r] retry, [c] continue, [a] abort"), std::string::npos);
  EXPECT_TRUE(nlohmann::json::parse(hub.state_json())["prompt"].is_null());  // closed once answered
}

TEST(WebOperator, TheTerminalAnswersTooAndItsEndLeavesThePage) {
  LiveHub hub;
  Pipe terminal;
  std::ostringstream out;
  WebOperatorOptions o;
  o.terminal_fd = terminal.fd[0], o.terminal_out = &out;
  WebOperator op(hub, std::move(o));
  ASSERT_EQ(::write(terminal.fd[1], "x\nc\n", 4), 4);  // a stray key, then continue
  EXPECT_EQ(op.check_failed(phase_with_step(), 1, "coherence"), station::CheckAnswer::kContinue);
  ASSERT_EQ(::write(terminal.fd[1], "y\n", 2), 2);
  EXPECT_EQ(op.step(phase_with_step(), 0), station::StepAnswer::kConfirm);
  ::close(terminal.fd[1]);
  terminal.fd[1] = -1;  // end of input: the page answers alone (not an abort)
  std::thread page = page_answers(hub, "confirm");
  EXPECT_EQ(op.step(phase_with_step(), 0), station::StepAnswer::kConfirm);
  page.join();
}

station::PhaseSpec typed_capacitance() {
  station::PhaseSpec p;
  p.name = "capacitance", p.experiment = "capacitance", p.source = station::ValueSource::kTyped;
  return p;
}

// The refusal of a typed value: the terminal's (TerminalOperator's InputError) text.
std::string terminal_refusal(const station::PhaseSpec& p, const std::string& lines) {
  std::istringstream in(lines);
  std::ostringstream out;
  station::TerminalOperator t(in, out, "op");
  try {
    (void)t.values(p);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "accepted";
}

// Typed values in the page: one field each; a bad value is refused with the terminal's words and
// the prompt stays open; good values have the terminal's effect.
TEST(WebOperator, TypedValuesInThePageAreCheckedAsOnTheTerminal) {
  LiveHub hub;
  std::ostringstream out;
  WebOperatorOptions o;
  o.terminal_fd = -1, o.terminal_out = &out;
  WebOperator op(hub, std::move(o));
  std::thread page([&hub] {
    for (int i = 0; i < 400; ++i) {
      const nlohmann::json s = nlohmann::json::parse(hub.state_json());
      if (!s["prompt"].is_null()) {
        const auto id = s["prompt"]["id"].get<std::uint64_t>();
        EXPECT_EQ(s["prompt"]["fields"].size(), 2u);
        EXPECT_EQ(s["prompt"]["fields"][0]["name"], "sensor_uF");
        const AnswerResult bad = hub.answer(id, "confirm", {{"sensor_uF", "-1"}, {"actuator_uF", "10.1"}});
        EXPECT_EQ(bad.status, AnswerResult::Status::kRefused);
        EXPECT_EQ(bad.message, terminal_refusal(typed_capacitance(), "-1\n10.1\n"));
        EXPECT_EQ(hub.answer(id, "confirm", {{"sensor_uF", "5.2"}}).status, AnswerResult::Status::kRefused);  // actuator missing
        EXPECT_EQ(hub.answer(id, "confirm", {{"sensor_uF", "5.2"}, {"actuator_uF", "10.1"}}).status, AnswerResult::Status::kTaken);
        return;
      }
      std::this_thread::sleep_for(5ms);
    }
    ADD_FAILURE() << "no prompt opened";
  });
  const station::PhaseValues v = op.values(typed_capacitance());
  page.join();
  ASSERT_TRUE(v.sensor_uF && v.actuator_uF);
  EXPECT_DOUBLE_EQ(*v.sensor_uF, 5.2);
  EXPECT_DOUBLE_EQ(*v.actuator_uF, 10.1);
  // The terminal gives the same values, line by line, and refuses a bad line as TerminalOperator does.
  Pipe terminal;
  WebOperatorOptions t;
  t.terminal_fd = terminal.fd[0], t.terminal_out = &out;
  WebOperator typed(hub, std::move(t));
  ASSERT_EQ(::write(terminal.fd[1], "5.2\n10.1\n", 9), 9);
  const station::PhaseValues w = typed.values(typed_capacitance());
  EXPECT_DOUBLE_EQ(*w.sensor_uF, 5.2);
  EXPECT_DOUBLE_EQ(*w.actuator_uF, 10.1);
  ASSERT_EQ(::write(terminal.fd[1], "abc\n", 4), 4);
  try {
    (void)typed.values(typed_capacitance());
    ADD_FAILURE() << "accepted abc";
  } catch (const std::exception& e) {
    EXPECT_EQ(std::string(e.what()), terminal_refusal(typed_capacitance(), "abc\n"));
  }
  EXPECT_TRUE(nlohmann::json::parse(hub.state_json())["prompt"].is_null());
}

TEST(WebOperator, CtrlCWhileWaitingAborts) {
  LiveHub hub;
  std::atomic<bool> stop{false};
  WebOperatorOptions o;
  o.terminal_fd = -1, o.stop = &stop;
  std::ostringstream out;
  o.terminal_out = &out;
  WebOperator op(hub, std::move(o));
  std::thread ctrl_c([&] {
    std::this_thread::sleep_for(50ms);
    stop = true;
  });
  EXPECT_EQ(op.check_failed(phase_with_step(), 1, "lost samples"), station::CheckAnswer::kAbort);
  ctrl_c.join();
}

}  // namespace
}  // namespace piezobench::web
