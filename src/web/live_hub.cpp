// The live state of a qualification (live_hub.hpp): the runner appends, a feeder thread releases
// screen samples at their measurement time and builds the FRF, clients read through mailboxes.
#include "piezobench/web/live_hub.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "piezobench/dsp/welch.hpp"

namespace piezobench::web {

namespace {

using Clock = std::chrono::steady_clock;

double unix_ms(std::chrono::system_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(t.time_since_epoch()).count();
}
double now_unix_ms() { return unix_ms(std::chrono::system_clock::now()); }

// Wall time of a steady-clock instant (the two clocks read once, now).
double unix_ms_of(Clock::time_point t) {
  const auto sys = std::chrono::system_clock::now();
  const auto steady = Clock::now();
  return unix_ms(sys) - std::chrono::duration<double, std::milli>(steady - t).count();
}

nlohmann::json number_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
nlohmann::json optional_number(const std::optional<double>& x) { return x ? number_or_null(*x) : nlohmann::json(nullptr); }

int channel_index(const io::TimeSeries& ts, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    const auto it = std::find(ts.names.begin(), ts.names.end(), n);
    if (it != ts.names.end()) return static_cast<int>(it - ts.names.begin());
  }
  return -1;
}

}  // namespace

struct LiveHub::PhaseState {
  std::string name, experiment, state = "waiting", verdict, reason;
  int tries = 0;
  double started_ms = 0.0, finished_ms = 0.0, record_s = 0.0;
  std::optional<double> expected_s;
  std::vector<station::MeasurementRow> measurements;
};

// The FRF phase's record (input u, output d_e) and the averages already computed.
struct LiveHub::Frf {
  std::string phase;
  Eigen::VectorXd u, de;
  double sample_rate = 0.0;
  dsp::WelchOptions welch;
  Eigen::Index averages = 0;
};

// The record being released: its screen samples and when each is due.
struct LiveHub::Pending {
  std::vector<ScreenSample> blocks;
  std::vector<Clock::time_point> due;
  std::size_t next = 0;
  Eigen::Index block_samples = 1;
  bool shown = false;  // its signals came from a loop tap while it ran
  std::shared_ptr<Frf> frf;
};

// A loop tap's screen samples in the making (the loop's logger thread alone touches it; the runs
// of a record follow each other, each logger thread joined before the next starts).
struct LiveHub::Tap {
  std::size_t block_records = 1;  // tapped records per screen sample
  double last_t = -1.0;           // the newest record's time in its run, s
  ScreenSample block;             // the screen sample being formed
  std::int64_t block_ns = 0;      // when its first record was measured
  std::size_t in_block = 0;
  std::vector<std::pair<ScreenSample, std::int64_t>> ready;  // complete, to append
  std::pair<std::string, int> shown{"", -1};                 // the phase try being shown
  std::int64_t record_ns = 0;                                // and its first sample's time

  void add(const rt::LogRecord& r, std::int64_t ns) {
    const double v[3] = {r.va, 1e6 * r.de, r.vs};
    double* out[3] = {block.va, block.de_um, block.vs};
    if (in_block == 0) {
      block_ns = ns;
      for (int c = 0; c < 3; ++c) out[c][0] = out[c][1] = v[c];
    }
    for (int c = 0; c < 3; ++c) {
      out[c][0] = std::min(out[c][0], v[c]), out[c][1] = std::max(out[c][1], v[c]), out[c][2] = v[c];
    }
    if (++in_block == block_records) close();
  }
  void close() {
    if (in_block == 0) return;
    block.measured_unix_ms = unix_ms_of(Clock::time_point(std::chrono::nanoseconds(block_ns)));
    ready.emplace_back(block, block_ns);
    in_block = 0;
  }
};

class LiveHub::Client final : public EventStream {
 public:
  explicit Client(LiveHub& hub) : hub_(hub) {}
  std::optional<std::string> next() override;

 private:
  LiveHub& hub_;
  std::uint64_t state_version_ = 0, seq_ = 0, frf_version_ = 0;
};

LiveHub::LiveHub(LiveHubOptions options) : options_(options) {
  feeder_ = std::thread([this] { feed(); });
}

