// `piezobench qualify`: one unit through the station's phases on a bench, recorded in the station
// database; `piezobench db list|show|export`: what the database holds (docs/station.md).
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "measure_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/station/certificate.hpp"
#include "piezobench/station/phase_runner.hpp"
#include "piezobench/station/record_json.hpp"
#include "piezobench/version.hpp"
#include "piezobench/web/web_operator.hpp"
#include "station_ui.hpp"

namespace piezobench::app {

namespace {

namespace fs = std::filesystem;
using station::Verdict;
using station::qualification_json;

struct QualifyCli {
  std::string bench, station, serial, resume, answers, db = "station.db", data = "station-data", batch, operator_name;
  int unit = 0;
  std::uint64_t seed = 0;
  CLI::Option *unit_option = nullptr, *seed_option = nullptr;
  bool paced = false, strict = false, json = false;
  UiCli ui;
};

void check_serial(const std::string& option, const std::string& serial) {
  const bool ok = !serial.empty() && serial.size() <= 64 && serial.front() != '.' &&
                  std::all_of(serial.begin(), serial.end(), [](char c) {
                    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.';
                  });
  if (!ok) throw UsageError(option, "a serial number of letters, digits, '-', '_' and '.' (at most 64)", "'" + serial + "'");
}

void print_qualification(const station::QualificationRow& q, const std::vector<station::PhaseTryRow>& tries) {
  fmt::print("{} (batch '{}'): {} {}, station '{}', operator '{}', {} .. {}\n", q.serial, q.batch, q.status,
             q.verdict.empty() ? "" : "verdict " + q.verdict, q.station, q.operator_name, q.started, q.finished);
  for (const auto& t : tries) {
    fmt::print("  {:<18} try {} {:<11} {:<8}{}\n", t.phase_name, t.try_number, t.status, t.verdict, t.reason.empty() ? "" : "  " + t.reason);
    for (const auto& m : t.measurements) {
      fmt::print("      {:<32} {:>12} {:<5} [{}, {}] {}\n", m.name, m.value ? fmt::format("{:.5g}", *m.value) : "none", m.unit,
                 m.min ? fmt::format("{:g}", *m.min) : "", m.max ? fmt::format("{:g}", *m.max) : "", m.verdict);
    }
  }
  if (!q.deciding_phase.empty()) fmt::print("decided by phase {}, {}\n", q.deciding_phase, q.deciding_measurement);
}

int run_qualify(const QualifyCli& o) {
  if (o.serial.empty() == o.resume.empty()) throw UsageError("--serial", "exactly one of --serial SN and --resume SN", "both or neither");
  const std::string serial = o.serial.empty() ? o.resume : o.serial;
  check_serial(o.serial.empty() ? "--resume" : "--serial", serial);
  // Everything is read and checked before anything moves.
  const rt::BenchDescription bench = rt::read_bench_file(o.bench);
  const station::StationFile st = station::read_station_file(o.station);
  std::unique_ptr<station::Operator> op;
  if (!o.answers.empty()) {
    op = std::make_unique<station::AnswersOperator>(station::read_answers(o.answers, st));
  } else if (o.ui.listen.empty()) {
    op = std::make_unique<station::TerminalOperator>(std::cin, std::cerr, o.operator_name);
  }
  // The live page (--ui): the hub follows the runner and the records; the page's operator answers
  // the prompts with the terminal (an answers file still answers alone).
  std::unique_ptr<web::LiveHub> hub;
  if (!o.ui.listen.empty()) {
    hub = std::make_unique<web::LiveHub>();
    web::WebOperatorOptions wo;
    wo.inner = std::move(op);
    wo.name = o.operator_name;
    wo.stop = stop_on_sigint();
    op = std::make_unique<web::WebOperator>(*hub, std::move(wo));
  }
  station::BenchInstrumentOptions bo;
  bo.bench = bench;
  bo.unit = o.unit_option->count() > 0 ? o.unit : bench.unit;
  bo.seed = o.seed_option->count() > 0 ? o.seed : bench.seed;
  bo.paced = o.paced;
  bo.make_backend = [](const rt::BenchDescription& b) { return make_backend(b); };
  bo.operator_fd = o.answers.empty() ? 0 : -1;
  bo.stop = stop_on_sigint();
  bo.log = log_line;
  if (!bench.hardware() && (bo.unit < 1 || bo.unit > 7)) throw UsageError("--unit", "a unit of the virtual batch, 1 to 7", std::to_string(bo.unit));
  if (o.paced && bench.hardware()) throw UsageError("--paced", "the virtual bench (hardware is paced by its clock)", "backend " + bench.backend);
  if (hub) bo.on_record = [&hub](const io::TimeSeries& ts, std::chrono::steady_clock::time_point start) { hub->record(ts, start); };
  // Hardware: the signals while each record runs, from the loop's log (its logger thread).
  if (hub && bench.hardware()) bo.live_tap = hub->loop_tap(bench.sample_rate);
  station::BenchInstrument instrument(bo);
  station::RecordStore store(o.db);
  std::optional<StationUi> ui;
  if (hub) {
    hub->plan(st, serial, o.batch, expected_phase_durations(store, st.name));
    if (!o.resume.empty()) {
      // The phases kept by the run being resumed: shown finished, as they will not run again.
      const auto q = store.latest_qualification(serial);
      if (q && q->status != "complete") {
        for (const auto& t : store.phase_tries(q->id)) {
          if (t.status == "complete") hub->phase_finished(serial, t);
        }
      }
    }
    ui.emplace(o.ui, o.db, hub.get());
  }
  station::QualifyOptions qo;
  qo.serial = serial;
  qo.batch = o.batch;
  qo.unit_id = bo.unit;
  qo.data_dir = fs::absolute(o.data);
  qo.station_sha256 = station::sha256_file(o.station);
  qo.bench_file = fs::absolute(o.bench).string();
  qo.bench_sha256 = station::sha256_file(o.bench);
  qo.software_version = std::string("piezobench ") + kVersion;
  qo.resume = !o.resume.empty();
  qo.stop = bo.stop;
  qo.log = log_line;
  qo.observer = hub.get();
  const station::QualifyResult r = station::qualify(st, instrument, *op, store, qo);
  if (hub) hub->finished(r.status, !r.certificate.empty());
  const auto q = store.qualification(r.qualification_id);
  if (o.json) {
    nlohmann::json doc = qualification_json(*q, store.phase_tries(r.qualification_id));
    doc["resumed_phases"] = r.resumed_phases;
    doc["reasons"] = r.reasons;
    doc["analysis_seconds"] = r.analysis_seconds;
    doc["analysis_cpu_seconds"] = r.analysis_cpu_seconds;
    doc["database"] = o.db;
    doc["certificate"] = r.certificate.string();
    print_json(doc);
  } else {
    print_qualification(*q, store.phase_tries(r.qualification_id));
    for (const auto& reason : r.reasons) fmt::print("  - {}\n", reason);
  }
  std::fflush(stdout);
  if (ui) ui->linger(qo.stop);
  if (r.status != "complete") {
    throw InputError(o.db, "qualification " + serial,
                     "a completed qualification",
                     fmt::format("{} (resume with: piezobench qualify --bench {} --station {} --resume {}{})", r.status, o.bench, o.station,
                                 serial, o.answers.empty() ? "" : " --answers " + o.answers));
  }
  return o.strict && r.verdict == Verdict::kFail ? 5 : 0;
}

struct DbCli {
  std::string db = "station.db", serial, batch, out;
  bool json = false;
};

int run_db_list(const DbCli& o) {
  station::RecordStore store(o.db);
  const auto rows = store.list(o.batch);
  if (o.json) {
    nlohmann::json doc = nlohmann::json::array();
    for (const auto& q : rows) doc.push_back(qualification_json(q, {}));
    print_json(doc);
    return 0;
  }
  for (const auto& q : rows) {
    fmt::print("{:>6}  {:<16} {:<10} {:<9} {:<8} {}  {}\n", q.id, q.serial, q.batch, q.status, q.verdict, q.started,
               q.deciding_phase.empty() ? "" : q.deciding_phase + ": " + q.deciding_measurement);
  }
  return 0;
}

int run_db_show(const DbCli& o) {
  station::RecordStore store(o.db);
  const auto q = store.latest_qualification(o.serial);
  if (!q) throw InputError(o.db, "serial", "a unit the database holds", "'" + o.serial + "'");
  const auto tries = store.phase_tries(q->id);
  if (o.json) {
    nlohmann::json doc = qualification_json(*q, tries);
    doc["reasons"] = q->reasons;
    doc["results"] = q->results_json.empty() ? nlohmann::json(nullptr) : nlohmann::json::parse(q->results_json);
    print_json(doc);
  } else {
    print_qualification(*q, tries);
  }
  return 0;
}

int run_db_export(const DbCli& o) {
  station::RecordStore store(o.db);
  const std::string text = station::export_campaign(store, o.batch);
  write_text_atomically(o.out, text);
  log_line(fmt::format("db export: batch '{}' written to {}", o.batch, o.out));
  return 0;
}

int run_db_certificate(const DbCli& o) {
  station::RecordStore store(o.db);
  const auto q = store.latest_qualification(o.serial);
  if (!q || q->status != "complete") throw InputError(o.db, "serial", "a unit with a completed qualification", "'" + o.serial + "'");
  const std::string html = station::certificate_html(*q, store.phase_tries(q->id));
  const std::string sha = station::sha256_text(html);
  write_text_atomically(o.out, html);
  fmt::print("{}: sha256 {} ({} the one stored with qualification {})\n", o.out, sha, sha == q->certificate_sha256 ? "equal to" : "DIFFERENT from",
             q->id);
  if (sha != q->certificate_sha256) throw InputError(o.db, "certificate_sha256", q->certificate_sha256, sha);
  return 0;
}

int run_db_charts(const DbCli& o) {
  station::RecordStore store(o.db);
  const auto charts = station::control_charts(store, o.batch);
  const std::string title = o.batch.empty() ? "Control charts, every batch" : "Control charts, batch " + o.batch;
  write_text_atomically(o.out, station::control_charts_html(charts, title));
  for (const auto& c : charts) {
    log_line(fmt::format("{}: {} units, mean {:.5g} {}, 3 sigma {:.3g}, {} marginal, {} failed", c.quantity, c.points.size(), c.mean, c.unit,
                         3 * c.sigma, c.marginal, c.failed));
  }
  return 0;
}

int run_db_check(const DbCli& o) {
  station::RecordStore store(o.db);
  const std::string result = store.integrity_check();
  fmt::print("{}\n", result);
  if (result != "ok") throw InputError(o.db, "PRAGMA integrity_check", "ok", result);
  return 0;
}

}  // namespace

void add_qualify_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<QualifyCli>();
  CLI::App* q = app.add_subcommand("qualify", "Run one unit through a station's phases on a bench and record it (docs/station.md)");
  q->add_option("--bench", o->bench, "bench file (TOML, docs/hardware.md)")->required()->check(input_file());
  q->add_option("--station", o->station, "station file (TOML, docs/station.md)")->required()->check(input_file());
  q->add_option("--serial", o->serial, "serial number of the unit under test");
  q->add_option("--resume", o->resume, "serial number of an unfinished qualification to continue at its first incomplete phase");
  q->add_option("--answers", o->answers, "the operator's answers (TOML) instead of prompts on the terminal")->check(input_file());
  q->add_option("--db", o->db, "station database (SQLite)")->capture_default_str();
  q->add_option("--data", o->data, "folder of the raw files (DATA/SERIAL/...)")->capture_default_str();
  q->add_option("--batch", o->batch, "batch of the unit (db export --batch)");
  q->add_option("--operator", o->operator_name, "operator's name (terminal prompts; an answers file gives its own)");
  o->unit_option = q->add_option("--unit", o->unit, "virtual bench: the unit of the batch, 1..7 (default: the bench file's); the campaign id");
  o->seed_option = q->add_option("--seed", o->seed, "virtual bench: seed (default: the bench file's)");
  q->add_flag("--paced", o->paced, "virtual bench: each record takes its real duration");
  q->add_flag("--strict", o->strict, "exit 5 when the unit's verdict is fail");
  q->add_flag("--json", o->json, "print the qualification as one JSON document");
  add_ui_options(q, o->ui, "");
  q->callback([o, &action] { action = [o] { return run_qualify(*o); }; });

