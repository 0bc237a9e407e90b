#include "piezobench/web/station_site.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "piezobench/station/certificate.hpp"
#include "test_util.hpp"
#include "embedded_assets.hpp"

namespace piezobench::web {
namespace {

HttpRequest site_get(const std::string& path, std::map<std::string, std::string> query = {}) {
  HttpRequest r;
  r.method = "GET", r.path = path, r.query = std::move(query);
  return r;
}

// One unit with a stroke phase, complete, its certificate's hash stored as qualify stores it.
void qualify_one(station::RecordStore& s, const std::string& serial, const std::string& batch, double stroke_um) {
  station::QualificationRow q;
  q.serial = serial, q.batch = batch, q.station = "st", q.started = station::utc_now();
  q.id = s.begin_qualification(q);
  station::PhaseTryRow t = s.begin_phase_try(q.id, 0, "stroke");
  t.status = "complete", t.verdict = "pass", t.finished = station::utc_now();
  t.measurements.push_back({"stroke_um", "um", stroke_um, 200.0, std::nullopt, "pass", "", false});
  s.finish_phase_try(t);
  q.status = "complete", q.verdict = "pass", q.finished = station::utc_now();
  s.finish_qualification(q);
  const auto stored = s.qualification(q.id);
  s.set_certificate(q.id, station::sha256_text(station::certificate_html(*stored, s.phase_tries(q.id))));
}

TEST(StationSite, ServesItsFixedFilesAndNothingElse) {
  test::TempDir dir;
  StationSite site(dir.path() / "st.db", nullptr);
  const HttpResponse page = site.handle(site_get("/"));
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.body, std::string(detail::page_html()));
  EXPECT_NE(page.body.find("<script src=\"/station.js\""), std::string::npos);
  EXPECT_EQ(site.handle(site_get("/station.js")).content_type, "text/javascript; charset=utf-8");
  EXPECT_GT(site.handle(site_get("/plotly.min.js")).body.size(), 1000000u);
  for (const char* other : {"/etc/passwd", "/station.js.map", "/assets/station.js", "/api/nothing", "/index.htm"}) {
    EXPECT_EQ(site.handle(site_get(other)).status, 404) << other;
  }
  EXPECT_EQ(site.handle(site_get("/api/state")).body, R"({"live":false})");
  EXPECT_EQ(site.open_stream(site_get("/api/events")), nullptr);  // no live qualification here
  EXPECT_TRUE(site.accepts_post("/api/answer"));
  EXPECT_FALSE(site.accepts_post("/"));
  // A path that is not UTF-8 (fuzz_http_request): answered 404 in valid JSON, U+FFFD for its bytes.
  const HttpResponse not_utf8 = site.handle(site_get("/\xe2\xff"));
  EXPECT_EQ(not_utf8.status, 404);
  const nlohmann::json body = nlohmann::json::parse(not_utf8.body, nullptr, false);
  ASSERT_FALSE(body.is_discarded()) << not_utf8.body;
  EXPECT_NE(body["error"].get<std::string>().find("\xef\xbf\xbd"), std::string::npos);
}

TEST(StationSite, BrowsesTheDatabase) {
  test::TempDir dir;
  {
    station::RecordStore store(dir.path() / "st.db");
    qualify_one(store, "SN1", "B1", 240.0);
    qualify_one(store, "SN2", "B2", 260.0);
  }
  StationSite site(dir.path() / "st.db", nullptr);
  const nlohmann::json all = nlohmann::json::parse(site.handle(site_get("/api/qualifications")).body);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0]["serial"], "SN2");  // newest first
  EXPECT_EQ(nlohmann::json::parse(site.handle(site_get("/api/qualifications", {{"batch", "B1"}})).body).size(), 1u);
  const nlohmann::json unit = nlohmann::json::parse(site.handle(site_get("/api/units/SN1")).body);
  EXPECT_DOUBLE_EQ(unit["phase_tries"][0]["measurements"][0]["value"].get<double>(), 240.0);
  const nlohmann::json charts = nlohmann::json::parse(site.handle(site_get("/api/charts")).body);
  const auto stroke = std::find_if(charts.begin(), charts.end(), [](const auto& c) { return c["quantity"] == "stroke_um"; });
  ASSERT_NE(stroke, charts.end());
  EXPECT_DOUBLE_EQ((*stroke)["mean"].get<double>(), 250.0);
  EXPECT_NEAR((*stroke)["sigma"].get<double>(), std::sqrt(200.0), 1e-12);  // sample standard deviation of 240, 260
  const HttpResponse cert = site.handle(site_get("/api/certificate/SN1"));
  EXPECT_EQ(cert.status, 200);
  EXPECT_EQ(cert.content_type, "text/html; charset=utf-8");
  EXPECT_NE(cert.body.find("SN1"), std::string::npos);
  EXPECT_EQ(site.handle(site_get("/api/units/NOPE")).status, 404);
  EXPECT_EQ(site.handle(site_get("/api/units/..")).status, 400);
  EXPECT_EQ(site.handle(site_get("/api/units/<script>")).status, 400);
}

