#include "piezobench/campaign/demo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include <toml++/toml.h>

#include "embedded_superelement.hpp"
#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/truth.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/parallel.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using nlohmann::json;

void DemoOptions::validate() const {
  if (units.empty()) throw InputError("demo", "units", "at least one unit", "none");
  for (const int u : units) {
    if (u < 1 || u > 7) throw InputError("demo", "units", "units of the batch, 1 to 7", std::to_string(u));
  }
  if (std::find(units.begin(), units.end(), iff_unit) == units.end() && !iff_gains.empty()) {
    throw InputError("demo", "iff_unit", "one of the simulated units", std::to_string(iff_unit));
  }
  for (const double a : hysteresis_amplitudes) {
    if (!(a > 0.0 && a <= 85.0)) throw InputError("demo", "hysteresis_amplitudes", "amplitudes in (0, 85] V (65 V +- A inside -20..150 V)", fmt::format("{}", a));
  }
  for (const double g : iff_gains) {
    if (!(g >= 0.0)) throw InputError("demo", "iff_gains", "gains >= 0", fmt::format("{}", g));
  }
  if (tracking_unit != 0 && std::find(units.begin(), units.end(), tracking_unit) == units.end()) {
    throw InputError("demo", "tracking_unit", "0 (none) or one of the simulated units", std::to_string(tracking_unit));
  }
  if (threads < 0) throw InputError("demo", "threads", "0 (all cores) or more", std::to_string(threads));
}

namespace {

struct Job {
  int unit = 0;
  bench::Experiment experiment = bench::Experiment::kStroke;
  std::optional<double> amplitude, gain, duration;
  std::string file;   // relative to DIR
  double cost = 1.0;  // for scheduling (longest first)
  bool open_circuit = false;  // every stack open: the actuators disconnected, no resistor (k_oc)
  bool no_resistor = false;   // no resistor across the sensor stack (report section 2.5)
  std::string tracking_file = {};  // hysteresis: then the tracking experiment with the model of this record
};

std::string number_tag(double v) { return fmt::format("{:g}", v); }

// The records of one unit: the static tests, the FRF and hammer runs, the hysteresis cycles (the
// largest one then the tracking run, when this is the tracking unit) and, on the IFF unit, the
// FRF without the resistor and the damped plants.
void add_unit_jobs(int id, const DemoOptions& options, double frf_s, double iff_s, std::vector<Job>& jobs) {
  const std::string u = fmt::format("unit{}", id);
  jobs.push_back({id, bench::Experiment::kFlatness, {}, {}, {}, "data/" + u + "_flatness.mat", 0.01});
  jobs.push_back({id, bench::Experiment::kCapacitance, {}, {}, {}, "data/" + u + "_capacitance.mat", 0.01});
  jobs.push_back({id, bench::Experiment::kStroke, {}, {}, {}, "data/" + u + "_stroke.mat", 3.0});
  jobs.push_back({id, bench::Experiment::kStiffness, {}, {}, {}, "data/" + u + "_stiffness.mat", 2.0});
  jobs.push_back({id, bench::Experiment::kStiffness, {}, {}, {}, "data/" + u + "_stiffness-open.mat", 2.0, true, true});
  jobs.push_back({id, bench::Experiment::kFrfNoise, {}, {}, frf_s, "data/" + u + "_frf-noise.mat", frf_s / 10.0});
  jobs.push_back({id, bench::Experiment::kHammer, {}, {}, {}, "data/" + u + "_hammer.mat", 1.0});
  const std::string tracking_file = id == options.tracking_unit ? "data/" + u + "_tracking.mat" : "";
  const auto largest = std::max_element(options.hysteresis_amplitudes.begin(), options.hysteresis_amplitudes.end());
  for (const double a : options.hysteresis_amplitudes) {
    jobs.push_back({id, bench::Experiment::kHysteresis, a, {}, {}, "data/" + u + "_hysteresis_" + number_tag(a) + "V.mat", 0.5});
    if (a == *largest && !tracking_file.empty()) {
      jobs.back().tracking_file = tracking_file;
      jobs.back().cost += 1.0;
    }
  }
  if (largest == options.hysteresis_amplitudes.end() && !tracking_file.empty()) {
    jobs.push_back({id, bench::Experiment::kTracking, {}, {}, {}, tracking_file, 1.0});  // model identified from its open run
  }
  if (id == options.iff_unit) {
    // Figure 2.7 on the IFF unit: u -> Vs without the resistor.
    jobs.push_back({id, bench::Experiment::kFrfNoise, {}, {}, frf_s, "data/" + u + "_frf-noise-no-resistor.mat", frf_s / 10.0, false, true});
    for (const double g : options.iff_gains) {
      jobs.push_back({id, bench::Experiment::kIff, {}, g, iff_s, "data/" + u + "_iff_g" + number_tag(g) + ".mat", iff_s / 10.0});
    }
  }
}

// Every record of the demo, longest first.
std::vector<Job> demo_jobs(const DemoOptions& options) {
  const double frf_s = options.fast ? 8.0 : 20.0;
  const double iff_s = options.fast ? 4.0 : 10.0;
  std::vector<Job> jobs;
  for (const int id : options.units) add_unit_jobs(id, options, frf_s, iff_s, jobs);
  std::stable_sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.cost > b.cost; });
  return jobs;
}