  auto d = std::make_shared<DbCli>();
  CLI::App* db = app.add_subcommand("db", "The station database: list, show, export (docs/station.md)");
  db->require_subcommand(1);
  const auto database = [&d](CLI::App* sub) { sub->add_option("--db", d->db, "station database (SQLite)")->capture_default_str(); };
  CLI::App* list = db->add_subcommand("list", "Qualifications, newest first");
  list->add_option("--batch", d->batch, "only this batch");
  list->add_flag("--json", d->json, "as JSON");
  database(list);
  list->callback([d, &action] { action = [d] { return run_db_list(*d); }; });
  CLI::App* show = db->add_subcommand("show", "The newest qualification of a unit: tries, measurements, raw files");
  show->add_option("serial", d->serial, "serial number")->required();
  show->add_flag("--json", d->json, "as JSON (with the per-unit results)");
  database(show);
  show->callback([d, &action] { action = [d] { return run_db_show(*d); }; });
  CLI::App* exp = db->add_subcommand("export", "A campaign file of a batch's qualified units that `piezobench run` accepts");
  exp->add_option("--batch", d->batch, "the batch")->required();
  exp->add_option("--out", d->out, "campaign file to write")->required();
  database(exp);
  exp->callback([d, &action] { action = [d] { return run_db_export(*d); }; });
  CLI::App* cert = db->add_subcommand("certificate", "Regenerate a unit's certificate (HTML) from the database; checks its stored SHA-256");
  cert->add_option("serial", d->serial, "serial number")->required();
  cert->add_option("--out", d->out, "HTML file to write")->required();
  database(cert);
  cert->callback([d, &action] { action = [d] { return run_db_certificate(*d); }; });
  CLI::App* charts = db->add_subcommand("charts", "Control charts across units and batches (HTML): values, spec limits, mean +- 3 sigma");
  charts->add_option("--batch", d->batch, "only this batch (default: every batch)");
  charts->add_option("--out", d->out, "HTML file to write")->required();
  database(charts);
  charts->callback([d, &action] { action = [d] { return run_db_charts(*d); }; });
  CLI::App* check = db->add_subcommand("check", "PRAGMA integrity_check of the database (prints ok)");
  database(check);
  check->callback([d, &action] { action = [d] { return run_db_check(*d); }; });
}

}  // namespace piezobench::app