TEST(StationSite, AnswersTheOpenPromptOnly) {
  test::TempDir dir;
  LiveHub hub;
  StationSite site(dir.path() / "st.db", &hub);
  const std::uint64_t id = hub.open_prompt("stroke", "mount the actuator", {"confirm", "abort"});
  HttpRequest post;
  post.method = "POST", post.path = "/api/answer", post.operator_rights = true;
  post.body = "not json";
  EXPECT_EQ(site.handle(post).status, 400);
  post.body = nlohmann::json{{"id", id}, {"answer", "retry"}}.dump();
  EXPECT_EQ(site.handle(post).status, 409);
  post.body = nlohmann::json{{"id", id}, {"answer", "confirm"}}.dump();
  EXPECT_EQ(site.handle(post).status, 200);
  EXPECT_EQ(hub.wait_answer(id, std::chrono::milliseconds(0)).value_or(""), "confirm");
  EXPECT_NE(site.open_stream(site_get("/api/events")), nullptr);
  EXPECT_EQ(nlohmann::json::parse(site.handle(site_get("/api/state")).body)["prompt"]["id"], id);
  hub.close_prompt(id);
  // Typed values: 422 with the check's refusal (the prompt stays open), 400 for values not text.
  const std::uint64_t typed = hub.open_prompt("capacitance", "type the values", {"confirm"}, {{"sensor_uF", "capacitance"}},
                                              [](const std::map<std::string, std::string>& v) {
                                                if (v.count("sensor_uF") == 0 || v.at("sensor_uF") != "5") throw std::runtime_error("refused: not 5");
                                              });
  post.body = nlohmann::json{{"id", typed}, {"answer", "confirm"}, {"values", {{"sensor_uF", 5}}}}.dump();
  EXPECT_EQ(site.handle(post).status, 400);
  post.body = nlohmann::json{{"id", typed}, {"answer", "confirm"}, {"values", {{"sensor_uF", "4"}}}}.dump();
  const HttpResponse refused = site.handle(post);
  EXPECT_EQ(refused.status, 422);
  EXPECT_EQ(nlohmann::json::parse(refused.body)["error"], "refused: not 5");
  post.body = nlohmann::json{{"id", typed}, {"answer", "confirm"}, {"values", {{"sensor_uF", "5"}}}}.dump();
  EXPECT_EQ(site.handle(post).status, 200);
  std::map<std::string, std::string> got;
  EXPECT_EQ(hub.wait_answer(typed, std::chrono::milliseconds(0), &got).value_or(""), "confirm");
  EXPECT_EQ(got.at("sensor_uF"), "5");
}

}  // namespace
}  // namespace piezobench::web