// One record simulated and written, and the tracking record that follows it.
io::TimeSeries simulate_job(const Job& j, const fs::path& dir, const bench::UnitTruth& truth, const bench::BenchOptions& bench_options,
                            std::uint64_t seed) {
  bench::ExperimentOptions eo;
  eo.bench = bench_options;
  eo.bench.actuator_open_circuit = j.open_circuit;
  eo.bench.hpf_resistor = !(j.no_resistor || j.open_circuit);
  eo.amplitude = j.amplitude;
  eo.gain = j.gain;
  eo.duration = j.duration;
  io::TimeSeries ts = bench::simulate(j.experiment, truth, eo, seed);
  io::write_timeseries(ts, dir / j.file);
  if (!j.tracking_file.empty()) {
    // The tracking experiment with the unit's hysteresis model as the campaign identifies it
    // (the same fit of the same record: campaign hysteresis_model).
    bench::ExperimentOptions to;
    to.bench = bench_options;
    const Eigen::VectorXd va = ts.channel("Va"), de = ts.channel("de");
    to.feedforward = ident::fit_hysteresis({va.data(), static_cast<std::size_t>(va.size())},
                                           {de.data(), static_cast<std::size_t>(de.size())}, ts.sample_rate)
                         .model;
    io::write_timeseries(bench::simulate(bench::Experiment::kTracking, truth, to, seed), dir / j.tracking_file);
  }
  return ts;
}

// Simulates and writes the records in parallel; returns the settings of the stiffness records
// (the campaign file needs them), by file.
std::map<std::string, io::TimeSeries> simulate_jobs(const std::vector<Job>& jobs, const fs::path& dir, const DemoOptions& options,
                                                    const std::map<int, bench::UnitTruth>& truths, const bench::BenchOptions& bench_options) {
  std::mutex log_mutex;
  std::map<std::string, io::TimeSeries> small;  // settings needed for the campaign (stiffness)
  std::atomic<std::size_t> done{0};
  const auto start = std::chrono::steady_clock::now();
  const int threads = options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  core::parallel_for(jobs.size(), threads, [&](std::size_t i) {
    const Job& j = jobs[i];
    const io::TimeSeries ts = simulate_job(j, dir, truths.at(j.unit), bench_options, options.seed);
    const std::lock_guard<std::mutex> lock(log_mutex);
    if (j.experiment == bench::Experiment::kStiffness) {
      io::TimeSeries head;
      head.settings = ts.settings;
      small[j.file] = head;
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.log) options.log(fmt::format("simulated {:>2}/{} {} ({:.1f} s)", ++done, jobs.size(), j.file, elapsed));
  });
  return small;
}