LiveHub::~LiveHub() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  answered_.notify_all();
  if (feeder_.joinable()) feeder_.join();
}

void LiveHub::plan(const station::StationFile& station, const std::string& serial, const std::string& batch,
                   const std::map<std::string, double>& expected_s) {
  std::lock_guard lock(mutex_);
  serial_ = serial, batch_ = batch, station_ = station.name;
  phases_.clear();
  for (const station::PhaseSpec& p : station.phases) {
    PhaseState s;
    s.name = p.name, s.experiment = p.experiment;
    if (const auto it = expected_s.find(p.name); it != expected_s.end()) s.expected_s = it->second;
    phases_.push_back(std::move(s));
  }
  status_ = "running";
  started_unix_ms_ = now_unix_ms();
  bump();
}

void LiveHub::finished(const std::string& status, bool certificate) {
  std::lock_guard lock(mutex_);
  status_ = status, certificate_ = certificate;
  finished_unix_ms_ = now_unix_ms();
  bump();
}

void LiveHub::phase_started(const std::string&, const station::PhaseSpec& phase, int try_number) {
  std::lock_guard lock(mutex_);
  for (PhaseState& s : phases_) {
    if (s.name != phase.name) continue;
    s.state = try_number > 1 ? "retried" : "running";
    s.tries = try_number;
    s.started_ms = now_unix_ms(), s.finished_ms = 0.0, s.record_s = 0.0;
    s.reason.clear();
  }
  last_message_.clear();  // the operator's step was answered
  bump();
}

void LiveHub::phase_finished(const std::string&, const station::PhaseTryRow& row) {
  std::lock_guard lock(mutex_);
  for (PhaseState& s : phases_) {
    if (s.name != row.phase_name) continue;
    if (row.status == "complete") {
      s.state = row.verdict == "pass" ? "passed" : row.verdict == "marginal" ? "marginal" : "failed";
    } else {
      s.state = "failed";
    }
    s.finished_ms = now_unix_ms();
    s.verdict = row.verdict, s.reason = row.reason, s.measurements = row.measurements;
  }
  bump();
}

void LiveHub::prompt(const std::string&, const std::string& text) {
  std::lock_guard lock(mutex_);
  last_message_ = text;
  bump();
}

void LiveHub::verdict(const std::string&, station::Verdict v, const std::string& phase, const std::string& measurement) {
  std::lock_guard lock(mutex_);
  verdict_ = station::to_string(v), deciding_phase_ = phase, deciding_measurement_ = measurement;
  bump();
}

void LiveHub::record(const io::TimeSeries& ts, Clock::time_point start) {
  auto p = std::make_unique<Pending>();
  const double fs = ts.sample_rate;
  const Eigen::Index n = ts.samples();
  if (!(fs > 0.0) || n == 0) return;
  p->block_samples = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::llround(fs / options_.screen_rate_Hz)));
  const int va = channel_index(ts, {"Va"}), de = channel_index(ts, {"de", "d_e"}), vs = channel_index(ts, {"Vs"}),
            u = channel_index(ts, {"u"});
  const double start_ms = unix_ms_of(start);
  const auto experiment = ts.settings.find("experiment");
  const std::string kind = experiment != ts.settings.end() && std::holds_alternative<std::string>(experiment->second)
                               ? std::get<std::string>(experiment->second) : "";
  std::string phase;
  int try_number = 0;
  {
    std::lock_guard lock(mutex_);
    for (PhaseState& s : phases_) {
      if (s.state == "running" || s.state == "retried") {
        phase = s.name, try_number = s.tries;
        s.record_s = static_cast<double>(n) / fs;
      }
    }
    p->shown = live_shown_ == std::pair<std::string, int>{phase, try_number};
    bump();
  }
  for (Eigen::Index k0 = 0; k0 < n; k0 += p->block_samples) {
    const Eigen::Index k1 = std::min(n, k0 + p->block_samples);
    ScreenSample s;
    s.phase = phase, s.try_number = try_number;
    s.t_s = static_cast<double>(k0) / fs;
    s.measured_unix_ms = start_ms + 1e3 * s.t_s;
    const auto fill = [&](int c, double* out, double scale) {
      if (c < 0) {
        out[0] = out[1] = out[2] = std::numeric_limits<double>::quiet_NaN();
        return;
      }
      const auto block = ts.data.col(c).segment(k0, k1 - k0);
      out[0] = scale * block.minCoeff(), out[1] = scale * block.maxCoeff(), out[2] = scale * block(block.size() - 1);
    };
    fill(va, s.va, 1.0), fill(de, s.de_um, 1e6), fill(vs, s.vs, 1.0);
    p->blocks.push_back(std::move(s));
    p->due.push_back(start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(static_cast<double>(k1 - 1) / fs)));
  }
  if ((kind == "frf-noise" || kind == "iff") && u >= 0 && de >= 0) {
    auto f = std::make_shared<Frf>();
    f->phase = phase, f->u = ts.data.col(u), f->de = ts.data.col(de), f->sample_rate = fs;
    f->welch = dsp::welch_options_for_record(n, fs);
    f->welch.threads = 1;
    f->welch.detrend = dsp::Detrend::kMean;
    p->frf = std::move(f);
  }
  {
    std::lock_guard lock(mutex_);
    release_due(Clock::time_point::max());  // whatever is left of the previous record
    pending_ = std::move(p);
    if (pending_->frf) {
      frf_json_ = nlohmann::json{{"phase", phase}, {"averages", 0}}.dump();
      ++frf_version_;
    }
  }
  wake_.notify_all();
}

