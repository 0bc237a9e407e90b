#include "piezobench/station/phase_runner.hpp"

#include <gtest/gtest.h>

#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "station_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::station {
namespace {

namespace fs = std::filesystem;

// The virtual bench, with failures and saturation injected on chosen tries, counting the records.
class TestInstrument final : public Instrument {
 public:
  explicit TestInstrument(int unit) : bench_([unit] {
    BenchInstrumentOptions o;
    o.bench = rt::parse_bench_description("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n", "b.toml");
    o.unit = unit;
    return o;
  }()) {}
  Acquired acquire(const PhaseSpec& p, const PhaseValues& v, const fs::path& stem) override {
    const int n = ++calls[p.name];
    if (fail_phase == p.name && n == 1) throw InputError("measure on udp", "run", "a run without a safety trip", "the safe state (stale input)");
    Acquired a = bench_.acquire(p, v, stem);
    if (saturate_phase == p.name && n == 1) a.settings["clamped_samples"] = 5.0;
    return a;
  }
  void check(const StationFile& st) const override { bench_.check(st); }
  std::map<std::string, int> calls;
  std::string fail_phase, saturate_phase;

 private:
  BenchInstrument bench_;
};

class Recorder final : public Observer {
 public:
  void phase_started(const std::string& sn, const PhaseSpec& p, int n) override { events.push_back(sn + " start " + p.name + " " + std::to_string(n)); }
  void phase_finished(const std::string& sn, const PhaseTryRow& t) override { events.push_back(sn + " end " + t.phase_name + " " + t.verdict); }
  void prompt(const std::string& sn, const std::string& text) override { events.push_back(sn + " prompt " + text); }
  void verdict(const std::string& sn, Verdict v, const std::string& phase, const std::string& m) override {
    events.push_back(sn + " verdict " + to_string(v) + " " + phase + " " + m);
  }
  std::vector<std::string> events;
};

struct Station {
  test::TempDir dir;
  StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  RecordStore store{dir.path() / "st.db"};
  QualifyOptions options(const std::string& serial, int unit) const {
    QualifyOptions o;
    o.serial = serial;
    o.batch = "B";
    o.unit_id = unit;
    o.data_dir = dir.path() / "data";
    o.station_sha256 = "s";
    return o;
  }
  AnswersOperator answers(const std::string& text = testdata::kSmallAnswers) const { return AnswersOperator(parse_answers(text, "a.toml", st)); }
};

TEST(PhaseRunner, AGoodUnitPassesWithEveryRawFileHashedAndTheCampaignsResults) {
  Station s;
  TestInstrument inst(1);
  AnswersOperator op = s.answers();
  Recorder rec;
  QualifyOptions o = s.options("SN1", 1);
  o.observer = &rec;
  const QualifyResult r = qualify(s.st, inst, op, s.store, o);
  EXPECT_EQ(r.status, "complete");
  EXPECT_EQ(r.verdict, Verdict::kPass);
  const auto tries = s.store.phase_tries(r.qualification_id);
  ASSERT_EQ(tries.size(), 3U);
  for (const auto& t : tries) {
    ASSERT_EQ(t.raw_files.size(), 1U);
    EXPECT_EQ(sha256_file(t.raw_files[0].path), t.raw_files[0].sha256);
  }
  EXPECT_EQ(rec.events.front(), "SN1 start capacitance 1");
  EXPECT_EQ(rec.events[2], "SN1 prompt mount the actuator");
  EXPECT_EQ(rec.events.back(), "SN1 verdict pass  ");
  // The measurements are the campaign pipeline's figures of the exported campaign.
  const fs::path campaign_file = s.dir.path() / "export.toml";
  write_text_atomically(campaign_file, export_campaign(s.store, "B"));
  const campaign::CampaignResult cr = campaign::run_campaign(campaign::read_campaign(campaign_file));
  ASSERT_EQ(cr.units.size(), 1U);
  EXPECT_TRUE(cr.units[0].accepted);
  EXPECT_DOUBLE_EQ(*tries[1].measurements[0].value, *campaign::stroke_of(cr.units[0]) * 1e6);
  EXPECT_DOUBLE_EQ(*tries[0].measurements[0].value, *campaign::capacitance_sensor_of(cr.units[0]) * 1e6);
  EXPECT_DOUBLE_EQ(*tries[2].measurements[0].value, cr.units[0].hysteresis[0].result.relative_width);
  EXPECT_DOUBLE_EQ(*campaign::stroke_of(*r.unit), *campaign::stroke_of(cr.units[0]));
  EXPECT_EQ(s.store.qualification(r.qualification_id)->status, "complete");
}

TEST(PhaseRunner, UnitThreeFailsOnItsCapacitanceAndStopsAtItsStroke) {
  Station s;
  TestInstrument inst(3);
  AnswersOperator op = s.answers();
  const QualifyResult r = qualify(s.st, inst, op, s.store, s.options("SN3", 3));
  EXPECT_EQ(r.status, "complete");
  EXPECT_EQ(r.verdict, Verdict::kFail);
  EXPECT_EQ(r.deciding_phase, "capacitance");
  EXPECT_EQ(r.deciding_measurement, "capacitance_sensor_uF");
  EXPECT_EQ(inst.calls.count("hysteresis-20V"), 0U);  // stroke_um stops on a fail
  ASSERT_TRUE(r.unit);
  EXPECT_FALSE(r.unit->accepted);
  const std::string reasons = [&] {
    std::string all;
    for (const auto& x : r.reasons) all += x + "\n";
    return all;
  }();
  EXPECT_TRUE(test::contains(reasons, "capacitance of the sensor stack")) << reasons;
  EXPECT_TRUE(test::contains(reasons, "below the minimum 200 um")) << reasons;
}

TEST(PhaseRunner, ALostBenchFailsThePhaseAndResumeNeverMeasuresAKeptPhaseAgain) {
  Station s;
  TestInstrument inst(1);
  inst.fail_phase = "stroke";
  AnswersOperator op = s.answers();
  const QualifyResult r = qualify(s.st, inst, op, s.store, s.options("SN1", 1));
  EXPECT_EQ(r.status, "failed");
  auto tries = s.store.phase_tries(r.qualification_id);
  ASSERT_EQ(tries.size(), 2U);
  EXPECT_EQ(tries[1].status, "failed");
  EXPECT_TRUE(test::contains(tries[1].reason, "bench: measure on udp: run: expected a run without a safety trip")) << tries[1].reason;
  QualifyOptions o = s.options("SN1", 1);
  o.resume = true;
  AnswersOperator op2 = s.answers();
  const QualifyResult r2 = qualify(s.st, inst, op2, s.store, o);
  EXPECT_EQ(r2.status, "complete");
  EXPECT_EQ(r2.qualification_id, r.qualification_id);
  EXPECT_EQ(r2.resumed_phases, std::vector<std::string>{"capacitance"});
  EXPECT_EQ(inst.calls["capacitance"], 1);
  EXPECT_EQ(inst.calls["stroke"], 2);
  tries = s.store.phase_tries(r.qualification_id);
  ASSERT_EQ(tries.size(), 4U);
  EXPECT_EQ(tries[2].phase_name, "stroke");
  EXPECT_EQ(tries[2].try_number, 2);
  // A complete qualification is not resumed.
  AnswersOperator op3 = s.answers();
  test::expect_input_error([&] { (void)qualify(s.st, inst, op3, s.store, o); }, {"--resume SN1", "its newest qualification is complete"});
}

TEST(PhaseRunner, AFailedCheckIsRetriedAndEveryTryKept) {
  Station s;
  TestInstrument inst(1);
  inst.saturate_phase = "capacitance";
  AnswersOperator op = s.answers(std::string(testdata::kSmallAnswers) + "[phases.capacitance]\non_check_fail = [\"retry\"]\n");
  const QualifyResult r = qualify(s.st, inst, op, s.store, s.options("SN1", 1));
  EXPECT_EQ(r.verdict, Verdict::kPass);
  const auto tries = s.store.phase_tries(r.qualification_id);
  ASSERT_EQ(tries.size(), 4U);
  EXPECT_EQ(tries[0].status, "failed");
  EXPECT_EQ(tries[0].reason, "saturation: 5 clamped_samples (at most 0 allowed)");
  EXPECT_EQ(tries[1].status, "complete");
  EXPECT_EQ(tries[1].try_number, 2);
}

TEST(PhaseRunner, AnAbortedQualificationResumesAtTheAbortedPhase) {
  Station s;
  TestInstrument inst(1);
  AnswersOperator abort = s.answers("[phases.stroke]\nsteps = [\"abort\"]\n");
  const QualifyResult r = qualify(s.st, inst, abort, s.store, s.options("SN1", 1));
  EXPECT_EQ(r.status, "aborted");
  EXPECT_EQ(inst.calls.count("stroke"), 0U);
  QualifyOptions o = s.options("SN1", 1);
  o.resume = true;
  AnswersOperator op = s.answers();
  EXPECT_EQ(qualify(s.st, inst, op, s.store, o).status, "complete");
  EXPECT_EQ(inst.calls["capacitance"], 1);
}

TEST(PhaseRunner, CtrlCBeforeAPhaseAbortsResumably) {
  Station s;
  TestInstrument inst(1);
  AnswersOperator op = s.answers();
  std::atomic<bool> stop{true};
  QualifyOptions o = s.options("SN1", 1);
  o.stop = &stop;
  EXPECT_EQ(qualify(s.st, inst, op, s.store, o).status, "aborted");
  EXPECT_TRUE(inst.calls.empty());
  stop = false;
  o.resume = true;
  AnswersOperator op2 = s.answers();
  EXPECT_EQ(qualify(s.st, inst, op2, s.store, o).status, "complete");
}

TEST(PhaseRunner, ResumeRefusesARawFileChangedSinceItWasRecorded) {
  Station s;
  TestInstrument inst(1);
  inst.fail_phase = "stroke";
  AnswersOperator op = s.answers();
  const QualifyResult r = qualify(s.st, inst, op, s.store, s.options("SN1", 1));
  const auto tries = s.store.phase_tries(r.qualification_id);
  test::write_text(tries[0].raw_files[0].path, "changed");
  QualifyOptions o = s.options("SN1", 1);
  o.resume = true;
  AnswersOperator op2 = s.answers();
  test::expect_input_error([&] { (void)qualify(s.st, inst, op2, s.store, o); }, {"sha256", "a file with other contents"});
}

}  // namespace
}  // namespace piezobench::station
