#include "piezobench/station/record_store.hpp"

#include <fmt/format.h>
#include <nettle/sha2.h>
#include <sqlite3.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <thread>

#include "piezobench/core/error.hpp"

namespace piezobench::station {

namespace fs = std::filesystem;

namespace {

std::string hex(const std::uint8_t* d, std::size_t n) {
  std::string s;
  s.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:02x}", d[i]);
  return s;
}

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS unit (
  serial TEXT PRIMARY KEY, batch TEXT NOT NULL DEFAULT '', first_qualified TEXT NOT NULL, ordinal INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS qualification (
  id INTEGER PRIMARY KEY, serial TEXT NOT NULL REFERENCES unit(serial), batch TEXT NOT NULL DEFAULT '',
  station TEXT NOT NULL, station_sha256 TEXT NOT NULL, operator TEXT NOT NULL DEFAULT '',
  bench_file TEXT NOT NULL, bench_sha256 TEXT NOT NULL, software_version TEXT NOT NULL,
  started TEXT NOT NULL, finished TEXT NOT NULL DEFAULT '', status TEXT NOT NULL, verdict TEXT NOT NULL DEFAULT '',
  deciding_phase TEXT NOT NULL DEFAULT '', deciding_measurement TEXT NOT NULL DEFAULT '', reasons TEXT NOT NULL DEFAULT '',
  campaign_toml TEXT NOT NULL DEFAULT '', results_json TEXT NOT NULL DEFAULT '', certificate_sha256 TEXT NOT NULL DEFAULT '');
CREATE INDEX IF NOT EXISTS qualification_serial ON qualification(serial, id);
CREATE INDEX IF NOT EXISTS qualification_batch ON qualification(batch, status, id);
CREATE TABLE IF NOT EXISTS phase_try (
  id INTEGER PRIMARY KEY, qualification_id INTEGER NOT NULL REFERENCES qualification(id),
  phase_index INTEGER NOT NULL, phase_name TEXT NOT NULL, try_number INTEGER NOT NULL,
  started TEXT NOT NULL, finished TEXT NOT NULL DEFAULT '', status TEXT NOT NULL,
  reason TEXT NOT NULL DEFAULT '', verdict TEXT NOT NULL DEFAULT '',
  UNIQUE (qualification_id, phase_name, try_number));
CREATE TABLE IF NOT EXISTS measurement (
  id INTEGER PRIMARY KEY, phase_try_id INTEGER NOT NULL REFERENCES phase_try(id),
  name TEXT NOT NULL, unit TEXT NOT NULL, value REAL, min REAL, max REAL,
  verdict TEXT NOT NULL, reason TEXT NOT NULL DEFAULT '', stop_on_fail INTEGER NOT NULL DEFAULT 0);
CREATE INDEX IF NOT EXISTS measurement_try ON measurement(phase_try_id);
CREATE INDEX IF NOT EXISTS measurement_name ON measurement(name, phase_try_id);
CREATE TABLE IF NOT EXISTS raw_file (
  id INTEGER PRIMARY KEY, phase_try_id INTEGER NOT NULL REFERENCES phase_try(id),
  path TEXT NOT NULL, campaign_key TEXT NOT NULL, sha256 TEXT NOT NULL, bytes INTEGER NOT NULL);
CREATE INDEX IF NOT EXISTS raw_file_try ON raw_file(phase_try_id);
)sql";

// One prepared statement; bind by position from 1, columns from 0.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const fs::path& file) : file_(file) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s_, nullptr) != SQLITE_OK) {
      throw InputError(file.string(), "database", "a statement SQLite accepts", sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& bind(int i, std::int64_t v) {
    sqlite3_bind_int64(s_, i, v);
    return *this;
  }
  Statement& bind(int i, const std::optional<double>& v) {
    if (v) {
      sqlite3_bind_double(s_, i, *v);
    } else {
      sqlite3_bind_null(s_, i);
    }
    return *this;
  }
  // true while a row is available.
  bool step() {
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw InputError(file_.string(), "database", "a completed statement", sqlite3_errmsg(sqlite3_db_handle(s_)));
  }
  [[nodiscard]] std::string text(int c) const {
    const auto* p = sqlite3_column_text(s_, c);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(s_, c))) : std::string();
  }
  [[nodiscard]] std::int64_t integer(int c) const { return sqlite3_column_int64(s_, c); }
  [[nodiscard]] std::optional<double> real(int c) const {
    if (sqlite3_column_type(s_, c) == SQLITE_NULL) return std::nullopt;
    return sqlite3_column_double(s_, c);
  }

 private:
  sqlite3_stmt* s_ = nullptr;
  fs::path file_;
};

