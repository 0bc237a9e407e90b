#include "piezobench/station/record_store.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.hpp"

namespace piezobench::station {
namespace {

namespace fs = std::filesystem;

QualificationRow row(const std::string& serial, const std::string& batch) {
  QualificationRow q;
  q.serial = serial;
  q.batch = batch;
  q.station = "st";
  q.station_sha256 = "s";
  q.bench_file = "b.toml";
  q.bench_sha256 = "b";
  q.software_version = "test";
  q.started = utc_now();
  return q;
}

// One unit qualified: a stroke try with its measurement and raw file, then complete.
void qualify_one(RecordStore& s, const std::string& serial, const std::string& batch, double stroke_um) {
  QualificationRow q = row(serial, batch);
  q.id = s.begin_qualification(q);
  PhaseTryRow t = s.begin_phase_try(q.id, 0, "stroke");
  t.status = "complete";
  t.verdict = "pass";
  t.finished = utc_now();
  t.measurements.push_back({"stroke_um", "um", stroke_um, 200.0, std::nullopt, "pass", "", true});
  t.raw_files.push_back({"/data/" + serial + ".mat", "stroke", "abc", 1234});
  s.finish_phase_try(t);
  q.status = "complete";
  q.verdict = "pass";
  q.finished = utc_now();
  s.finish_qualification(q);
}

TEST(RecordStore, Sha256OfTheStandardVectors) {
  // FIPS 180-2, appendix B.1 and B.2.
  EXPECT_EQ(sha256_text("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_text("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  test::TempDir dir;
  test::write_text(dir.path() / "f", "abc");
  EXPECT_EQ(sha256_file(dir.path() / "f"), sha256_text("abc"));
  EXPECT_THROW((void)sha256_file(dir.path() / "missing"), InputError);
}

TEST(RecordStore, EveryTryIsKeptWithItsMeasurementsAndFiles) {
  test::TempDir dir;
  RecordStore s(dir.path() / "st.db");
  QualificationRow q = row("SN1", "B1");
  q.id = s.begin_qualification(q);
  PhaseTryRow t1 = s.begin_phase_try(q.id, 0, "frf");
  EXPECT_EQ(t1.try_number, 1);
  t1.status = "failed";
  t1.reason = "coherence";
  t1.verdict = "fail";
  s.finish_phase_try(t1);
  PhaseTryRow t2 = s.begin_phase_try(q.id, 0, "frf");
  EXPECT_EQ(t2.try_number, 2);
  PhaseTryRow t3 = s.begin_phase_try(q.id, 1, "iff");  // left running, as by a killed process
  (void)t3;
  EXPECT_EQ(s.mark_interrupted(q.id), 2);
  const auto tries = s.phase_tries(q.id);
  ASSERT_EQ(tries.size(), 3U);
  EXPECT_EQ(tries[0].status, "failed");
  EXPECT_EQ(tries[0].reason, "coherence");
  EXPECT_EQ(tries[1].status, "interrupted");
  EXPECT_EQ(s.latest_qualification("SN1")->status, "running");
  qualify_one(s, "SN2", "B1", 250.0);
  const auto latest = s.latest_qualification("SN2");
  ASSERT_TRUE(latest);
  const auto t = s.phase_tries(latest->id);
  ASSERT_EQ(t.size(), 1U);
  ASSERT_EQ(t[0].measurements.size(), 1U);
  EXPECT_DOUBLE_EQ(*t[0].measurements[0].value, 250.0);
  EXPECT_FALSE(t[0].measurements[0].max.has_value());
  EXPECT_TRUE(t[0].measurements[0].stop_on_fail);
  EXPECT_EQ(t[0].raw_files[0].bytes, 1234);
  EXPECT_EQ(s.list("B1").size(), 2U);
  EXPECT_EQ(s.list("B2").size(), 0U);
  const auto h = s.history("stroke_um", "B1");
  ASSERT_EQ(h.size(), 1U);
  EXPECT_EQ(h[0].serial, "SN2");
  EXPECT_DOUBLE_EQ(h[0].value, 250.0);
  EXPECT_DOUBLE_EQ(*h[0].min, 200.0);
  EXPECT_EQ(h[0].verdict, "pass");
  EXPECT_EQ(s.integrity_check(), "ok");
}

TEST(RecordStore, TwoProcessesWritingAtOnceLoseNothing) {
  test::TempDir dir;
  const fs::path db = dir.path() / "st.db";
  { RecordStore init(db); }
  constexpr int kUnits = 60;
  std::vector<pid_t> children;
  for (int p = 0; p < 2; ++p) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int code = 0;
      try {
        RecordStore s(db);
        for (int i = 0; i < kUnits; ++i) qualify_one(s, "P" + std::to_string(p) + "-" + std::to_string(i), "B", 200.0 + i);
      } catch (...) {
        code = 1;
      }
      ::_exit(code);
    }
    children.push_back(pid);
  }
  for (const pid_t c : children) {
    int status = 0;
    ::waitpid(c, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  RecordStore s(db);
  EXPECT_EQ(s.list("B", 10000).size(), static_cast<std::size_t>(2 * kUnits));
  EXPECT_EQ(s.history("stroke_um", "B").size(), static_cast<std::size_t>(2 * kUnits));
  EXPECT_EQ(s.integrity_check(), "ok");
}

}  // namespace
}  // namespace piezobench::station
