#include "piezobench/station/certificate.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace piezobench::station {
namespace {

void add_unit(RecordStore& s, const std::string& serial, const std::string& batch, double stroke_um, const std::string& verdict) {
  QualificationRow q;
  q.serial = serial;
  q.batch = batch;
  q.station = "st";
  q.station_sha256 = "s";
  q.bench_file = "bench <virtual>.toml";
  q.bench_sha256 = "b";
  q.software_version = "piezobench test";
  q.started = "2026-01-01T00:00:00.000Z";
  q.id = s.begin_qualification(q);
  PhaseTryRow t = s.begin_phase_try(q.id, 0, "stroke");
  t.status = "complete";
  t.verdict = verdict;
  t.measurements.push_back({"stroke_um", "um", stroke_um, 200.0, std::nullopt, verdict, verdict == "pass" ? "" : "stroke low", true});
  t.raw_files.push_back({"/data/" + serial + "/stroke.mat", "stroke", "ab12", 99});
  s.finish_phase_try(t);
  q.status = "complete";
  q.verdict = verdict;
  q.deciding_phase = verdict == "pass" ? "" : "stroke";
  q.deciding_measurement = verdict == "pass" ? "" : "stroke_um";
  q.reasons = verdict == "pass" ? "" : "stroke: fail: stroke low\nsecond reason";
  s.finish_qualification(q);
}

TEST(Certificate, TheSameRecordsGiveTheSameBytesWithTheProvenance) {
  test::TempDir dir;
  RecordStore s(dir.path() / "st.db");
  add_unit(s, "SN<1>", "B", 150.0, "fail");
  const auto q = s.latest_qualification("SN<1>");
  const std::string a = certificate_html(*q, s.phase_tries(q->id));
  RecordStore again(dir.path() / "st.db");
  const auto q2 = again.latest_qualification("SN<1>");
  EXPECT_EQ(certificate_html(*q2, again.phase_tries(q2->id)), a);
  EXPECT_TRUE(test::contains(a, "Qualification certificate: SN&lt;1&gt;")) << a;  // escaped
  EXPECT_TRUE(test::contains(a, "decided by phase <b>stroke</b>, stroke_um"));
  EXPECT_TRUE(test::contains(a, "<li>second reason</li>"));
  EXPECT_TRUE(test::contains(a, "bench &lt;virtual&gt;.toml <code>sha256 b</code>"));
  EXPECT_TRUE(test::contains(a, "<td>/data/SN&lt;1&gt;/stroke.mat</td><td>99</td><td><code>ab12</code></td>"));
  EXPECT_TRUE(test::contains(a, "<td>150</td><td>um</td><td>200</td><td></td><td class=\"fail\">fail</td>"));
}

TEST(Certificate, ControlChartsGiveMeanSigmaAndCounts) {
  test::TempDir dir;
  RecordStore s(dir.path() / "st.db");
  add_unit(s, "A", "B1", 240.0, "pass");
  add_unit(s, "B", "B1", 250.0, "pass");
  add_unit(s, "C", "B1", 199.0, "marginal");
  add_unit(s, "D", "B2", 150.0, "fail");
  const auto b1 = control_charts(s, "B1");
  ASSERT_EQ(b1.size(), 1U);  // only stroke is recorded
  EXPECT_EQ(b1[0].points.size(), 3U);
  EXPECT_NEAR(b1[0].mean, 689.0 / 3.0, 1e-12);
  // Sample standard deviation of 240, 250, 199.
  const double m = 689.0 / 3.0;
  EXPECT_NEAR(b1[0].sigma, std::sqrt(((240 - m) * (240 - m) + (250 - m) * (250 - m) + (199 - m) * (199 - m)) / 2.0), 1e-12);
  EXPECT_EQ(b1[0].marginal, 1);
  EXPECT_EQ(b1[0].failed, 0);
  EXPECT_DOUBLE_EQ(*b1[0].min, 200.0);
  const auto all = control_charts(s, "");
  EXPECT_EQ(all[0].points.size(), 4U);
  EXPECT_EQ(all[0].failed, 1);
  const std::string html = control_charts_html(all, "charts");
  EXPECT_TRUE(test::contains(html, "<h2>stroke_um (um)</h2><p>4 units")) << html;
  EXPECT_TRUE(test::contains(html, "<title>D (B2): 150 um, fail</title>"));
}

}  // namespace
}  // namespace piezobench::station
