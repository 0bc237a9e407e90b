#pragma once
// The live state of one qualification, as the station's page shows it (docs/station.md, "The live
// page"): the phases with their states and times, the operator's open prompt, the verdict table,
// the signals decimated to the screen rate, and the FRF and coherence being built up average by
// average during the FRF phases.
//
// Producers never wait on the web: the phase runner's Observer calls and record() take the hub's
// lock only to append (no I/O, no serialisation); a feeder thread of the hub releases each
// record's screen samples when their measurement time has come (a paced virtual bench: sample k
// of a record that started at T0 is measured at T0 + k / rate; hardware and unpaced records are
// past when they arrive) and builds the FRF's averages. On hardware the signals come sooner, while
// each record runs, from the loop's log tap (loop_tap(): the loop's logger thread forms the screen
// samples and appends each one as soon as its block has been measured). Clients read through a Mailbox: each call
// of next() gives what changed since that client's previous call (the newest state, the screen
// samples it has not had, bounded to the last window_s seconds, the newest FRF), so a slow client
// skips states and never makes anything queue.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/logger.hpp"
#include "piezobench/station/phase_runner.hpp"
#include "piezobench/web/http_server.hpp"

namespace piezobench::web {

struct LiveHubOptions {
  double screen_rate_Hz = 20.0;  // screen samples per second of signal (10..20 for a page)
  double window_s = 30.0;        // screen samples kept (and sent at most) per client
  int frf_points = 240;          // log-spaced frequencies of the FRF sent to the page
  double frf_min_Hz = 5.0, frf_max_Hz = 2000.0;
};

// One screen sample: a block of 1 / screen_rate_Hz seconds of the record, per channel its
// minimum, maximum and last value (Va [V], d_e [um], Vs [V]).
struct ScreenSample {
  std::uint64_t seq = 0;
  std::string phase;
  int try_number = 0;
  double t_s = 0.0;               // the block's first sample, s into the record
  double measured_unix_ms = 0.0;  // wall time (ms since 1970) its first sample was measured
  double va[3] = {0, 0, 0}, de_um[3] = {0, 0, 0}, vs[3] = {0, 0, 0};  // min, max, last
};

// An operator prompt open on the page.
struct LivePrompt {
  std::uint64_t id = 0;
  std::string phase, text;
  std::vector<std::string> choices;  // "confirm", "abort", "retry", "continue"
  std::vector<station::TypedValueField> fields;  // values to type with the answer (capacitance, a file)
};

// The page's answer to a prompt: taken, or why not.
struct AnswerResult {
  enum class Status { kTaken, kNotOpen, kRefused } status = Status::kTaken;
  std::string message;  // kRefused: the refusal, as the terminal words it (the InputError's text)
};
// Checks a prompt's typed values (throws InputError to refuse them).
using ValuesCheck = std::function<void(const std::map<std::string, std::string>& typed)>;

class LiveHub final : public station::Observer {
 public:
  explicit LiveHub(LiveHubOptions options = {});
  ~LiveHub() override;  // stops the feeder
  LiveHub(const LiveHub&) = delete;
  LiveHub& operator=(const LiveHub&) = delete;

  // The qualification about to run: its phases (all waiting), expected durations per phase name
  // (s, from an earlier qualification; absent: unknown).
  void plan(const station::StationFile& station, const std::string& serial, const std::string& batch,
            const std::map<std::string, double>& expected_s = {});
  // The qualification's end: status (complete, aborted, failed) and whether a certificate exists.
  void finished(const std::string& status, bool certificate);

  // station::Observer (the runner's thread; never blocks beyond the hub's lock).
  void phase_started(const std::string& serial, const station::PhaseSpec& phase, int try_number) override;
  void phase_finished(const std::string& serial, const station::PhaseTryRow& result) override;
  void prompt(const std::string& serial, const std::string& text) override;
  void verdict(const std::string& serial, station::Verdict verdict, const std::string& phase, const std::string& measurement) override;

  // A record of the running phase (channels t, u, Va, de, Vs as the bench writes them) whose first
  // sample was measured at `start`; decimated here, released by the feeder as its time comes.
  void record(const io::TimeSeries& record, std::chrono::steady_clock::time_point start);

  // The live signals of a hardware bench (station::BenchInstrumentOptions::live_tap, rt::LogTap):
  // about 1,000 of the loop's records per second of its `loop_rate_Hz` (every N-th), formed into
  // screen samples on the loop's logger thread and appended as each block ends; the record
  // given to record() afterwards then only feeds the FRF and the phase's length.
  [[nodiscard]] rt::LogTap loop_tap(double loop_rate_Hz);

  // Prompts (web_operator.hpp): open one, wait for the page's answer, close it.
  // A prompt with `fields` takes their typed texts with its answer, checked by `check` on the
  // answering (server's) thread, outside the hub's lock.
  std::uint64_t open_prompt(const std::string& phase, const std::string& text, std::vector<std::string> choices,
                            std::vector<station::TypedValueField> fields = {}, ValuesCheck check = {});
  // The page's answer to prompt `id`: kNotOpen when it is not the open prompt or not one of its
  // choices; kRefused (the prompt stays open) when `check` refuses the typed values.
  AnswerResult answer(std::uint64_t id, const std::string& choice, const std::map<std::string, std::string>& typed = {});
  // The answer to `id` when one came within `timeout`; with its typed values in `typed`.
  std::optional<std::string> wait_answer(std::uint64_t id, std::chrono::milliseconds timeout,
                                         std::map<std::string, std::string>* typed = nullptr);
  void close_prompt(std::uint64_t id);

  // The whole state (phases, prompt, verdicts) as JSON text.
  [[nodiscard]] std::string state_json() const;
  // A client's mailbox (an EventStream for the server): each next() gives a JSON object with
  // "state" when it changed, "samples" the client has not had, "frf" when it changed.
  [[nodiscard]] std::unique_ptr<EventStream> mailbox();

  [[nodiscard]] std::uint64_t samples_released() const;

  struct Pending;
  struct Frf;
  struct Tap;

 private:
  class Client;
  void feed();
  void release_due(std::chrono::steady_clock::time_point now);
  void append_live(Tap& tap);
  void bump() { ++state_version_; }
  [[nodiscard]] std::string state_json_locked() const;

  LiveHubOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable answered_;
  // State (guarded by mutex_).
  std::string serial_, batch_, station_, status_ = "waiting", verdict_, deciding_phase_, deciding_measurement_;
  bool certificate_ = false;
  double started_unix_ms_ = 0.0, finished_unix_ms_ = 0.0;
  struct PhaseState;
  std::vector<PhaseState> phases_;
  std::optional<LivePrompt> prompt_;
  std::uint64_t next_prompt_id_ = 1;
  ValuesCheck prompt_check_;
  struct Answer {
    std::uint64_t id = 0;
    std::string choice;
    std::map<std::string, std::string> typed;
  };
  std::optional<Answer> answer_;
  std::string last_message_;
  std::uint64_t state_version_ = 1;
  std::deque<ScreenSample> samples_;
  std::uint64_t next_seq_ = 1;
  std::unique_ptr<Pending> pending_;  // the record being released
  std::pair<std::string, int> live_shown_{"", -1};  // the phase try whose signals came from a loop tap
  std::unique_ptr<Frf> frf_;
  std::string frf_json_;
  std::uint64_t frf_version_ = 0;
  // The feeder.
  bool stop_ = false;
  std::condition_variable wake_;
  std::thread feeder_;
};

}  // namespace piezobench::web
