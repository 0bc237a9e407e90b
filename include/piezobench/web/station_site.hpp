#pragma once
// The station's page and its endpoints (docs/station.md, "Endpoints"), served by HttpServer:
//
//   GET  /  (/index.html), /station.js, /station.css, /plotly.min.js   the page: a fixed set of files
//        built into the program (no path from the URL reaches the file system)
//   GET  /api/state            the live qualification (LiveHub::state_json), {"live": false} without
//   GET  /api/events           its Server-Sent Events (LiveHub's mailbox), one message per change
//                              at most every 50 ms
//   POST /api/answer           {"id": PROMPT, "answer": "confirm"|"abort"|"retry"|"continue"}:
//                              answers the open prompt (operator token); 409 when it is not open
//   GET  /api/qualifications[?batch=B]   the database's qualifications, newest first (db list --json)
//   GET  /api/units/SN         a unit's newest qualification with every try (db show --json, without
//                              the results)
//   GET  /api/charts[?batch=B] the control charts (db charts) as JSON
//   GET  /api/certificate/SN   the unit's certificate (HTML), regenerated from the database and
//                              checked against its stored SHA-256 (409 when it differs)
// Anything else: 404. The database is opened by the site (its own connection, on the server's
// thread).
#include <filesystem>
#include <memory>
#include <optional>

#include "piezobench/station/record_store.hpp"
#include "piezobench/web/http_server.hpp"
#include "piezobench/web/live_hub.hpp"

namespace piezobench::web {

class StationSite final : public Site {
 public:
  // `hub`: the live qualification (qualify --ui), or null (station serve). InputError when the
  // database cannot be opened.
  StationSite(const std::filesystem::path& database, LiveHub* hub);
  HttpResponse handle(const HttpRequest& request) override;
  std::unique_ptr<EventStream> open_stream(const HttpRequest& request) override;
  [[nodiscard]] bool accepts_post(const std::string& path) const override { return path == "/api/answer"; }

 private:
  HttpResponse database(const HttpRequest& request);
  HttpResponse answer(const HttpRequest& request);
  station::RecordStore store_;
  LiveHub* hub_;
};

}  // namespace piezobench::web