rt::LogTap LiveHub::loop_tap(double loop_rate_Hz) {
  rt::LogTap tap;
  tap.every = static_cast<std::size_t>(std::max<long long>(1, std::llround(loop_rate_Hz / 1000.0)));
  auto state = std::make_shared<Tap>();
  const double tapped_Hz = loop_rate_Hz / static_cast<double>(tap.every);
  state->block_records = static_cast<std::size_t>(std::max<long long>(1, std::llround(tapped_Hz / options_.screen_rate_Hz)));
  tap.deliver = [this, state](std::span<const rt::LogRecord> records) {
    Tap& t = *state;
    for (const rt::LogRecord& r : records) {
      if (r.t < t.last_t) t.close();  // a new loop run: its blocks start afresh
      t.last_t = r.t;
      t.add(r, r.measured_ns);
    }
    if (records.empty()) {  // the run is over: its last, shorter block
      t.close();
      t.last_t = -1.0;
    }
    if (!t.ready.empty()) append_live(t);
  };
  return tap;
}

void LiveHub::append_live(Tap& tap) {
  const std::size_t keep = static_cast<std::size_t>(std::ceil(options_.window_s * options_.screen_rate_Hz));
  std::lock_guard lock(mutex_);
  std::pair<std::string, int> running{"", 0};
  for (const PhaseState& p : phases_) {
    if (p.state == "running" || p.state == "retried") running = {p.name, p.tries};
  }
  if (running != tap.shown) {
    tap.shown = running;
    tap.record_ns = tap.ready.front().second;
  }
  live_shown_ = running;
  for (auto& [block, ns] : tap.ready) {
    block.phase = running.first, block.try_number = running.second;
    block.t_s = static_cast<double>(ns - tap.record_ns) * 1e-9;
    block.seq = next_seq_++;
    samples_.push_back(std::move(block));
    if (samples_.size() > keep) samples_.pop_front();
  }
  tap.ready.clear();
}

void LiveHub::release_due(Clock::time_point now) {
  if (!pending_) return;
  const std::size_t keep = static_cast<std::size_t>(std::ceil(options_.window_s * options_.screen_rate_Hz));
  while (pending_->next < pending_->blocks.size() && pending_->due[pending_->next] <= now) {
    ScreenSample s = std::move(pending_->blocks[pending_->next++]);
    if (pending_->shown) continue;  // the loop's tap has shown these signals already
    s.seq = next_seq_++;
    samples_.push_back(std::move(s));
    if (samples_.size() > keep) samples_.pop_front();
  }
}

