#include "piezobench/station/phase_runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/campaign/unit_analysis.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/station/certificate.hpp"

namespace piezobench::station {

namespace fs = std::filesystem;
using campaign::Experiment;

std::string campaign_header(const StationFile& station) {
  return fmt::format("# The campaign of station '{}' ({}); docs/campaign.md\n{}\n{}\n", station.name, station.file.filename().string(),
                     station.campaign_tables, station.campaign_specs());
}

std::string unit_campaign_entry(int id, const std::string& name, const StationFile& station, const std::vector<PhaseTryRow>& kept) {
  toml::table unit;
  unit.insert("id", id);
  unit.insert("name", name);
  toml::array hysteresis, iff;
  for (const PhaseTryRow& t : kept) {
    const PhaseSpec* p = station.phase(t.phase_name);
    if (p == nullptr || t.raw_files.empty()) continue;
    const std::string& file = t.raw_files.front().path;
    if (p->record == Experiment::kHysteresis) {
      hysteresis.push_back(file);
    } else if (p->record == Experiment::kIff) {
      iff.push_back(toml::table{{"file", file}, {"gain", p->gain.value_or(0.0)}});
    } else {
      unit.insert_or_assign(campaign::to_string(p->record), file);
    }
  }
  if (!hysteresis.empty()) unit.insert("hysteresis", hysteresis);
  if (!iff.empty()) unit.insert("iff", iff);
  toml::array units;
  units.push_back(std::move(unit));
  std::ostringstream s;
  s << toml::toml_formatter(toml::table{{"units", units}}) << "\n";
  return s.str();
}

std::string export_campaign(const RecordStore& store, const std::string& batch) {
  std::vector<QualificationRow> rows = store.list(batch, 1 << 30);
  std::reverse(rows.begin(), rows.end());  // oldest first
  std::vector<std::string> serials;
  std::map<std::string, std::int64_t> latest;
  for (const QualificationRow& q : rows) {
    if (q.status != "complete") continue;
    if (latest.find(q.serial) == latest.end()) serials.push_back(q.serial);
    latest[q.serial] = q.id;
  }
  if (serials.empty()) throw InputError(store.file().string(), "--batch", "a batch with a completed qualification", "'" + batch + "'");
  std::string header, units;
  std::string first;
  std::map<long, std::string> ids;
  for (const std::string& serial : serials) {
    const QualificationRow q = *store.qualification(latest[serial]);
    const auto split = q.campaign_toml.find("[[units]]");
    const std::string h = q.campaign_toml.substr(0, split);
    if (header.empty()) {
      header = h;
      first = serial;
    } else if (h != header) {
      throw InputError(store.file().string(), "--batch " + batch, "units qualified with one station file (the campaign of " + first + ")",
                       serial + " with another (station sha256 " + q.station_sha256 + ")");
    }
    const std::string entry = q.campaign_toml.substr(split);
    const toml::table t = toml::parse(entry);
    const long id = static_cast<long>(t["units"][0]["id"].value_or(std::int64_t{0}));
    if (const auto [it, fresh] = ids.emplace(id, serial); !fresh) {
      throw InputError(store.file().string(), "--batch " + batch, "a campaign id per unit (qualify --unit)",
                       fmt::format("{} and {} both with id {}", it->second, serial, id));
    }
    units += entry;
  }
  return header + units;
}

namespace {

// The records a phase's analysis needs besides its own.
std::vector<Experiment> dependencies(Experiment e) {
  if (e == Experiment::kFrf) return {Experiment::kCapacitance};
  if (e == Experiment::kFrfNoResistor || e == Experiment::kIff) return {Experiment::kCapacitance, Experiment::kFrf};
  return {};
}

double setting(const std::map<std::string, io::Setting>& s, const char* key) {
  const auto it = s.find(key);
  return it != s.end() && std::holds_alternative<double>(it->second) ? std::get<double>(it->second) : 0.0;
}

// The checks of a record's settings: saturation and lost samples. Empty when they pass.
std::vector<std::string> record_checks(const PhaseSpec& p, const std::map<std::string, io::Setting>& s) {
  std::vector<std::string> out;
  for (const char* key : {"clamped_samples", "slew_limited_samples"}) {
    const double n = setting(s, key);
    if (n > static_cast<double>(p.max_clamped_samples)) {
      out.push_back(fmt::format("saturation: {} {} (at most {} allowed)", n, key, p.max_clamped_samples));
    }
  }
  for (const char* key : {"io_lost", "stale_samples"}) {
    const double n = setting(s, key);
    if (n > 0.0) out.push_back(fmt::format("lost samples: {} {}", n, key));
  }
  return out;
}

std::optional<std::string> coherence_check(const PhaseSpec& p, const campaign::Campaign& c, const campaign::UnitAnalysis& ua) {
  if (p.min_coherence <= 0.0) return std::nullopt;
  const dsp::Frf* frf = campaign::frf_of(ua);
  if (!frf || frf->coherence.empty()) return "coherence: the FRF has none";
  const Eigen::Index de = frf->output_index("de");
  double sum = 0.0;
  long n = 0;
  for (Eigen::Index k = 0; k < frf->freq_Hz.size(); ++k) {
    const double f = frf->freq_Hz(k);
    if (f < c.analysis.fmin_Hz || f > c.analysis.fmax_Hz) continue;
    sum += frf->coherence[static_cast<std::size_t>(de)](k);
    ++n;
  }
  const double mean = n > 0 ? sum / static_cast<double>(n) : 0.0;
  if (mean >= p.min_coherence) return std::nullopt;
  return fmt::format("coherence: mean coherence of u -> d_e in [{:g}, {:g}] Hz {:.3f} below {:g}", c.analysis.fmin_Hz, c.analysis.fmax_Hz,
                     mean, p.min_coherence);
}

struct Context {
  const StationFile& station;
  Instrument& instrument;
  Operator& op;
  RecordStore& store;
  const QualifyOptions& options;
  QualificationRow q;
  std::vector<PhaseTryRow> kept;  // in phase order
  void say(const std::string& line) const {
    if (options.log) options.log(line);
  }
  void prompt(const std::string& text) const {
    if (options.observer) options.observer->prompt(options.serial, text);
  }
  [[nodiscard]] fs::path campaign_path() const { return options.data_dir / options.serial / "campaign.toml"; }
  [[nodiscard]] campaign::Campaign campaign_of(const std::vector<PhaseTryRow>& tries) const {
    return campaign::parse_campaign(campaign_header(station) + unit_campaign_entry(options.unit_id, options.serial, station, tries),
                                    campaign_path());
  }
};

// Analyses a try's record with the kept records it depends on; fills the try's measurements and
// verdict; returns the failed checks.
std::vector<std::string> analyse_try(const Context& cx, const PhaseSpec& p, PhaseTryRow& row, const Acquired& a) {
  std::vector<std::string> failed = record_checks(p, a.settings);
  std::vector<PhaseTryRow> records;
  for (const Experiment d : dependencies(p.record)) {
    for (const PhaseTryRow& k : cx.kept) {
      const PhaseSpec* kp = cx.station.phase(k.phase_name);
      if (kp && kp->record == d) records.push_back(k);
    }
  }
  records.push_back(row);
  std::optional<campaign::UnitAnalysis> ua;
  std::optional<campaign::Campaign> c;
  try {
    c = cx.campaign_of(records);
    ua = campaign::analyze_unit(*c, c->units.front());
  } catch (const InputError& e) {
    failed.push_back(std::string("analysis: ") + e.what());
  }
  if (ua) {
    for (const std::string& f : ua->failed) failed.push_back("analysis: " + f);
    if (auto coh = coherence_check(p, *c, *ua)) failed.push_back(*coh);
  }
  Verdict v = failed.empty() ? Verdict::kPass : Verdict::kFail;
  for (const MeasurementSpec& m : p.measurements) {
    const MeasurementKind& kind = *find_measurement(m.name);
    const std::optional<double> value = ua ? measured_value(*ua, m.name, row.raw_files.front().path) : std::nullopt;
    const MeasuredValue j = judge(kind, value, m.limit, cx.station.margin_relative);
    row.measurements.push_back({j.name, j.unit, j.value, m.limit.min, m.limit.max, to_string(j.verdict), j.reason, m.stop_on_fail});
    v = worst(v, j.verdict);
  }
  row.verdict = to_string(v);
  return failed;
}

enum class PhaseOutcome { kKept, kAborted, kBenchFailed };

std::string join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

// One try: acquire, record, analyse. Returns the failed checks (empty: kept); sets bench_error
// when the bench failed.
std::vector<std::string> run_try(Context& cx, int index, const PhaseSpec& p, const PhaseValues& values, PhaseTryRow& row,
                                 std::optional<std::string>& bench_error) {
  if (cx.options.observer) cx.options.observer->phase_started(cx.options.serial, p, row.try_number);
  cx.say(fmt::format("qualify {}: phase {}/{} {} (try {})", cx.options.serial, index + 1, cx.station.phases.size(), p.name, row.try_number));
  const fs::path stem = cx.options.data_dir / cx.options.serial / fmt::format("q{}-{}-try{}", cx.q.id, p.name, row.try_number);
  Acquired a;
  try {
    a = cx.instrument.acquire(p, values, stem);
  } catch (const InputError& e) {
    bench_error = e.what();
    return {std::string("bench: ") + e.what()};
  }
  row.raw_files.push_back({fs::absolute(a.file).lexically_normal().string(), campaign::to_string(p.record), sha256_file(a.file),
                           static_cast<std::int64_t>(fs::file_size(a.file))});
  return analyse_try(cx, p, row, a);
}

PhaseOutcome run_phase(Context& cx, int index, const PhaseSpec& p) {
  for (std::size_t s = 0; s < p.steps.size(); ++s) {
    cx.prompt(p.steps[s]);
    if (cx.op.step(p, s) == StepAnswer::kAbort) {
      cx.say(fmt::format("qualify {}: aborted by the operator at phase {}: {}", cx.options.serial, p.name, p.steps[s]));
      return PhaseOutcome::kAborted;
    }
  }
  const PhaseValues values = cx.op.values(p);
  for (long attempt = 0;; ++attempt) {
    PhaseTryRow row = cx.store.begin_phase_try(cx.q.id, index, p.name);
    std::optional<std::string> bench_error;
    const std::vector<std::string> failed = run_try(cx, index, p, values, row, bench_error);
    row.finished = utc_now();
    CheckAnswer answer = CheckAnswer::kContinue;
    if (bench_error) {
      row.status = "failed";
      row.verdict = to_string(Verdict::kFail);
    } else if (!failed.empty()) {
      cx.prompt(fmt::format("phase {} failed its checks: {}", p.name, join(failed, "; ")));
      answer = cx.op.check_failed(p, row.try_number, join(failed, "; "));
      if (answer == CheckAnswer::kRetry && attempt >= p.retries) answer = CheckAnswer::kContinue;  // no retry left
      row.status = answer == CheckAnswer::kContinue ? "complete" : "failed";
    } else {
      row.status = "complete";
    }
    row.reason = join(failed, "; ");
    cx.store.finish_phase_try(row);
    if (cx.options.observer) cx.options.observer->phase_finished(cx.options.serial, row);
    cx.say(fmt::format("qualify {}: phase {} try {}: {} ({}){}", cx.options.serial, p.name, row.try_number, row.status, row.verdict,
                       row.reason.empty() ? "" : ": " + row.reason));
    if (bench_error) return PhaseOutcome::kBenchFailed;
    if (answer == CheckAnswer::kAbort) return PhaseOutcome::kAborted;
    if (row.status == "complete") {
      cx.kept.push_back(std::move(row));
      return PhaseOutcome::kKept;
    }
  }
}

bool stops(const PhaseTryRow& t) {
  return std::any_of(t.measurements.begin(), t.measurements.end(),
                     [](const MeasurementRow& m) { return m.stop_on_fail && m.verdict == to_string(Verdict::kFail); });
}

// Resume: the kept tries of the newest unfinished qualification, their raw files checked.
void load_resume(Context& cx) {
  const auto q = cx.store.latest_qualification(cx.options.serial);
  if (!q || q->status == "complete") {
    throw InputError(cx.store.file().string(), "--resume " + cx.options.serial, "a qualification of the unit that did not complete",
                     q ? "its newest qualification is complete" : "no qualification of this serial");
  }
  if (q->station_sha256 != cx.options.station_sha256) {
    throw InputError(cx.station.file.string(), "--station", "the station file the qualification started with (sha256 " + q->station_sha256 + ")",
                     "a file with sha256 " + cx.options.station_sha256);
  }
  cx.q = *q;
  const int interrupted = cx.store.mark_interrupted(q->id);
  if (interrupted > 0) cx.say(fmt::format("qualify {}: {} try left running by a stopped process marked interrupted", cx.options.serial, interrupted));
  for (PhaseTryRow& t : cx.store.phase_tries(q->id)) {
    if (t.status != "complete") continue;
    for (const RawFileRow& f : t.raw_files) {
      if (!fs::is_regular_file(f.path) || sha256_file(f.path) != f.sha256) {
        throw InputError(f.path, "sha256", "the raw file recorded for phase " + t.phase_name + " (" + f.sha256 + ")",
                         fs::is_regular_file(f.path) ? "a file with other contents" : "no file");
      }
    }
    cx.kept.push_back(std::move(t));
  }
}

// The unit's verdict from its kept phases and the pipeline's acceptance.
void decide(const Context& cx, const campaign::UnitAnalysis& ua, QualifyResult& r) {
  r.verdict = Verdict::kPass;
  for (const PhaseSpec& p : cx.station.phases) {
    for (const PhaseTryRow& t : cx.kept) {
      if (t.phase_name != p.name) continue;
      const Verdict v = verdict_from_string(t.verdict);
      if (!t.reason.empty()) r.reasons.push_back(p.name + ": " + t.reason);
      for (const MeasurementRow& m : t.measurements) {
        if (!m.reason.empty()) r.reasons.push_back(p.name + ": " + m.verdict + ": " + m.reason);
      }
      if (static_cast<int>(v) <= static_cast<int>(r.verdict) && !(r.deciding_phase.empty() && v != Verdict::kPass)) continue;
      r.verdict = v;
      r.deciding_phase = p.name;
      r.deciding_measurement = t.reason.empty() ? "" : "checks";
      for (const MeasurementRow& m : t.measurements) {
        if (m.verdict == to_string(v)) {
          r.deciding_measurement = m.name;
          break;
        }
      }
    }
  }
  if (!ua.accepted) {
    for (const std::string& reason : ua.reasons) r.reasons.push_back("campaign: " + reason);
    if (r.verdict != Verdict::kFail) {
      r.verdict = Verdict::kFail;
      r.deciding_phase = "analysis";
      r.deciding_measurement = ua.reasons.empty() ? "" : ua.reasons.front();
    }
  }
}

// CPU time of the whole process (every thread), s.
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

QualifyResult finish(Context& cx, const std::string& status, QualifyResult r) {
  r.qualification_id = cx.q.id;
  r.status = status;
  cx.q.status = status;
  cx.q.finished = utc_now();
  if (status == "complete") {
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = process_cpu_seconds();
    const campaign::Campaign c = cx.campaign_of(cx.kept);
    campaign::CampaignResult cr = campaign::run_campaign(c);
    r.analysis_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.analysis_cpu_seconds = process_cpu_seconds() - cpu0;
    decide(cx, cr.units.front(), r);
    cx.q.verdict = to_string(r.verdict);
    cx.q.deciding_phase = r.deciding_phase;
    cx.q.deciding_measurement = r.deciding_measurement;
    cx.q.reasons = join(r.reasons, "\n");
    cx.q.campaign_toml = campaign_header(cx.station) + unit_campaign_entry(cx.options.unit_id, cx.options.serial, cx.station, cx.kept);
    cx.q.results_json = campaign::unit_json(cr.units.front()).dump();
    r.unit = std::move(cr.units.front());
    if (cx.options.observer) cx.options.observer->verdict(cx.options.serial, r.verdict, r.deciding_phase, r.deciding_measurement);
  }
  cx.store.finish_qualification(cx.q);
  if (status == "complete") {
    // The certificate from the database's rows (db certificate regenerates the same bytes).
    const std::string html = certificate_html(*cx.store.qualification(cx.q.id), cx.store.phase_tries(cx.q.id));
    r.certificate = cx.options.data_dir / cx.options.serial / fmt::format("certificate-q{}.html", cx.q.id);
    write_text_atomically(r.certificate, html);
    cx.store.set_certificate(cx.q.id, sha256_text(html));
  }
  return r;
}

}  // namespace

QualifyResult qualify(const StationFile& station, Instrument& instrument, Operator& op, RecordStore& store, const QualifyOptions& options) {
  instrument.check(station);
  Context cx{station, instrument, op, store, options, {}, {}};
  std::error_code ec;
  fs::create_directories(options.data_dir / options.serial, ec);
  if (ec) throw InputError((options.data_dir / options.serial).string(), "--data", "a folder that can be created", ec.message());
  QualifyResult r;
  if (options.resume) {
    load_resume(cx);
  } else {
    QualificationRow q;
    q.serial = options.serial;
    q.batch = options.batch;
    q.station = station.name;
    q.station_sha256 = options.station_sha256;
    q.operator_name = op.name();
    q.bench_file = options.bench_file;
    q.bench_sha256 = options.bench_sha256;
    q.software_version = options.software_version;
    q.started = utc_now();
    q.id = store.begin_qualification(q);
    cx.q = q;
  }
  for (std::size_t i = 0; i < station.phases.size(); ++i) {
    const PhaseSpec& p = station.phases[i];
    const auto kept = std::find_if(cx.kept.begin(), cx.kept.end(), [&](const PhaseTryRow& t) { return t.phase_name == p.name; });
    if (kept != cx.kept.end()) {
      r.resumed_phases.push_back(p.name);
      if (stops(*kept)) break;
      continue;
    }
    if (options.stop && options.stop->load()) {
      cx.say(fmt::format("qualify {}: interrupted before phase {}", options.serial, p.name));
      return finish(cx, "aborted", std::move(r));
    }
    const PhaseOutcome o = run_phase(cx, static_cast<int>(i), p);
    if (o == PhaseOutcome::kAborted) return finish(cx, "aborted", std::move(r));
    if (o == PhaseOutcome::kBenchFailed) return finish(cx, "failed", std::move(r));
    if (stops(cx.kept.back())) {
      cx.say(fmt::format("qualify {}: phase {} failed a stop_on_fail measurement: the qualification stops", options.serial, p.name));
      break;
    }
  }
  return finish(cx, "complete", std::move(r));
}

}  // namespace piezobench::station
