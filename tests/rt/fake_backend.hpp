#pragma once
// A scriptable backend for the rt tests: a discrete state-space plant u -> [d_e; Vs] stepped in
// lockstep (read() returns C x, write(u) advances x), with injectable faults: a NaN sample, stale
// samples (the sequence number stops advancing), a stall (read() sleeps once).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

#include "piezobench/lti/state_space.hpp"
#include "piezobench/rt/backend.hpp"

namespace piezobench::rt::fake {

class FakeBackend final : public Backend {
 public:
  // `plant`: discrete, one input, outputs [d_e; Vs] (or one output: Vs, with d_e = 0).
  FakeBackend(const lti::StateSpace& plant, double rate) : rate_(rate) {
    n_ = static_cast<int>(plant.states());
    for (int i = 0; i < n_; ++i) {
      for (int j = 0; j < n_; ++j) a_.push_back(plant.A(i, j));
      b_.push_back(plant.B(i, 0));
    }
    const int outputs = static_cast<int>(plant.outputs());
    for (int j = 0; j < n_; ++j) {
      c_de_.push_back(outputs == 2 ? plant.C(0, j) : 0.0);
      c_vs_.push_back(plant.C(outputs - 1, j));
    }
    x_.assign(static_cast<std::size_t>(n_), 0.0);
    xn_ = x_;
  }

  std::string name() const override { return "fake"; }
  double sample_rate() const override { return rate_; }
  void start() override {
    std::fill(x_.begin(), x_.end(), 0.0);
    reads_ = 0;
    writes_ = 0;
  }
  SensorSample read() noexcept override {
    SensorSample s;
    for (int j = 0; j < n_; ++j) {
      s.de += c_de_[static_cast<std::size_t>(j)] * x_[static_cast<std::size_t>(j)];
      s.vs += c_vs_[static_cast<std::size_t>(j)] * x_[static_cast<std::size_t>(j)];
    }
    s.sequence = reads_ >= stale_from ? stale_from : reads_ + 1;
    if (reads_ == nan_at) s.vs = std::numeric_limits<double>::quiet_NaN();
    if (reads_ == stall_at) std::this_thread::sleep_for(stall);
    ++reads_;
    return s;
  }
  void write(double u) noexcept override {
    for (int i = 0; i < n_; ++i) {
      double v = b_[static_cast<std::size_t>(i)] * u;
      for (int j = 0; j < n_; ++j) v += a_[static_cast<std::size_t>(i * n_ + j)] * x_[static_cast<std::size_t>(j)];
      xn_[static_cast<std::size_t>(i)] = v;
    }
    x_.swap(xn_);
    writes_u.size() > writes_ ? void(writes_u[writes_] = u) : void();
    ++writes_;
  }
  void stop() noexcept override { stopped = true; }
  void on_watchdog() noexcept override { watchdog_calls.fetch_add(1); }

  // Fault injection (read index, 0-based).
  std::uint64_t nan_at = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t stale_from = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t stall_at = std::numeric_limits<std::uint64_t>::max();
  std::chrono::milliseconds stall{0};
  // Commands written (preallocate to record them without allocating in write()).
  std::vector<double> writes_u;
  bool stopped = false;
  std::atomic<int> watchdog_calls{0};
  [[nodiscard]] std::uint64_t writes() const { return writes_; }

 private:
  double rate_;
  int n_ = 0;
  std::vector<double> a_, b_, c_de_, c_vs_, x_, xn_;
  std::uint64_t reads_ = 0, writes_ = 0;
};

}  // namespace piezobench::rt::fake
