// `piezobench run` (the whole characterization of a campaign file, or a part of it), `merge` (the
// parts of a split campaign: docs/cluster.md) and `piezobench demo` (the
// report's seven-unit campaign simulated on the virtual bench, then run). docs/campaign.md.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <regex>

#include "cli_common.hpp"
#include "field_reference.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/part.hpp"
#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/output_dir.hpp"

namespace piezobench::app {
namespace {

namespace fs = std::filesystem;

// Exit code of `run --strict` / `demo --strict` when a unit is rejected (docs/campaign.md).
constexpr int kRejected = 5;
// Exit code of `run`, `merge` and `demo` when a unit could not be analysed (a file missing or
// unreadable, bad data): the other units were analysed and the outputs written (docs/cli.md).
constexpr int kUnitNotAnalysed = 7;

struct RunOptions {
  std::string campaign;
  std::string out = "piezobench-results";
  bool strict = false;
  bool json = false;
  int threads = 0;
  bool list_units = false;
  std::string part;   // "K/N"
  std::string units;  // "3,7-9"
};

struct MergeOptions {
  std::vector<std::string> parts;
  std::string out = "piezobench-results";
  bool strict = false;
  bool json = false;
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

// The output folder's lock (io::OutputLock) whose file is removed when the run ends, while the lock
// is still held: a finished run leaves only its outputs in --out.
struct RunLock {
  explicit RunLock(const fs::path& out) : lock(out), file(out / ".piezobench.lock") {}
  ~RunLock() {
    std::error_code ec;
    fs::remove(file, ec);
  }
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  io::OutputLock lock;  // released after the destructor's body: the file goes first
  fs::path file;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

campaign::PipelineOptions pipeline_options(int threads) {
  campaign::PipelineOptions po;
  po.threads = threads;
  po.log = [](const std::string& line) { log_line(line); };
  return po;
}

// Writes the outputs of a campaign's result and prints the summary (`run` and `merge`).
int write_and_print(const campaign::CampaignResult& r, const fs::path& out, bool strict, bool json,
                    std::chrono::steady_clock::time_point t0, const nlohmann::json& extra = nlohmann::json::object()) {
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
    fmt::print("{} units: {} accepted, {}{} rejected, {} not analysed ({:.1f} s)\n", r.units.size(), r.accepted,
               r.marginal > 0 ? fmt::format("{} marginal, ", r.marginal) : std::string(), r.rejected, r.not_analysed, elapsed);
    for (const auto& u : r.units) {
      if (u.not_analysed) {
        fmt::print("  {:<8} NOT ANALYSED ({})\n           - {}\n", u.name, u.not_analysed->file.empty() ? u.not_analysed->key : u.not_analysed->file,
                   u.not_analysed->reason);
        continue;
      }
      fmt::print("  {:<8} {}\n", u.name, u.accepted ? "accepted" : u.marginal ? "MARGINAL" : "REJECTED");
      for (const auto& reason : u.reasons) fmt::print("           - {}\n", reason);
    }
    if (r.iff.optimal_gain && r.iff.unit) {
      fmt::print("IFF: optimal controller gain g = {:.4g} (a factor on eq. 2.4's K0; unit {}), maximum damping ratio {:.3f}\n", *r.iff.optimal_gain, *r.iff.unit,
                 r.iff.max_damping.value_or(0.0));
    }
    fmt::print("report: {}\n", fs::absolute(report).string());
    fmt::print("results: {}, {}\n", (out / "results.json").string(), (out / "results.mat").string());
  }
  log_line("report written to " + fs::absolute(report).string());
  if (r.not_analysed > 0) {
    log_line(fmt::format("{} of {} units could not be analysed (exit code {})", r.not_analysed, r.units.size(), kUnitNotAnalysed));
    return kUnitNotAnalysed;
  }
  // --strict: a marginal unit (a limit within its value +- U) is not proved to conform either.
  return strict && (r.rejected > 0 || r.marginal > 0) ? kRejected : 0;
}

// Runs the pipeline on a campaign file and writes the outputs; prints the summary.
int run_pipeline(const fs::path& campaign_file, const fs::path& out, bool strict, bool json, int threads,
                 const nlohmann::json& extra = nlohmann::json::object()) {
  const auto t0 = std::chrono::steady_clock::now();
  // An earlier run's result set goes first: a run that fails leaves none, never a mix.
  campaign::remove_outputs(out);
  log_line("reading " + campaign_file.string());
  const campaign::Campaign c = campaign::read_campaign(campaign_file);
  return write_and_print(campaign::run_campaign(c, pipeline_options(threads)), out, strict, json, t0, extra);
}

// "3,7-9" -> {3, 7, 8, 9}.
std::vector<int> parse_unit_ids(const std::string& text) {
  static const std::regex item("^([0-9]+)(-([0-9]+))?$");
  std::vector<int> ids;
  for (const std::string& s : split_list(text, "--units")) {
    std::smatch m;
    if (!std::regex_match(s, m, item) || m[1].length() > 9 || m[3].length() > 9) {
      throw UsageError(fmt::format("--units: expected unit ids and ranges like 3,7-9, found '{}'", s));
    }
    const int lo = std::stoi(m[1].str());
    const int hi = m[3].matched ? std::stoi(m[3].str()) : lo;
    if (hi < lo || hi - lo > 1000000) throw UsageError(fmt::format("--units: expected a range LO-HI with LO <= HI, found '{}'", s));
    for (int id = lo; id <= hi; ++id) ids.push_back(id);
  }
  return ids;
}

// `run --list-units`: the campaign's unit ids and names, one per line (tab-separated), file order.
int list_units(const RunOptions& o) {
  const campaign::Campaign c = campaign::read_campaign(o.campaign);
  if (o.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& u : c.units) list.push_back({{"id", u.id}, {"name", u.name}});
    print_json({{"campaign", c.file.string()}, {"units", list}});
  } else {
    for (const auto& u : c.units) fmt::print("{}\t{}\n", u.id, u.name);
  }
  return 0;
}

// `run --part K/N` / `run --units LIST`: the units' analyses into OUT/part.json (campaign/part.hpp).
int run_part(const RunOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path file = fs::path(o.out) / "part.json";
  std::error_code ec;
  fs::remove(file, ec);  // a part that fails leaves none
  log_line("reading " + o.campaign);
  const campaign::Campaign c = campaign::read_campaign(o.campaign);
  std::vector<std::size_t> indices;
  std::string what;
  try {
    if (!o.part.empty()) {
      const auto slash = o.part.find('/');
      indices = campaign::part_indices(c, std::stoi(o.part.substr(0, slash)), std::stoi(o.part.substr(slash + 1)));
      what = "part " + o.part;
    } else {
      indices = campaign::unit_indices(c, parse_unit_ids(o.units));
      what = "units " + o.units;
    }
  } catch (const InputError& e) {
    throw UsageError(e.what());  // a command-line value the campaign refuses: exit 2
  }
  const std::vector<campaign::UnitAnalysis> units = campaign::analyze_units(c, indices, pipeline_options(o.threads));
  const fs::path written = campaign::write_part(c, units, o.out);
  const double elapsed = seconds_since(t0);
  std::vector<int> ids;
  for (const auto& u : units) ids.push_back(u.id);
  if (o.json) {
    print_json({{"part", written.string()}, {"units", ids}, {"campaign", c.file.string()}, {"campaign_hash", campaign::campaign_hash(c.file)},
                {"pipeline_seconds", elapsed}});
  } else {
    fmt::print("{}: {} of {} units ({}) analysed in {:.1f} s\n", what, units.size(), c.units.size(), fmt::join(ids, ", "), elapsed);
    fmt::print("part: {}\n", written.string());
  }
  return 0;
}

// `merge PART... --out DIR`: the batch over the parts' units; the outputs of a single `run`.
int run_merge(const MergeOptions& o) {
  const RunLock lock(o.out);
  const auto t0 = std::chrono::steady_clock::now();
  campaign::remove_outputs(o.out);
  std::vector<campaign::CampaignPart> parts;
  for (const auto& p : o.parts) parts.push_back(campaign::read_part(p));
  log_line(fmt::format("{} parts of {}", parts.size(), parts.front().campaign));
  campaign::Campaign c = campaign::read_campaign(parts.front().campaign_path);
  std::vector<campaign::UnitAnalysis> units = campaign::merge_parts(c, parts);
  c.file = parts.front().campaign;  // as given to `run`: results.json names it the same way
  return write_and_print(campaign::finish_campaign(c, std::move(units), pipeline_options(0)), o.out, o.strict, o.json, t0);
}

int run_run(const RunOptions& o) {
  if (o.threads < 0) throw UsageError("--threads", "0 (all cores) or more", std::to_string(o.threads));
  if (o.list_units) return list_units(o);
  const RunLock lock(o.out);  // a second run on the same --out is refused (exit 3)
  if (!o.part.empty() || !o.units.empty()) return run_part(o);
  return run_pipeline(o.campaign, o.out, o.strict, o.json, o.threads);
}

int run_demo(const DemoCli& o) {
  if (o.threads < 0) throw UsageError("--threads", "0 (all cores) or more", std::to_string(o.threads));
  const RunLock lock(o.out);
  const auto t0 = std::chrono::steady_clock::now();
  campaign::DemoOptions d;
  d.seed = o.seed;
  d.fast = o.fast;
  d.threads = o.threads;
  if (!o.units.empty()) {
    d.units.clear();
    for (const double u : parse_number_list(o.units, "--units")) {
      if (u != std::floor(u) || u < 1 || u > 7) throw UsageError("--units", "unit numbers 1..7", fmt::format("{}", u));
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
  auto* list = run->add_flag("--list-units", r->list_units, "Print the campaign's unit ids and names, one per line (file order), and stop");
  auto* part = run->add_option("--part", r->part, "Analyse only part K of N of the units (K, K+N, K+2N, ...) into OUT/part.json, for `merge`")
                   ->check(CLI::Validator(
                       [](const std::string& v) {
                         static const std::regex re("^[1-9][0-9]{0,5}/[1-9][0-9]{0,5}$");
                         if (!std::regex_match(v, re)) return std::string("expected K/N (e.g. 2/8), found '") + v + "'";
                         const auto slash = v.find('/');
                         if (std::stoi(v.substr(0, slash)) > std::stoi(v.substr(slash + 1))) return "K above N in '" + v + "'";
                         return std::string();
                       },
                       "K/N", ""));
  auto* units = run->add_option("--units", r->units, "Analyse only these unit ids (e.g. 3,7-9) into OUT/part.json, for `merge`");
  part->excludes(units);
  list->excludes(part);
  list->excludes(units);
  run->callback([r, &action] { action = [r] { return run_run(*r); }; });

  auto m = std::make_shared<MergeOptions>();
  CLI::App* merge = app.add_subcommand("merge", "Merge the parts of a split campaign (run --part/--units): the outputs of a single run");
  merge->add_option("parts", m->parts, "Part folders (each with the part.json of `run --part K/N` or `run --units LIST`)")->required();
  merge->add_option("--out", m->out, "Output folder (results.json, results.mat, report.html)")->capture_default_str();
  merge->add_flag("--strict", m->strict, "Exit with code 5 when a unit is rejected");
  merge->add_flag("--json", m->json, "Print the results as one JSON document on stdout");
  merge->callback([m, &action] { action = [m] { return run_merge(*m); }; });

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

  auto fields_out = std::make_shared<std::string>();
  CLI::App* fields = app.add_subcommand("fields", "Print the reference of every result field (docs/fields.md) from their declarations");
  fields->add_option("--out", *fields_out, "Write it to this file instead of stdout");
  fields->callback([fields_out, &action] {
    action = [fields_out] {
      const std::string doc = field_reference_markdown();
      if (fields_out->empty()) {
        fmt::print("{}", doc);
      } else {
        io::write_text_atomically(*fields_out, doc);
      }
      return 0;
    };
  });
}

}  // namespace piezobench::app
