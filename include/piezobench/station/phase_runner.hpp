#pragma once
// The station's phase runner (`piezobench qualify`, docs/station.md): one unit through the phases
// of a station file, on a bench, with an operator, recorded in a RecordStore.
//
// For each phase, in order: its operator steps (confirm or abort), then tries until one is kept:
// the bench measures the phase's record (Instrument), the record is written atomically to
// DATA/SERIAL/q<ID>-<PHASE>-try<N>.<ext> and its SHA-256 taken, the phase's analysis (the campaign
// pipeline's per-unit analysis of this record and the records it depends on: capacitance for the
// FRF, the FRF for the resistor and IFF phases) gives its measurements and their verdicts, and its
// checks run (saturation, lost samples, coherence, an analysis that refused the data). A try whose
// checks fail asks the operator: retry (while retries remain), continue (the failure kept) or
// abort. The try, its measurements and its raw file are committed to the store in one transaction
// before the next phase starts; every try is kept.
//
// A phase whose stop_on_fail measurement fails ends the qualification (the remaining phases are
// not measured). After the last phase the whole unit is analysed by the campaign pipeline
// (run_campaign on the unit's campaign, the one `db export` writes) and the unit's verdict is the
// worst of its phases' verdicts and the pipeline's acceptance; the deciding phase and measurement
// are the first with that verdict. The certificate (certificate.hpp) is written next to the raw
// files and its SHA-256 stored.
//
// Resume (options.resume): the newest qualification of the serial, not complete, continues at its
// first phase without a kept try; a kept phase is never measured again (its raw file's hash is
// checked first). A bench that fails (InputError from the Instrument: safe state, lost target)
// marks the try failed with the reason and the qualification failed, and qualify returns: the
// qualification can be resumed.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/campaign/results.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "piezobench/rt/logger.hpp"
#include "piezobench/station/answers.hpp"
#include "piezobench/station/record_store.hpp"
#include "piezobench/station/station_file.hpp"

namespace piezobench::station {

// What an operator gives a phase besides confirmations: typed capacitances, a file.
struct PhaseValues {
  std::optional<double> sensor_uF, actuator_uF;
  std::optional<std::filesystem::path> file;
};

// A record written by the instrument: its file and the settings that say how it was made
// (clamped_samples, io_lost, ...: the phase's checks read them).
struct Acquired {
  std::filesystem::path file;
  std::map<std::string, io::Setting> settings;
};

// The bench: one record per call. InputError when the bench fails (the try is then failed).
class Instrument {
 public:
  virtual ~Instrument() = default;
  // Writes the record of `phase` atomically to target_stem + an extension of the instrument's
  // choice.
  virtual Acquired acquire(const PhaseSpec& phase, const PhaseValues& values, const std::filesystem::path& target_stem) = 0;
  // Refuses (InputError naming the station file's line) a phase this bench cannot measure, before
  // anything moves.
  virtual void check(const StationFile& station) const = 0;
};

struct BenchInstrumentOptions {
  rt::BenchDescription bench;
  int unit = 1;                 // virtual bench: the unit of the batch
  std::uint64_t seed = 1;
  bool paced = false;           // virtual bench: each record takes its real duration
  // Hardware: the backend of the bench description (app's make_backend).
  std::function<std::unique_ptr<rt::Backend>(const rt::BenchDescription&)> make_backend;
  int operator_fd = 0;          // in-record confirmations (stiffness mass on/off); -1: answered at once
  const std::atomic<bool>* stop = nullptr;
  std::function<void(const std::string&)> log;
  // A live view of the signals (web::LiveHub::record): each bench record as soon as it exists, with
  // the moment its first sample was measured (paced virtual bench: when the phase started, the
  // samples then come due at their times; otherwise the record is complete and all of it is past).
  // Called on the runner's thread; must not block.
  std::function<void(const io::TimeSeries&, std::chrono::steady_clock::time_point)> on_record;
  // Hardware: a live copy of the loop's log while each record runs (rt::LogTap, on the loop's
  // logger thread; web::LiveHub::loop_tap), before on_record hands the whole record.
  rt::LogTap live_tap;
};

// The bench as `measure` drives it: the virtual bench through bench::simulate, hardware through
// bench::run_experiment over rt::BackendRunner; flatness and capacitance from a file (copied) or
// typed in (written as a one-sample record).
class BenchInstrument final : public Instrument {
 public:
  explicit BenchInstrument(BenchInstrumentOptions options);
  Acquired acquire(const PhaseSpec& phase, const PhaseValues& values, const std::filesystem::path& target_stem) override;
  void check(const StationFile& station) const override;

