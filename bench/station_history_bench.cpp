// The station database at scale (docs/performance.md, "Station"): N units (default 10,000), each
// qualified through the 16 phases of docs/examples/station.toml with one measurement or more per
// phase, written through RecordStore as qualify writes them; then the history and listing queries
// a control chart or a web page makes, each timed (median of 5 runs).
//   station_history_bench [DB] [UNITS]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "piezobench/station/record_store.hpp"
#include "program_main.hpp"


namespace {

using namespace piezobench;
using piezobench::bench_program::seconds_since;

void fill(station::RecordStore& s, int units) {
  const char* phases[] = {"flatness", "capacitance", "stroke", "hysteresis-4V", "hysteresis-20V", "hysteresis-40V", "hysteresis-80V", "stiffness",
                          "stiffness-open", "frf", "frf-no-resistor", "iff-30000", "iff-60000", "iff-120000", "iff-240000", "tracking"};
  const char* names[] = {"flatness_um", "capacitance_sensor_uF", "stroke_um", "hysteresis_relative_width", "hysteresis_relative_width",
                         "hysteresis_relative_width", "hysteresis_relative_width", "k1_N_per_um", "k_oc_N_per_um", "resonance_Hz",
                         "hpf_corner_without_resistor_Hz", "damped_damping", "damped_damping", "damped_damping", "damped_damping", "tracking_width_ff"};
  for (int u = 0; u < units; ++u) {
    station::QualificationRow q;
    q.serial = "APA-" + std::to_string(u);
    q.batch = "B" + std::to_string(u / 100);
    q.station = "APA300ML acceptance";
    q.station_sha256 = q.bench_sha256 = std::string(64, 'a');
    q.bench_file = "bench.toml";
    q.software_version = "bench";
    q.started = station::utc_now();
    q.id = s.begin_qualification(q);
    for (int p = 0; p < 16; ++p) {
      station::PhaseTryRow t = s.begin_phase_try(q.id, p, phases[p]);
      t.status = "complete";
      t.verdict = "pass";
      t.finished = station::utc_now();
      const double value = 240.0 + (u % 37) - 18.0 + p;
      t.measurements.push_back({names[p], "x", value, 1.0, 1e6, "pass", "", false});
      if (p == 9) t.measurements.push_back({"antiresonance_Hz", "Hz", 41.0 + (u % 7) * 0.1, std::nullopt, std::nullopt, "pass", "", false});
      t.raw_files.push_back({"/data/" + q.serial + "/" + phases[p] + ".mat", "x", std::string(64, 'b'), 1 << 20});
      s.finish_phase_try(t);
    }
    q.status = "complete";
    q.verdict = "pass";
    q.finished = station::utc_now();
    s.finish_qualification(q);
    if ((u + 1) % 1000 == 0) std::fprintf(stderr, "station_history_bench: %d units written\n", u + 1);
  }
}

template <typename F>
double median_ms(F&& f) {
  std::vector<double> t;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(1e3 * seconds_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[2];
}

int run(int argc, char** argv) {
  const std::filesystem::path db = argc > 1 ? argv[1] : "/tmp/station-history-bench.db";
  const int units = argc > 2 ? std::stoi(argv[2]) : 10000;
  if (!std::filesystem::exists(db)) {
    station::RecordStore s(db);
    const auto t0 = std::chrono::steady_clock::now();
    fill(s, units);
    std::printf("wrote %d units (16 phase tries each) in %.1f s\n", units, seconds_since(t0));
  }
  station::RecordStore s(db);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::size_t n = 0;
  std::printf("history stroke_um, every unit:   %.1f ms\n", median_ms([&] { n = s.history("stroke_um").size(); }));
  std::printf("  (%zu points)\n", n);
  std::printf("history resonance_Hz, one batch: %.2f ms\n", median_ms([&] { n = s.history("resonance_Hz", "B42").size(); }));
  std::printf("list, one batch:                 %.2f ms\n", median_ms([&] { n = s.list("B42").size(); }));
  std::printf("list, newest 1000:               %.2f ms\n", median_ms([&] { n = s.list("", 1000).size(); }));
  std::printf("latest qualification + tries:    %.2f ms\n", median_ms([&] {
    const auto q = s.latest_qualification("APA-4242");
    n = q ? s.phase_tries(q->id).size() : 0;
  }));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return piezobench::bench_program::guarded_main("station_history_bench", run, argc, argv); }