// The campaign file's head: the bench (its added mass and gravity as the stiffness records state
// them), the specifications and the analysis.
std::string campaign_head(const DemoOptions& options, const bench::BenchOptions& bench_options,
                          const std::map<std::string, io::TimeSeries>& stiffness_records) {
  double added_mass = 6.4, gravity = bench_options.gravity;
  for (const auto& [file, ts] : stiffness_records) {
    if (const auto it = ts.settings.find("added_mass_kg"); it != ts.settings.end() && std::holds_alternative<double>(it->second)) {
      added_mass = std::get<double>(it->second);
    }
    if (const auto it = ts.settings.find("gravity_m_per_s2"); it != ts.settings.end() && std::holds_alternative<double>(it->second)) {
      gravity = std::get<double>(it->second);
    }
  }
  return fmt::format(
      "# The demo campaign written by `piezobench demo` (seed {}{}): the report's seven APA300ML on the\n"
      "# virtual bench. docs/campaign.md documents every key.\n"
      "title = \"APA300ML batch (virtual bench, seed {})\"\n\n"
      "[bench]\n"
      "amplifier_gain = {:g}          # V/V (PD200)\n"
      "suspended_mass_kg = {:g}\n"
      "added_mass_kg = {:g}\n"
      "gravity_m_per_s2 = {:g}\n"
      "hpf_resistance_ohm = {:g}\n"
      "probe_accuracy_um = 0.5\n\n"
      "[specs]\n"
      "flatness_um = 25.0\n"
      "flatness_method = \"least-squares\"\n"
      "capacitance_sensor_uF = [4.0, 6.0]\n"
      "capacitance_actuator_uF = [8.0, 12.0]\n"
      "stroke_min_um = 200.0\n"
      "stiffness_N_per_um = [1.5, 2.5]\n\n"
      "[analysis]\n"
      "window = \"hann-periodic\"\n"
      "nfft = 0                       # automatic: 4 s segments\n"
      "overlap = 0.5\n"
      "fmin_Hz = 20.0                 # below ~10 Hz creep and hysteresis raise the small-signal gain\n"
      "fmax_Hz = 500.0                # eq. 2.3 and the 2-DoF model hold below the anti-aliasing filter\n"
      "iff_unit = {}\n\n",
      options.seed, options.fast ? ", fast" : "", options.seed, bench_options.amplifier_gain, bench_options.suspended_mass, added_mass,
      gravity, bench_options.hpf_resistance, std::find(options.units.begin(), options.units.end(), options.iff_unit) != options.units.end() && !options.iff_gains.empty() ? options.iff_unit : 0);
}

// The [superelement] table for the super element written beside the campaign.
std::string demo_superelement_table(const fs::path& se_toml) {
  const toml::table se = io::read_toml_file(se_toml);
  const auto text = [&](const char* key) { return se[key].value<std::string>().value_or(""); };
  return fmt::format(
      "[superelement]                 # the APA300ML super element from our own geometry (docs/apa300ml.md)\n"
      "format = \"matrix-market\"\n"
      "k_file = \"superelement/{}\"\nm_file = \"superelement/{}\"\nnodes_file = \"superelement/{}\"\n"
      "fix = [{}]                  # bottom interface (remote point 2)\n"
      "actuator = \"{}\"     # remote points 3 -> 4: the two actuator stacks\n"
      "sensor = \"{}\"       # remote points 4 -> 5: the sensor stack\n"
      "output = \"{}\"             # top interface (remote point 1): d_e\n"
      "damping = \"modal:0.02\"\n"
      "stack_modulus_Pa = {:g}      # the stacks' effective modulus the element was built with (eq. 4.1)\n\n",
      text("k_file"), text("m_file"), text("nodes_file"), se["fix"][0].value<int64_t>().value_or(0), text("actuator"), text("sensor"),
      text("output"), se["stack_modulus_Pa"].value<double>().value_or(48e9));
}