// BEGIN IMMEDIATE ... COMMIT, rolled back when an exception leaves the scope.
class Transaction {
 public:
  Transaction(sqlite3* db, const fs::path& file) : db_(db), file_(file) { run("BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    run("COMMIT");
    done_ = true;
  }

 private:
  void run(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string why = err ? err : "unknown";
      sqlite3_free(err);
      throw InputError(file_.string(), "database", std::string("a successful ") + sql, why);
    }
  }
  sqlite3* db_;
  fs::path file_;
  bool done_ = false;
};

constexpr const char* kQualificationColumns =
    "id, serial, batch, station, station_sha256, operator, bench_file, bench_sha256, software_version, started, finished, status, "
    "verdict, deciding_phase, deciding_measurement, reasons, campaign_toml, results_json, certificate_sha256";

QualificationRow read_qualification(const Statement& s) {
  QualificationRow q;
  q.id = s.integer(0);
  q.serial = s.text(1);
  q.batch = s.text(2);
  q.station = s.text(3);
  q.station_sha256 = s.text(4);
  q.operator_name = s.text(5);
  q.bench_file = s.text(6);
  q.bench_sha256 = s.text(7);
  q.software_version = s.text(8);
  q.started = s.text(9);
  q.finished = s.text(10);
  q.status = s.text(11);
  q.verdict = s.text(12);
  q.deciding_phase = s.text(13);
  q.deciding_measurement = s.text(14);
  q.reasons = s.text(15);
  q.campaign_toml = s.text(16);
  q.results_json = s.text(17);
  q.certificate_sha256 = s.text(18);
  return q;
}

}  // namespace

std::string sha256_text(const std::string& bytes) {
  sha256_ctx ctx;
  sha256_init(&ctx);
  sha256_update(&ctx, bytes.size(), reinterpret_cast<const std::uint8_t*>(bytes.data()));
  std::uint8_t d[SHA256_DIGEST_SIZE];
  sha256_digest(&ctx, SHA256_DIGEST_SIZE, d);
  return hex(d, SHA256_DIGEST_SIZE);
}

std::string sha256_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "a readable file", "it cannot be opened");
  sha256_ctx ctx;
  sha256_init(&ctx);
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const auto n = static_cast<std::size_t>(in.gcount());
    if (n > 0) sha256_update(&ctx, n, reinterpret_cast<const std::uint8_t*>(buf.data()));
  }
  if (in.bad()) throw InputError(file.string(), "file", "a readable file", "a read error");
  std::uint8_t d[SHA256_DIGEST_SIZE];
  sha256_digest(&ctx, SHA256_DIGEST_SIZE, d);
  return hex(d, SHA256_DIGEST_SIZE);
}

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:03d}Z", buf, static_cast<int>(ms));
}