void LiveHub::feed() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    release_due(Clock::now());
    // The FRF: one more average whenever the released samples hold one more segment.
    std::shared_ptr<Frf> f = pending_ ? pending_->frf : nullptr;
    if (f) {
      const Eigen::Index released = std::min<Eigen::Index>(f->u.size(), static_cast<Eigen::Index>(pending_->next) * pending_->block_samples);
      const Eigen::Index nfft = f->welch.nfft, step = nfft - f->welch.noverlap();
      const Eigen::Index segments = released < nfft ? 0 : 1 + (released - nfft) / step;
      if (segments > f->averages) {
        f->averages = segments;
        lock.unlock();
        const Eigen::Index used = nfft + (segments - 1) * step;
        const dsp::CrossSpectra cs = dsp::cross_spectra({"u", std::span<const double>(f->u.data(), used)},
                                                        {{"de", std::span<const double>(f->de.data(), used)}}, f->sample_rate, f->welch);
        const Eigen::VectorXd coh = dsp::coherence(cs, 0);
        nlohmann::json freq = nlohmann::json::array(), mag = nlohmann::json::array(), cohj = nlohmann::json::array();
        const double fmax = std::min(options_.frf_max_Hz, f->sample_rate / 2);
        Eigen::Index last = -1;
        for (int i = 0; i < options_.frf_points; ++i) {
          const double target = options_.frf_min_Hz * std::pow(fmax / options_.frf_min_Hz, i / (options_.frf_points - 1.0));
          const Eigen::Index k = std::min<Eigen::Index>(cs.freq_Hz.size() - 1, std::llround(target / (f->sample_rate / static_cast<double>(nfft))));
          if (k <= last || k < 1) continue;
          last = k;
          freq.push_back(cs.freq_Hz(k));
          mag.push_back(number_or_null(1e6 * std::abs(cs.Suy[0](k)) / cs.Suu(k)));
          cohj.push_back(number_or_null(coh(k)));
        }
        std::string text = nlohmann::json{{"phase", f->phase}, {"averages", segments}, {"f_Hz", freq}, {"mag_um_per_V", mag}, {"coherence", cohj}}.dump();
        lock.lock();
        if (pending_ && pending_->frf == f) {
          frf_json_ = std::move(text);
          ++frf_version_;
        }
        continue;
      }
    }
    wake_.wait_for(lock, std::chrono::milliseconds(10));
  }
}

std::uint64_t LiveHub::open_prompt(const std::string& phase, const std::string& text, std::vector<std::string> choices,
                                   std::vector<station::TypedValueField> fields, ValuesCheck check) {
  std::lock_guard lock(mutex_);
  prompt_ = LivePrompt{next_prompt_id_++, phase, text, std::move(choices), std::move(fields)};
  prompt_check_ = std::move(check);
  answer_.reset();
  bump();
  return prompt_->id;
}

AnswerResult LiveHub::answer(std::uint64_t id, const std::string& choice, const std::map<std::string, std::string>& typed) {
  const auto open = [&] {
    return prompt_ && prompt_->id == id && !answer_ &&
           std::find(prompt_->choices.begin(), prompt_->choices.end(), choice) != prompt_->choices.end();
  };
  ValuesCheck check;
  {
    std::lock_guard lock(mutex_);
    if (!open()) return {AnswerResult::Status::kNotOpen, "not the open prompt, or not one of its answers"};
    if (!prompt_->fields.empty() && choice != "abort") check = prompt_check_;
  }
  if (check) {
    try {
      check(typed);
    } catch (const std::exception& e) {
      return {AnswerResult::Status::kRefused, e.what()};
    }
  }
  {
    std::lock_guard lock(mutex_);
    if (!open()) return {AnswerResult::Status::kNotOpen, "not the open prompt, or not one of its answers"};
    answer_ = Answer{id, choice, typed};
  }
  answered_.notify_all();
  return {};
}

std::optional<std::string> LiveHub::wait_answer(std::uint64_t id, std::chrono::milliseconds timeout, std::map<std::string, std::string>* typed) {
  std::unique_lock lock(mutex_);
  answered_.wait_for(lock, timeout, [&] { return stop_ || (answer_ && answer_->id == id); });
  if (!answer_ || answer_->id != id) return std::nullopt;
  if (typed != nullptr) *typed = answer_->typed;
  return answer_->choice;
}

