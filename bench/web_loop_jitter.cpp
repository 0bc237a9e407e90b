// The real-time loop's timing with the station's page open (issue 29; docs/performance.md, "Loop
// jitter with pages open"). The virtual bench in-process at 10 kHz through rt::run_loop in real
// time (SCHED_FIFO and mlockall when permitted), its log tapped into a web::LiveHub
// (LiveHub::loop_tap, as `qualify --ui` does on hardware) served by the web::HttpServer on
// 127.0.0.1, with clients reading /api/events as a page does:
//   none      no client
//   one       1 client
//   five      5 clients
//   killed    5 clients, one of them killed at mid-run (its socket reset with unread data, as the
//             kernel does for a killed browser)
// The client threads run in this process, on the same 2 cores as the loop, as pages on the
// station's computer would. The cases are interleaved round by round (the shared machine's load
// drifts). Per run (rt::LoopReport): the period jitter |actual period - T| between consecutive
// wake-ups, p99, p99.99 and max; the wake latency p99.99; overruns, skipped deadlines, dropped log
// records; the bytes the clients read and the screen samples the hub formed.
//
//   web_loop_jitter [--seconds S (10)] [--rounds R (3)] [--rate HZ (10000)]
#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/measure.hpp"
#include "piezobench/rt/virtual_backend.hpp"
#include "piezobench/web/http_server.hpp"
#include "piezobench/web/live_hub.hpp"
#include "piezobench/web/station_site.hpp"

namespace pb = piezobench;

namespace {

// A page's event stream: reads until told to stop, or is killed (reset) when told to.
class Client {
 public:
  Client(unsigned short port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{0, 100'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) throw std::runtime_error("connect failed");
    const std::string req = fmt::format("GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nAccept: text/event-stream\r\n\r\n", port);
    if (::send(fd_, req.data(), req.size(), 0) != static_cast<ssize_t>(req.size())) throw std::runtime_error("send failed");
    thread_ = std::thread([this] {
      char buf[4096];
      while (!stop_.load()) {
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n > 0) bytes_ += static_cast<std::uint64_t>(n);
        if (n == 0) break;
        if (kill_.load()) {
          // Stop reading with data pending and reset the connection.
          linger l{1, 0};
          ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof l);
          ::close(fd_);
          fd_ = -1;
          break;
        }
      }
    });
  }
  ~Client() {
    stop_.store(true);
    thread_.join();
    if (fd_ >= 0) ::close(fd_);
  }
  void kill() { kill_.store(true); }
  [[nodiscard]] std::uint64_t bytes() const { return bytes_.load(); }

 private:
  int fd_ = -1;
  std::atomic<bool> stop_{false}, kill_{false};
  std::atomic<std::uint64_t> bytes_{0};
  std::thread thread_;
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
  return v[std::min(k, v.size() - 1)];
}

struct Result {
  double jitter_p99 = 0, jitter_p9999 = 0, jitter_max = 0, latency_p9999 = 0;
  std::uint64_t overruns = 0, skipped = 0, dropped = 0, client_bytes = 0, samples_shown = 0;
  bool fifo = false, locked = false;
};

