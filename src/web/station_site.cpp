// The station's page and endpoints (station_site.hpp).
#include "piezobench/web/station_site.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "piezobench/core/error.hpp"
#include "piezobench/station/certificate.hpp"
#include "piezobench/station/record_json.hpp"
#include "piezobench/report/embedded_assets.hpp"
#include "embedded_assets.hpp"

namespace piezobench::web {

namespace {

HttpResponse asset(std::string_view bytes, const char* type) { return {200, type, std::string(bytes), {}}; }

// A serial as qualify accepts it (so no path or markup reaches the database layer or the page).
bool plausible_serial(const std::string& s) {
  if (s.empty() || s.size() > 64 || s.front() == '.') return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'; });
}

// The document as JSON text; a database text that is not UTF-8 (an operator's name typed on the
// command line) is replaced (U+FFFD), not thrown on (the exception would end the server's thread).
std::string text_of(const nlohmann::json& doc) { return doc.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

std::string query(const HttpRequest& r, const std::string& key) {
  const auto it = r.query.find(key);
  return it == r.query.end() ? "" : it->second;
}

}  // namespace

StationSite::StationSite(const std::filesystem::path& database, LiveHub* hub) : store_(database), hub_(hub) {}

HttpResponse StationSite::handle(const HttpRequest& r) {
  const std::string& p = r.path;
  if (p == "/" || p == "/index.html") return asset(detail::page_html(), "text/html; charset=utf-8");
  if (p == "/station.js") return asset(detail::page_script(), "text/javascript; charset=utf-8");
  if (p == "/station.css") return asset(detail::page_style(), "text/css; charset=utf-8");
  if (p == "/plotly.min.js") return asset(report::plotting_library(), "text/javascript; charset=utf-8");
  if (p == "/api/state") return json_response(200, hub_ ? hub_->state_json() : R"({"live":false})");
  if (p == "/api/answer") return answer(r);
  if (p.rfind("/api/", 0) == 0) return database(r);
  return error_response(404, "no such page: " + p);
}

std::unique_ptr<EventStream> StationSite::open_stream(const HttpRequest& r) {
  if (r.path != "/api/events" || !hub_) return nullptr;
  return hub_->mailbox();
}

HttpResponse StationSite::answer(const HttpRequest& r) {
  if (r.method != "POST") return error_response(405, "POST {\"id\": N, \"answer\": WORD}");
  if (!hub_) return error_response(409, "no qualification is running here");
  const nlohmann::json body = nlohmann::json::parse(r.body, nullptr, false);
  const bool values_ok = !body.is_object() || !body.contains("values") ||
                         (body["values"].is_object() && std::all_of(body["values"].begin(), body["values"].end(),
                                                                    [](const nlohmann::json& v) { return v.is_string(); }));
  if (body.is_discarded() || !body.is_object() || !body.contains("id") || !body["id"].is_number_unsigned() || !body.contains("answer") ||
      !body["answer"].is_string() || !values_ok) {
    return error_response(400, "expected {\"id\": N, \"answer\": \"confirm\"|\"abort\"|\"retry\"|\"continue\"[, \"values\": {FIELD: TEXT}]}");
  }
  std::map<std::string, std::string> typed;
  if (body.contains("values")) {
    for (const auto& [k, v] : body["values"].items()) typed[k] = v.get<std::string>();
  }
  const AnswerResult a = hub_->answer(body["id"].get<std::uint64_t>(), body["answer"].get<std::string>(), typed);
  if (a.status == AnswerResult::Status::kNotOpen) return error_response(409, a.message);
  if (a.status == AnswerResult::Status::kRefused) return error_response(422, a.message);
  return json_response(200, R"({"ok":true})");
}

HttpResponse StationSite::database(const HttpRequest& r) {
  const std::string& p = r.path;
  try {
    if (p == "/api/qualifications") {
      nlohmann::json doc = nlohmann::json::array();
      for (const auto& q : store_.list(query(r, "batch"), 500)) doc.push_back(station::qualification_json(q, {}));
      return json_response(200, text_of(doc));
    }
    if (p == "/api/charts") return json_response(200, text_of(station::control_charts_json(station::control_charts(store_, query(r, "batch")))));
    for (const std::string prefix : {"/api/units/", "/api/certificate/"}) {
      if (p.rfind(prefix, 0) != 0) continue;
      const std::string serial = p.substr(prefix.size());
      if (!plausible_serial(serial)) return error_response(400, "a serial of letters, digits, '-', '_' and '.'");
      const auto q = store_.latest_qualification(serial);
      if (!q) return error_response(404, "no unit " + serial + " in the database");
      const auto tries = store_.phase_tries(q->id);
      if (prefix == "/api/units/") {
        nlohmann::json doc = station::qualification_json(*q, tries);
        doc["reasons"] = q->reasons;
        return json_response(200, text_of(doc));
      }
      if (q->status != "complete") return error_response(404, "unit " + serial + " has no completed qualification");
      std::string html = station::certificate_html(*q, tries);
      if (station::sha256_text(html) != q->certificate_sha256) return error_response(409, "the certificate differs from the one stored");
      return {200, "text/html; charset=utf-8", std::move(html), {}};
    }
  } catch (const Error& e) {
    return error_response(500, e.what());
  }
  return error_response(404, "no such endpoint: " + p);
}

}  // namespace piezobench::web
