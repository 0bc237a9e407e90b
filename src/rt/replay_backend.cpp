#include "piezobench/rt/replay_backend.hpp"

#include "piezobench/core/error.hpp"

namespace piezobench::rt {

std::string to_string(ClockSource source) {
  return source == ClockSource::kHostMonotonic ? "host-monotonic" : "backend-sample-clock";
}

ReplayBackend::ReplayBackend(const io::TimeSeries& record) : sample_rate_(record.sample_rate), source_(record.source) {
  record.validate();
  const auto de = record.channel("de");  // InputError listing the channels when missing
  const auto vs = record.channel("Vs");
  de_.assign(de.data(), de.data() + de.size());
  vs_.assign(vs.data(), vs.data() + vs.size());
}

ReplayBackend::ReplayBackend(const std::filesystem::path& file) : ReplayBackend(io::read_timeseries(file)) {}

void ReplayBackend::start() {
  next_ = 0;
  last_u_ = 0.0;
}

SensorSample ReplayBackend::read() noexcept {
  SensorSample s;
  if (next_ < de_.size()) {
    s.de = de_[next_];
    s.vs = vs_[next_];
    s.sequence = next_ + 1;
    ++next_;
  } else if (!de_.empty()) {  // past the end: the last sample again (stale)
    s.de = de_.back();
    s.vs = vs_.back();
    s.sequence = de_.size();
  }
  return s;
}

void ReplayBackend::write(double u) noexcept { last_u_ = u; }

bool ReplayBackend::finished() const noexcept { return next_ >= de_.size(); }

}  // namespace piezobench::rt