 private:
  BenchInstrumentOptions options_;
};

// The operator's side of the prompts.
class Operator {
 public:
  virtual ~Operator() = default;
  virtual StepAnswer step(const PhaseSpec& phase, std::size_t index) = 0;
  virtual CheckAnswer check_failed(const PhaseSpec& phase, int try_number, const std::string& why) = 0;
  virtual PhaseValues values(const PhaseSpec& phase) = 0;
  [[nodiscard]] virtual std::string name() const = 0;
};

// Answers from an answers file (read_answers checked them against the station).
class AnswersOperator final : public Operator {
 public:
  explicit AnswersOperator(Answers answers) : answers_(std::move(answers)) {}
  StepAnswer step(const PhaseSpec& phase, std::size_t index) override;
  CheckAnswer check_failed(const PhaseSpec& phase, int try_number, const std::string& why) override;
  PhaseValues values(const PhaseSpec& phase) override;
  [[nodiscard]] std::string name() const override { return answers_.operator_name; }

 private:
  Answers answers_;
  std::map<std::string, std::size_t> check_answers_used_;
};

// The values an operator types for a phase (source "typed" or "file"), as every operator (the
// terminal, the page) asks and checks them. `typed_value_fields` lists them in the order asked
// ("sensor_uF", "actuator_uF"; or "file"; none for a bench phase), with the question of each;
// `typed_values` checks the typed texts, `check_typed_value` one of them (InputError naming
// "PHASE.FIELD_uF": a capacitance > 0 in uF; naming the phase: a file name that is not empty).
struct TypedValueField {
  std::string name;      // "sensor_uF", "actuator_uF", "file"
  std::string question;  // "capacitance of the sensor stack(s), uF"
};
std::vector<TypedValueField> typed_value_fields(const PhaseSpec& phase);
void check_typed_value(const PhaseSpec& phase, const std::string& field, const std::string& text);
PhaseValues typed_values(const PhaseSpec& phase, const std::map<std::string, std::string>& typed);

// Prompts on `out` (stderr), answers typed on `in` (stdin): "y" confirms, "a" aborts; after a
// failed check "r" retries, "c" continues, "a" aborts. The end of the input aborts.
class TerminalOperator final : public Operator {
 public:
  TerminalOperator(std::istream& in, std::ostream& out, std::string name) : in_(in), out_(out), name_(std::move(name)) {}
  StepAnswer step(const PhaseSpec& phase, std::size_t index) override;
  CheckAnswer check_failed(const PhaseSpec& phase, int try_number, const std::string& why) override;
  PhaseValues values(const PhaseSpec& phase) override;
  [[nodiscard]] std::string name() const override { return name_; }

 private:
  std::string ask(const std::string& prompt);
  std::istream& in_;
  std::ostream& out_;
  std::string name_;
};

// What a live view (a web page) is told; called on the runner's thread, must not block.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void phase_started(const std::string& serial, const PhaseSpec& phase, int try_number) = 0;
  virtual void phase_finished(const std::string& serial, const PhaseTryRow& result) = 0;
  virtual void prompt(const std::string& serial, const std::string& text) = 0;
  virtual void verdict(const std::string& serial, Verdict verdict, const std::string& phase, const std::string& measurement) = 0;
};

struct QualifyOptions {
  std::string serial;
  std::string batch;
  int unit_id = 1;                      // the unit's id in its campaign
  std::filesystem::path data_dir;       // raw files under DATA/SERIAL/
  std::string station_sha256, bench_file, bench_sha256, software_version;
  bool resume = false;
  const std::atomic<bool>* stop = nullptr;  // Ctrl-C: checked before each phase (status aborted)
  Observer* observer = nullptr;
  std::function<void(const std::string&)> log;
};

struct QualifyResult {
  std::int64_t qualification_id = 0;
  std::string status;                   // complete, aborted, failed
  Verdict verdict = Verdict::kFail;
  std::string deciding_phase, deciding_measurement;
  std::vector<std::string> reasons;
  std::vector<std::string> resumed_phases;  // kept phases of an earlier run, not measured again
  std::optional<campaign::UnitAnalysis> unit;   // the final analysis (status complete)
  double analysis_seconds = 0.0;        // the final analysis, wall time
  double analysis_cpu_seconds = 0.0;    // and CPU time (every thread)
  std::filesystem::path certificate;    // DATA/SERIAL/certificate-q<ID>.html (status complete)
};

QualifyResult qualify(const StationFile& station, Instrument& instrument, Operator& op, RecordStore& store,
                      const QualifyOptions& options);

// The [[units]] entry of a unit's campaign from its kept raw files (absolute paths).
std::string unit_campaign_entry(int id, const std::string& name, const StationFile& station, const std::vector<PhaseTryRow>& kept);
// The header of every campaign the station writes: [campaign.*] tables and the specs.
std::string campaign_header(const StationFile& station);
// `db export`: the campaign of a batch, every unit's newest complete qualification in the order
// the units were first qualified, as `qualify` analysed it (its header and [[units]] entry).
// InputError when the batch has no complete qualification, when its units were qualified with
// different station files (their campaigns differ), or when two units share a campaign id.
std::string export_campaign(const RecordStore& store, const std::string& batch);

}  // namespace piezobench::station
