// `piezobench run` (the whole characterization of a campaign file) and `piezobench demo` (the
// report's seven-unit campaign simulated on the virtual bench, then run). docs/campaign.md.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include "cli_common.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/io/output_dir.hpp"

namespace piezobench::app {
namespace {

namespace fs = std::filesystem;

// Exit code of `run --strict` / `demo --strict` when a unit is rejected (docs/campaign.md).
constexpr int kRejected = 5;

struct RunOptions {
  std::string campaign;
  std::string out = "piezobench-results";
  bool strict = false;
  bool json = false;
  int threads = 0;
};

struct DemoCli {
  std::string out = "piezobench-demo";
  std::uint64_t seed = 1;
  bool fast = false;
  bool strict = false;
  bool json = false;
  int threads = 0;
  std::string units;  // "1,3,4"; empty = all seven
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Runs the pipeline on a campaign file and writes the outputs; prints the summary.
int run_pipeline(const fs::path& campaign_file, const fs::path& out, bool strict, bool json, int threads,
                 nlohmann::json extra = nlohmann::json::object()) {
  const auto t0 = std::chrono::steady_clock::now();
  // An earlier run's result set goes first: a run that fails leaves none, never a mix.
  campaign::remove_outputs(out);
  log_line("reading " + campaign_file.string());
  const campaign::Campaign c = campaign::read_campaign(campaign_file);
  campaign::PipelineOptions po;
  po.threads = threads;
  po.log = [](const std::string& line) { log_line(line); };
  const campaign::CampaignResult r = campaign::run_campaign(c, po);
  const std::vector<fs::path> written = campaign::write_outputs(r, out);
  const double elapsed = seconds_since(t0);
  const fs::path report = out / "report.html";
  if (json) {
    nlohmann::json doc = campaign::results_json(r);
    doc["outputs"] = nlohmann::json::array();
    for (const auto& p : written) doc["outputs"].push_back(p.string());
    doc["pipeline_seconds"] = elapsed;
    for (const auto& [k, v] : extra.items()) doc[k] = v;
    print_json(doc);
  } else {
    fmt::print("{} units: {} accepted, {} rejected ({:.1f} s)\n", r.accepted + r.rejected, r.accepted, r.rejected, elapsed);
    for (const auto& u : r.units) {
      fmt::print("  {:<8} {}\n", u.name, u.accepted ? "accepted" : "REJECTED");
      for (const auto& reason : u.reasons) fmt::print("           - {}\n", reason);
    }
    if (r.iff.optimal_gain && r.iff.unit) {
      fmt::print("IFF: optimal gain {:.4g} (APA {}), maximum damping {:.3f}\n", *r.iff.optimal_gain, *r.iff.unit, r.iff.max_damping.value_or(0.0));
    }
    fmt::print("report: {}\n", fs::absolute(report).string());
    fmt::print("results: {}, {}\n", (out / "results.json").string(), (out / "results.mat").string());
  }
  log_line("report written to " + fs::absolute(report).string());
  return strict && r.rejected > 0 ? kRejected : 0;
}

int run_run(const RunOptions& o) {
  if (o.threads < 0) throw InputError("", "--threads", "0 (all cores) or more", std::to_string(o.threads));
  const io::OutputLock lock(o.out);  // a second run on the same --out is refused (exit 3)
  return run_pipeline(o.campaign, o.out, o.strict, o.json, o.threads);
}

int run_demo(const DemoCli& o) {
  if (o.threads < 0) throw InputError("", "--threads", "0 (all cores) or more", std::to_string(o.threads));
  const io::OutputLock lock(o.out);
  const auto t0 = std::chrono::steady_clock::now();
  campaign::DemoOptions d;
  d.seed = o.seed;
  d.fast = o.fast;
  d.threads = o.threads;
  if (!o.units.empty()) {
    d.units.clear();
    for (const double u : parse_number_list(o.units, "--units")) {
      if (u != std::floor(u) || u < 1 || u > 7) throw InputError("", "--units", "unit numbers 1..7", fmt::format("{}", u));
      d.units.push_back(static_cast<int>(u));
    }
    if (std::find(d.units.begin(), d.units.end(), d.iff_unit) == d.units.end()) d.iff_unit = d.units.front();
  }
  d.log = [](const std::string& line) { log_line(line); };
  log_line(fmt::format("simulating the report's 7-unit campaign on the virtual bench (seed {}{}) into {}", o.seed,
                       o.fast ? ", fast" : "", fs::absolute(o.out).string()));
  const campaign::DemoFiles files = campaign::write_demo_campaign(o.out, d);
  const double simulated = seconds_since(t0);
  log_line(fmt::format("simulation done in {:.1f} s: {} files, truth in {}", simulated, files.data.size(), files.truth.string()));
  const int code = run_pipeline(files.campaign, o.out, o.strict, o.json, o.threads,
                                {{"demo", {{"seed", o.seed}, {"fast", o.fast}, {"simulation_seconds", simulated},
                                           {"campaign", files.campaign.string()}, {"truth", files.truth.string()}}}});
  log_line(fmt::format("demo done in {:.1f} s", seconds_since(t0)));
  return code;
}

}  // namespace

void add_run_commands(CLI::App& app, Action& action) {
  auto r = std::make_shared<RunOptions>();
  CLI::App* run = app.add_subcommand("run", "Characterize a batch from a campaign file: results.json, results.mat, report.html");
  run->add_option("campaign", r->campaign, "Campaign file (TOML, docs/campaign.md)")->required();
  run->add_option("--out", r->out, "Output folder (results.json, results.mat, report.html)")->capture_default_str();
  run->add_flag("--strict", r->strict, "Exit with code 5 when a unit is rejected");
  run->add_flag("--json", r->json, "Print the results as one JSON document on stdout");
  run->add_option("--threads", r->threads, "Units analysed in parallel (0 = all cores)")->capture_default_str();
  run->callback([r, &action] { action = [r] { return run_run(*r); }; });

  auto d = std::make_shared<DemoCli>();
  CLI::App* demo = app.add_subcommand("demo", "Simulate the report's 7-unit campaign on the virtual bench, then run it");
  demo->add_option("--out", d->out, "Output folder (data/, campaign.toml, results, report.html)")->capture_default_str();
  demo->add_option("--seed", d->seed, "Seed of the virtual batch and its noise")->capture_default_str();
  demo->add_flag("--fast", d->fast, "Shorter noise records (FRF 8 s, IFF 4 s), for tests");
  demo->add_flag("--strict", d->strict, "Exit with code 5 when a unit is rejected (unit 3 is, by design)");
  demo->add_flag("--json", d->json, "Print the results as one JSON document on stdout");
  demo->add_option("--units", d->units, "Units of the batch to simulate, e.g. 1,3,4 (default all seven)");
  demo->add_option("--threads", d->threads, "Worker threads (0 = all cores)")->capture_default_str();
  demo->callback([d, &action] { action = [d] { return run_demo(*d); }; });
}

}  // namespace piezobench::app