// A unit's [[units]] table: its records.
std::string unit_section(int id, const DemoOptions& options) {
  const std::string u = fmt::format("data/unit{}", id);
  std::string toml = fmt::format("[[units]]\nid = {}\nname = \"APA {}\"\n", id, id);
  toml += fmt::format("flatness = \"{}_flatness.mat\"\ncapacitance = \"{}_capacitance.mat\"\nstroke = \"{}_stroke.mat\"\n", u, u, u);
  toml += "hysteresis = [";
  for (std::size_t i = 0; i < options.hysteresis_amplitudes.size(); ++i) {
    toml += fmt::format("{}\"{}_hysteresis_{}V.mat\"", i ? ", " : "", u, number_tag(options.hysteresis_amplitudes[i]));
  }
  toml += "]\n";
  toml += fmt::format("stiffness = \"{}_stiffness.mat\"\nstiffness_open_circuit = \"{}_stiffness-open.mat\"\n", u, u);
  toml += fmt::format("frf = \"{}_frf-noise.mat\"\nhammer = \"{}_hammer.mat\"\n", u, u);
  if (id == options.tracking_unit) toml += fmt::format("tracking = \"{}_tracking.mat\"\n", u);
  if (id == options.iff_unit) toml += fmt::format("frf_without_resistor = \"{}_frf-noise-no-resistor.mat\"\n", u);
  if (id == options.iff_unit && !options.iff_gains.empty()) {
    toml += "iff = [\n";
    for (const double g : options.iff_gains) {
      toml += fmt::format("  {{ file = \"{}_iff_g{}.mat\", gain = {:g} }},\n", u, number_tag(g), g);
    }
    toml += "]\n";
  }
  return toml + "\n";
}

}  // namespace

DemoFiles write_demo_campaign(const fs::path& dir, const DemoOptions& options) {
  options.validate();
  std::error_code ec;
  fs::create_directories(dir / "data", ec);
  if (ec) throw InputError(dir.string(), "--out", "a folder that can be created", ec.message());

  std::map<int, bench::UnitTruth> truths;
  for (const int id : options.units) truths[id] = bench::batch_unit(id, options.seed);
  const bench::BenchOptions bench_options;
  const std::vector<Job> jobs = demo_jobs(options);
  const std::map<std::string, io::TimeSeries> stiffness_records = simulate_jobs(jobs, dir, options, truths, bench_options);

  DemoFiles files;
  for (const Job& j : jobs) {
    files.data.push_back(dir / j.file);
    if (!j.tracking_file.empty()) files.data.push_back(dir / j.tracking_file);
  }
  std::sort(files.data.begin(), files.data.end());

  // The truth.
  json truth = {{"seed", options.seed}, {"fast", options.fast}, {"units", json::array()}};
  for (const int id : options.units) truth["units"].push_back(bench::truth_json(truths.at(id), bench_options));
  files.truth = dir / "data" / "truth.json";
  io::write_text_atomically(files.truth, truth.dump(2) + "\n");

  // The campaign file. The APA300ML super element shipped in the binary
  // (scripts/superelement/make_apa300ml.sh), put on the bench by the campaign (report section 4):
  // ga and gs tuned against each unit's FRFs.
  std::string toml = campaign_head(options, bench_options, stiffness_records);
  files.superelement = detail::write_apa300ml_superelement(dir / "superelement");
  toml += demo_superelement_table(files.superelement);
  for (const int id : options.units) toml += unit_section(id, options);
  files.campaign = dir / "campaign.toml";
  io::write_text_atomically(files.campaign, toml);
  return files;
}

}  // namespace piezobench::campaign