Result run_case(const std::string& name, double seconds, double rate, const std::filesystem::path& db) {
  pb::web::LiveHub hub;
  pb::station::StationFile st;
  st.name = "jitter";
  pb::station::PhaseSpec phase;
  phase.name = "frf", phase.experiment = "frf-noise";
  st.phases = {phase};
  hub.plan(st, "JITTER-1", "J");
  hub.phase_started("JITTER-1", phase, 1);
  pb::web::StationSite site(db, &hub);
  pb::web::HttpServerOptions so;
  so.port = 0;
  so.operator_token = pb::web::random_token();
  pb::web::HttpServer server(so, site);
  server.start();

  pb::bench::BenchOptions bo;
  bo.sample_rate = rate;
  pb::rt::VirtualBenchBackend backend(pb::bench::batch_unit(1, 1), bo, 1);
  pb::rt::LoopOptions lo;
  lo.duration = seconds;
  lo.controller = false;
  lo.keep_log = true;  // as measure does (the tap comes on top of the log)
  lo.excitation = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rate));
  for (Eigen::Index k = 0; k < lo.excitation.size(); ++k) lo.excitation(k) = 0.5 * std::sin(2 * M_PI * 10.0 * static_cast<double>(k) / rate);
  lo.limits.amplifier_gain = 20.0, lo.limits.va_min = -20.0, lo.limits.va_max = 150.0, lo.limits.slew_rate = 1e5;
  lo.log_tap = hub.loop_tap(rate);

  const int clients = name == "none" ? 0 : name == "one" ? 1 : 5;
  std::vector<std::unique_ptr<Client>> pages;
  for (int i = 0; i < clients; ++i) pages.push_back(std::make_unique<Client>(server.port()));
  std::thread killer;
  if (name == "killed") {
    killer = std::thread([&] {
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds / 2));
      pages[0]->kill();
    });
  }
  const pb::rt::LoopReport rep = pb::rt::run_loop(backend, lo);
  if (killer.joinable()) killer.join();
  Result r;
  for (const auto& p : pages) r.client_bytes += p->bytes();
  pages.clear();
  server.stop();
  r.samples_shown = hub.samples_released();
  // The loop's own statistics (histograms of every cycle, within 1.2 %): the period jitter
  // |actual period - T| between consecutive wake-ups, and the wake-up's lateness.
  r.jitter_p99 = rep.period_jitter_us.p99, r.jitter_p9999 = rep.period_jitter_us.p9999, r.jitter_max = rep.period_jitter_us.max;
  r.latency_p9999 = rep.wake_latency_us.p9999;
  r.overruns = rep.overruns, r.skipped = rep.skipped_deadlines, r.dropped = rep.dropped_log_samples;
  r.fifo = rep.sched_fifo, r.locked = rep.memory_locked;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0, rate = 10e3;
  int rounds = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::atof(argv[i + 1]);
    else if (a == "--rounds") rounds = std::atoi(argv[i + 1]);
    else if (a == "--rate") rate = std::atof(argv[i + 1]);
    else {
      fmt::print(stderr, "usage: web_loop_jitter [--seconds S] [--rounds R] [--rate HZ]\n");
      return 2;
    }
  }
  const std::filesystem::path db = std::filesystem::temp_directory_path() / fmt::format("web_loop_jitter-{}.db", ::getpid());
  std::ifstream loadavg("/proc/loadavg");
  std::string load;
  std::getline(loadavg, load);
  fmt::print("web_loop_jitter: {} s per run at {:g} Hz, {} rounds; load average at start: {}\n", seconds, rate, rounds, load);
  fmt::print("{:<7} {:>5} {:>10} {:>13} {:>10} {:>14} {:>8} {:>7} {:>7} {:>9} {:>8} {}\n", "case", "round", "jit p99", "jit p99.99",
             "jit max", "wake p99.99", "overrun", "skipped", "dropped", "kB read", "shown", "(us)");
  const std::vector<std::string> cases = {"none", "one", "five", "killed"};
  std::map<std::string, std::vector<Result>> all;
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t c = 0; c < cases.size(); ++c) {
      const std::string& name = cases[(c + static_cast<std::size_t>(round)) % cases.size()];
      const Result r = run_case(name, seconds, rate, db);
      all[name].push_back(r);
      fmt::print("{:<7} {:>5} {:>10.1f} {:>13.1f} {:>10.1f} {:>14.1f} {:>8} {:>7} {:>7} {:>9.0f} {:>8} {}{}\n", name, round + 1, r.jitter_p99,
                 r.jitter_p9999, r.jitter_max, r.latency_p9999, r.overruns, r.skipped, r.dropped, r.client_bytes / 1e3, r.samples_shown,
                 r.fifo ? "fifo" : "normal", r.locked ? " locked" : "");
      std::fflush(stdout);
    }
  }
  fmt::print("\nper case, median over rounds of jitter p99.99 (us) and of overruns per run:\n");
  for (const std::string& name : cases) {
    std::vector<double> p, o;
    for (const Result& r : all[name]) p.push_back(r.jitter_p9999), o.push_back(static_cast<double>(r.overruns));
    fmt::print("  {:<7} jitter p99.99 {:.1f} us (runs: {:.1f} .. {:.1f}), overruns {:.0f}\n", name, percentile(p, 0.5),
               *std::min_element(p.begin(), p.end()), *std::max_element(p.begin(), p.end()), percentile(o, 0.5));
  }
  std::filesystem::remove(db);
  std::filesystem::remove(db.string() + "-wal");
  std::filesystem::remove(db.string() + "-shm");
  return 0;
}
