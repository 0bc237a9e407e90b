#pragma once
// The station's record store: one SQLite file (Debian's libsqlite3) behind a thin typed layer
// (docs/station.md, "The database"). Tables:
//   unit          serial, batch, first qualified
//   qualification serial, station name and file hash, operator, bench file and hash, software
//                 version, start and end (UTC, ISO 8601), status (running, complete, aborted,
//                 failed), verdict, the deciding phase and measurement, the per-unit results
//                 (JSON) and the campaign text of the unit, the certificate's SHA-256
//   phase_try     every try of every phase: index, name, try number, start, end, status
//                 (running, complete, failed, aborted, interrupted), reason, verdict
//   measurement   per try: name, unit, value, limits, verdict, reason, stop_on_fail
//   raw_file      per try: path, campaign key, SHA-256, bytes
// The file is opened in WAL mode with a busy time-out, so several station processes can write one
// database at once; every write is one transaction (BEGIN IMMEDIATE), so a process killed at any
// moment leaves the database as it was before or after that write. Errors are InputErrors naming
// the database file and the operation.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;

namespace piezobench::station {

struct QualificationRow {
  std::int64_t id = 0;
  std::string serial, batch, station, station_sha256, operator_name, bench_file, bench_sha256, software_version;
  std::string started, finished;        // UTC, "2026-11-27T12:00:00.123Z"; finished "" while running
  std::string status = "running";       // running, complete, aborted, failed
  std::string verdict;                  // pass, marginal, fail ("" until complete)
  std::string deciding_phase, deciding_measurement, reasons;
  std::string campaign_toml;            // the unit's campaign (files by absolute path)
  std::string results_json;             // the per-unit results of the campaign pipeline
  std::string certificate_sha256;
};

struct MeasurementRow {
  std::string name, unit;
  std::optional<double> value, min, max;  // same unit as `unit` names
  std::string verdict, reason;
  bool stop_on_fail = false;
};

struct RawFileRow {
  std::string path;         // absolute
  std::string campaign_key; // "stroke", "hysteresis", ... (campaign/campaign_file.hpp)
  std::string sha256;       // hex
  std::int64_t bytes = 0;
};

struct PhaseTryRow {
  std::int64_t id = 0, qualification_id = 0;
  int phase_index = 0, try_number = 0;
  std::string phase_name, started, finished, status, reason, verdict;
  std::vector<MeasurementRow> measurements;
  std::vector<RawFileRow> raw_files;
};

// One unit's value of a measurement (RecordStore::history).
struct HistoryPoint {
  std::string serial, batch;
  double value = 0.0;              // same unit as `unit` names
  std::optional<double> min, max;  // same unit as `unit` names
  std::string verdict;
};

// The SHA-256 of a file's bytes as lower-case hex (nettle). InputError when it cannot be read.
std::string sha256_file(const std::filesystem::path& file);
std::string sha256_text(const std::string& bytes);
// Now, UTC, ISO 8601 with milliseconds.
std::string utc_now();

class RecordStore {
 public:
  // Opens (creating it and its tables if needed) the database; busy_timeout_ms: how long a writer
  // waits for another's lock before failing.
  explicit RecordStore(const std::filesystem::path& file, int busy_timeout_ms = 30000);
  ~RecordStore();
  RecordStore(const RecordStore&) = delete;
  RecordStore& operator=(const RecordStore&) = delete;

  // Inserts the unit (if new) and a running qualification; returns its id.
  std::int64_t begin_qualification(const QualificationRow& q);
  void finish_qualification(const QualificationRow& q);  // status, finished, verdict, deciding, reasons, results
  void set_certificate(std::int64_t qualification_id, const std::string& sha256);
  // A new running try of a phase (try number: one more than the phase's tries so far).
  PhaseTryRow begin_phase_try(std::int64_t qualification_id, int phase_index, const std::string& phase_name);
  // Ends a try with its measurements and raw files, in one transaction.
  void finish_phase_try(const PhaseTryRow& t);
  // Tries left running by a killed process become "interrupted"; returns how many.
  int mark_interrupted(std::int64_t qualification_id);

  [[nodiscard]] std::optional<QualificationRow> qualification(std::int64_t id) const;
  // The newest qualification of a serial (any status).
  [[nodiscard]] std::optional<QualificationRow> latest_qualification(const std::string& serial) const;
  // Newest first; batch "" lists every batch. Without the large text fields (campaign, results).
  [[nodiscard]] std::vector<QualificationRow> list(const std::string& batch = "", int limit = 1000) const;
  // Every try of a qualification, in order, with measurements and raw files.
  [[nodiscard]] std::vector<PhaseTryRow> phase_tries(std::int64_t qualification_id) const;
  // History of one measurement across units: the value in the latest complete qualification of
  // each unit, in the order units were first qualified; batch "" for all (indexed: docs/station.md
  // has the time on 10,000 units).
  [[nodiscard]] std::vector<HistoryPoint> history(const std::string& measurement, const std::string& batch = "") const;
  // "ok" when PRAGMA integrity_check finds nothing.
  [[nodiscard]] std::string integrity_check() const;
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  void exec(const std::string& sql) const;
  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

}  // namespace piezobench::station