RecordStore::RecordStore(const fs::path& file, int busy_timeout_ms) : file_(file) {
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw InputError(file.string(), "database", "an SQLite database that can be opened or created", why);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  try {
    // Two stations opening a new database at once: the switch to WAL needs the file alone for a
    // moment, and SQLite returns SQLITE_BUSY for it without calling the busy handler. Retried until
    // the busy timeout, as every other statement waits.
    const auto start = std::chrono::steady_clock::now();
    const auto waited_long_enough = [&] { return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(busy_timeout_ms); };
    for (;;) {
      try {
        exec("PRAGMA journal_mode=WAL");
        break;
      } catch (const InputError&) {
        const int rc = sqlite3_errcode(db_);
        if ((rc != SQLITE_BUSY && rc != SQLITE_LOCKED) || waited_long_enough()) throw;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    exec("PRAGMA synchronous=NORMAL");
    exec("PRAGMA foreign_keys=ON");
    Transaction t(db_, file_);
    exec(kSchema);
    t.commit();
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

RecordStore::~RecordStore() { sqlite3_close(db_); }

void RecordStore::exec(const std::string& sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string why = err ? err : sqlite3_errmsg(db_);
    sqlite3_free(err);
    throw InputError(file_.string(), "database", "a statement that succeeds", why);
  }
}

std::int64_t RecordStore::begin_qualification(const QualificationRow& q) {
  Transaction t(db_, file_);
  Statement(db_, "INSERT OR IGNORE INTO unit (serial, batch, first_qualified, ordinal) VALUES (?, ?, ?, (SELECT COUNT(*) FROM unit))", file_)
      .bind(1, q.serial)
      .bind(2, q.batch)
      .bind(3, q.started)
      .step();
  Statement s(db_,
              "INSERT INTO qualification (serial, batch, station, station_sha256, operator, bench_file, bench_sha256, software_version, "
              "started, status, campaign_toml) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, 'running', ?)",
              file_);
  s.bind(1, q.serial).bind(2, q.batch).bind(3, q.station).bind(4, q.station_sha256).bind(5, q.operator_name);
  s.bind(6, q.bench_file).bind(7, q.bench_sha256).bind(8, q.software_version).bind(9, q.started).bind(10, q.campaign_toml);
  s.step();
  const std::int64_t id = sqlite3_last_insert_rowid(db_);
  t.commit();
  return id;
}

void RecordStore::finish_qualification(const QualificationRow& q) {
  Transaction t(db_, file_);
  Statement s(db_,
              "UPDATE qualification SET status = ?, finished = ?, verdict = ?, deciding_phase = ?, deciding_measurement = ?, reasons = ?, "
              "campaign_toml = ?, results_json = ? WHERE id = ?",
              file_);
  s.bind(1, q.status).bind(2, q.finished).bind(3, q.verdict).bind(4, q.deciding_phase).bind(5, q.deciding_measurement);
  s.bind(6, q.reasons).bind(7, q.campaign_toml).bind(8, q.results_json).bind(9, q.id);
  s.step();
  t.commit();
}

void RecordStore::set_certificate(std::int64_t id, const std::string& sha256) {
  Transaction t(db_, file_);
  Statement(db_, "UPDATE qualification SET certificate_sha256 = ? WHERE id = ?", file_).bind(1, sha256).bind(2, id).step();
  t.commit();
}

PhaseTryRow RecordStore::begin_phase_try(std::int64_t qid, int phase_index, const std::string& phase_name) {
  Transaction t(db_, file_);
  PhaseTryRow row;
  row.qualification_id = qid;
  row.phase_index = phase_index;
  row.phase_name = phase_name;
  row.started = utc_now();
  row.status = "running";
  {
    Statement c(db_, "SELECT COUNT(*) FROM phase_try WHERE qualification_id = ? AND phase_name = ?", file_);
    c.bind(1, qid).bind(2, phase_name);
    c.step();
    row.try_number = static_cast<int>(c.integer(0)) + 1;
  }
  Statement s(db_,
              "INSERT INTO phase_try (qualification_id, phase_index, phase_name, try_number, started, status) VALUES (?, ?, ?, ?, ?, 'running')",
              file_);
  s.bind(1, qid).bind(2, std::int64_t{phase_index}).bind(3, phase_name).bind(4, std::int64_t{row.try_number}).bind(5, row.started);
  s.step();
  row.id = sqlite3_last_insert_rowid(db_);
  t.commit();
  return row;
}

void RecordStore::finish_phase_try(const PhaseTryRow& r) {
  Transaction t(db_, file_);
  Statement(db_, "UPDATE phase_try SET finished = ?, status = ?, reason = ?, verdict = ? WHERE id = ?", file_)
      .bind(1, r.finished)
      .bind(2, r.status)
      .bind(3, r.reason)
      .bind(4, r.verdict)
      .bind(5, r.id)
      .step();
  for (const MeasurementRow& m : r.measurements) {
    Statement s(db_,
                "INSERT INTO measurement (phase_try_id, name, unit, value, min, max, verdict, reason, stop_on_fail) VALUES (?, ?, ?, ?, ?, ?, "
                "?, ?, ?)",
                file_);
    s.bind(1, r.id).bind(2, m.name).bind(3, m.unit).bind(4, m.value).bind(5, m.min).bind(6, m.max).bind(7, m.verdict).bind(8, m.reason);
    s.bind(9, std::int64_t{m.stop_on_fail ? 1 : 0});
    s.step();
  }
  for (const RawFileRow& f : r.raw_files) {
    Statement s(db_, "INSERT INTO raw_file (phase_try_id, path, campaign_key, sha256, bytes) VALUES (?, ?, ?, ?, ?)", file_);
    s.bind(1, r.id).bind(2, f.path).bind(3, f.campaign_key).bind(4, f.sha256).bind(5, f.bytes);
    s.step();
  }
  t.commit();
}

int RecordStore::mark_interrupted(std::int64_t qid) {
  Transaction t(db_, file_);
  Statement(db_,
            "UPDATE phase_try SET status = 'interrupted', reason = 'the station process ended during the phase', finished = ? "
            "WHERE qualification_id = ? AND status = 'running'",
            file_)
      .bind(1, utc_now())
      .bind(2, qid)
      .step();
  const int n = sqlite3_changes(db_);
  t.commit();
  return n;
}

std::optional<QualificationRow> RecordStore::qualification(std::int64_t id) const {
  Statement s(db_, fmt::format("SELECT {} FROM qualification WHERE id = ?", kQualificationColumns), file_);
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return read_qualification(s);
}

std::optional<QualificationRow> RecordStore::latest_qualification(const std::string& serial) const {
  Statement s(db_, fmt::format("SELECT {} FROM qualification WHERE serial = ? ORDER BY id DESC LIMIT 1", kQualificationColumns), file_);
  s.bind(1, serial);
  if (!s.step()) return std::nullopt;
  return read_qualification(s);
}

std::vector<QualificationRow> RecordStore::list(const std::string& batch, int limit) const {
  Statement s(db_,
              "SELECT id, serial, batch, station, station_sha256, operator, bench_file, bench_sha256, software_version, started, finished, "
              "status, verdict, deciding_phase, deciding_measurement, reasons, '', '', certificate_sha256 FROM qualification "
              "WHERE (? = '' OR batch = ?) ORDER BY id DESC LIMIT ?",
              file_);
  s.bind(1, batch).bind(2, batch).bind(3, std::int64_t{limit});
  std::vector<QualificationRow> out;
  while (s.step()) out.push_back(read_qualification(s));
  return out;
}

std::vector<PhaseTryRow> RecordStore::phase_tries(std::int64_t qid) const {
  std::vector<PhaseTryRow> out;
  Statement s(db_,
              "SELECT id, phase_index, phase_name, try_number, started, finished, status, reason, verdict FROM phase_try "
              "WHERE qualification_id = ? ORDER BY id",
              file_);
  s.bind(1, qid);
  while (s.step()) {
    PhaseTryRow r;
    r.id = s.integer(0);
    r.qualification_id = qid;
    r.phase_index = static_cast<int>(s.integer(1));
    r.phase_name = s.text(2);
    r.try_number = static_cast<int>(s.integer(3));
    r.started = s.text(4);
    r.finished = s.text(5);
    r.status = s.text(6);
    r.reason = s.text(7);
    r.verdict = s.text(8);
    out.push_back(std::move(r));
  }
  for (PhaseTryRow& r : out) {
    Statement m(db_, "SELECT name, unit, value, min, max, verdict, reason, stop_on_fail FROM measurement WHERE phase_try_id = ? ORDER BY id", file_);
    m.bind(1, r.id);
    while (m.step()) {
      r.measurements.push_back({m.text(0), m.text(1), m.real(2), m.real(3), m.real(4), m.text(5), m.text(6), m.integer(7) != 0});
    }
    Statement f(db_, "SELECT path, campaign_key, sha256, bytes FROM raw_file WHERE phase_try_id = ? ORDER BY id", file_);
    f.bind(1, r.id);
    while (f.step()) r.raw_files.push_back({f.text(0), f.text(1), f.text(2), f.integer(3)});
  }
  return out;
}

std::vector<HistoryPoint> RecordStore::history(const std::string& measurement, const std::string& batch) const {
  // The latest complete qualification of each unit, then its complete tries' values. Two plans
  // (docs/performance.md, 10,000 units): a batch starts from its qualifications (index on batch)
  // and walks each one's tries; every batch starts from the measurement's rows (index on name),
  // keeping those of the latest qualifications (an IN list SQLite indexes).
  const std::string sql =
      batch.empty()
          ? "SELECT u.serial, u.batch, m.value, m.min, m.max, m.verdict FROM measurement m "
            "JOIN phase_try p ON p.id = m.phase_try_id JOIN qualification q ON q.id = p.qualification_id "
            "JOIN unit u ON u.serial = q.serial WHERE m.name = ?1 AND m.value IS NOT NULL AND p.status = 'complete' "
            "AND p.qualification_id IN (SELECT MAX(id) FROM qualification WHERE status = 'complete' GROUP BY serial) "
            "ORDER BY u.ordinal, p.id"
          : "WITH latest AS (SELECT serial, MAX(id) AS qid FROM qualification WHERE status = 'complete' AND batch = ?2 GROUP BY serial) "
            "SELECT u.serial, u.batch, m.value, m.min, m.max, m.verdict FROM latest l CROSS JOIN unit u ON u.serial = l.serial "
            "CROSS JOIN phase_try p ON p.qualification_id = l.qid CROSS JOIN measurement m ON m.phase_try_id = p.id "
            "WHERE p.status = 'complete' AND m.name = ?1 AND m.value IS NOT NULL ORDER BY u.ordinal, p.id";
  Statement s(db_, sql, file_);
  s.bind(1, measurement);
  if (!batch.empty()) s.bind(2, batch);
  std::vector<HistoryPoint> out;
  while (s.step()) out.push_back({s.text(0), s.text(1), *s.real(2), s.real(3), s.real(4), s.text(5)});
  return out;
}

std::string RecordStore::integrity_check() const {
  Statement s(db_, "PRAGMA integrity_check", file_);
  std::string out;
  while (s.step()) out += (out.empty() ? "" : "; ") + s.text(0);
  return out;
}

}  // namespace piezobench::station