void LiveHub::close_prompt(std::uint64_t id) {
  std::lock_guard lock(mutex_);
  if (prompt_ && prompt_->id == id) prompt_.reset(), prompt_check_ = nullptr;
  answer_.reset();
  bump();
}

std::string LiveHub::state_json() const {
  std::lock_guard lock(mutex_);
  return state_json_locked();
}

std::string LiveHub::state_json_locked() const {
  nlohmann::json phases = nlohmann::json::array();
  for (const PhaseState& s : phases_) {
    nlohmann::json ms = nlohmann::json::array();
    for (const auto& m : s.measurements) {
      ms.push_back({{"name", m.name}, {"unit", m.unit}, {"value", optional_number(m.value)}, {"min", optional_number(m.min)},
                    {"max", optional_number(m.max)}, {"verdict", m.verdict}, {"reason", m.reason}});
    }
    phases.push_back({{"name", s.name}, {"experiment", s.experiment}, {"state", s.state}, {"tries", s.tries}, {"started_ms", s.started_ms},
                      {"finished_ms", s.finished_ms}, {"record_s", s.record_s}, {"expected_s", optional_number(s.expected_s)},
                      {"verdict", s.verdict}, {"reason", s.reason}, {"measurements", ms}});
  }
  nlohmann::json prompt = nullptr;
  if (prompt_) {
    nlohmann::json fields = nlohmann::json::array();
    for (const auto& f : prompt_->fields) fields.push_back({{"name", f.name}, {"question", f.question}});
    prompt = {{"id", prompt_->id}, {"phase", prompt_->phase}, {"text", prompt_->text}, {"choices", prompt_->choices}, {"fields", fields}};
  }
  return nlohmann::json{{"live", !phases_.empty()}, {"serial", serial_}, {"batch", batch_}, {"station", station_}, {"status", status_},
                        {"verdict", verdict_}, {"deciding_phase", deciding_phase_}, {"deciding_measurement", deciding_measurement_},
                        {"certificate", certificate_}, {"started_ms", started_unix_ms_}, {"finished_ms", finished_unix_ms_},
                        {"now_ms", now_unix_ms()}, {"message", last_message_}, {"prompt", prompt}, {"phases", phases}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // a text not UTF-8 (a file typed on the terminal) must not throw
}

std::unique_ptr<EventStream> LiveHub::mailbox() { return std::make_unique<Client>(*this); }

std::uint64_t LiveHub::samples_released() const {
  std::lock_guard lock(mutex_);
  return next_seq_ - 1;
}

std::optional<std::string> LiveHub::Client::next() {
  std::lock_guard lock(hub_.mutex_);
  std::string out;
  if (hub_.state_version_ != state_version_) {
    state_version_ = hub_.state_version_;
    out += ",\"state\":" + hub_.state_json_locked();
  }
  if (!hub_.samples_.empty() && hub_.samples_.back().seq > seq_) {
    out += ",\"samples\":[";
    bool first = true;
    for (const ScreenSample& s : hub_.samples_) {
      if (s.seq <= seq_) continue;
      const auto triple = [](const double* v) {
        return fmt::format("[{},{},{}]", number_or_null(v[0]).dump(), number_or_null(v[1]).dump(), number_or_null(v[2]).dump());
      };
      out += fmt::format("{}{{\"seq\":{},\"phase\":{},\"try\":{},\"t\":{:.4f},\"at\":{:.1f},\"va\":{},\"de\":{},\"vs\":{}}}", first ? "" : ",",
                         s.seq, nlohmann::json(s.phase).dump(), s.try_number, s.t_s, s.measured_unix_ms, triple(s.va), triple(s.de_um),
                         triple(s.vs));
      first = false;
    }
    out += "]";
    seq_ = hub_.samples_.back().seq;
  }
  if (hub_.frf_version_ != frf_version_) {
    frf_version_ = hub_.frf_version_;
    if (!hub_.frf_json_.empty()) out += ",\"frf\":" + hub_.frf_json_;
  }
  if (out.empty()) return std::nullopt;
  return fmt::format("{{\"now_ms\":{:.1f}{}}}", now_unix_ms(), out);
}

}  // namespace piezobench::web
