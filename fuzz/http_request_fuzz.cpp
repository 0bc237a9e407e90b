// libFuzzer target of the station's web server (docs/fuzzing.md, issue 35): each input is the bytes
// a client sends on a new connection to `qualify --ui` / `station serve`, handled by
// web::exchange_request (the server's own parser, limits and checks of size, method, path, query,
// Host, Origin and tokens, then the station's site: its pages, the database's endpoints and
// POST /api/answer with typed values), twice: a server on 127.0.0.1:8080 (the loopback rules) and
// one on 0.0.0.0:8080 (a view token on every request). The site is the real StationSite over a
// database of one qualified unit (SN1) and a LiveHub whose open prompt (id 1, a new hub for each input)
// is the typed values of a phase of fuzz/seeds/station_toml/values.toml: capacitances (even input
// sizes) or a file (odd), checked by station::typed_values as the page's operator checks them.
//
// Nothing may escape exchange_request (on the server an exception would end its I/O thread), and
// the harness aborts (a finding) when the server's contract breaks: the site sees a path that is
// not absolute or has a "." or ".." segment, a control character or a backslash; a POST without
// the operator token; a prompt answered other than by the operator's POST; a status outside
// 100..599, or a refusal that is not {"error": TEXT}.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "piezobench/core/error.hpp"
#include "piezobench/station/certificate.hpp"
#include "piezobench/station/record_store.hpp"
#include "piezobench/station/station_file.hpp"
#include "piezobench/web/http_server.hpp"
#include "piezobench/web/live_hub.hpp"
#include "piezobench/web/station_site.hpp"

namespace {

namespace fs = std::filesystem;
namespace station = piezobench::station;
namespace web = piezobench::web;

constexpr const char* kOperatorToken = "0123456789abcdef0123456789abcdef";
constexpr const char* kViewToken = "fedcba9876543210fedcba9876543210";

fs::path database;
const bool verbose = std::getenv("PIEZOBENCH_FUZZ_VERBOSE") != nullptr;  // each input's outcome on stderr
station::StationFile values_station;

// A server's options and its site; the hub is made anew for each input at the same address (the
// site keeps a pointer to it), so that every input finds prompt 1 open and nothing else.
struct Server {
  web::HttpServerOptions options;
  std::optional<web::LiveHub> hub;
  std::unique_ptr<web::StationSite> site;
};
Server loopback_server, network_server;

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "piezobench fuzz: %s\n", what.c_str());
  std::abort();
}

// A database of one complete qualification with a stroke measurement and its certificate's hash.
void make_database(const fs::path& file) {
  station::RecordStore store(file);
  station::QualificationRow q;
  q.serial = "SN1", q.batch = "B1", q.station = "fuzz", q.started = "2026-11-27T12:00:00.000Z";
  q.id = store.begin_qualification(q);
  station::PhaseTryRow stroke = store.begin_phase_try(q.id, 0, "stroke");
  stroke.status = "complete", stroke.verdict = "pass", stroke.finished = "2026-11-27T12:01:00.000Z";
  stroke.measurements.push_back({"stroke_um", "um", 250.0, 200.0, std::nullopt, "pass", "", false});
  store.finish_phase_try(stroke);
  q.status = "complete", q.verdict = "pass", q.finished = "2026-11-27T12:02:00.000Z";
  store.finish_qualification(q);
  const auto stored = store.qualification(q.id);
  store.set_certificate(q.id, station::sha256_text(station::certificate_html(*stored, store.phase_tries(q.id))));
}

bool acceptable_path(const std::string& p) {
  if (p.empty() || p.front() != '/' || p.size() > 1024) return false;
  if (std::any_of(p.begin(), p.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '\\'; })) return false;
  const std::string padded = p + "/";
  return padded.find("/./") == std::string::npos && padded.find("/../") == std::string::npos;
}

void check_refusal(const web::HttpResponse& r) {
  const nlohmann::json body = nlohmann::json::parse(r.body, nullptr, false);
  if (!body.is_object() || !body.contains("error") || !body["error"].is_string()) finding("a refusal that is not {\"error\": TEXT}: " + r.body);
}

void serve_once(Server& server, std::string_view bytes) {
  server.hub.reset();
  web::LiveHub& hub = server.hub.emplace();
  const station::PhaseSpec& phase = values_station.phases[bytes.size() % 2 == 0 ? 1 : 0];
  const std::uint64_t id = hub.open_prompt(phase.name, "type the values", {"confirm"}, station::typed_value_fields(phase),
                                           [&phase](const std::map<std::string, std::string>& typed) {
                                             try {
                                               (void)station::typed_values(phase, typed);
                                             } catch (const piezobench::Error&) {
                                               throw;  // the refusal the page shows (422)
                                             } catch (const std::exception& e) {
                                               finding(std::string("typed values refused by another exception: ") + e.what());
                                             }
                                           });
  web::HttpExchange x;
  try {
    x = web::exchange_request(server.options, *server.site, bytes);
  } catch (const std::exception& e) {
    finding(std::string("an exception left the request's handling (it would end the server's thread): ") + e.what());
  }
  const int status = x.response.status;
  if (verbose) {
    std::fprintf(stderr, "piezobench fuzz: %s: %s %d%s%s\n", server.options.address.c_str(),
                 x.outcome == web::HttpExchange::Outcome::kClosed ? "closed" : x.outcome == web::HttpExchange::Outcome::kStream ? "stream" : "answered",
                 status, x.by_site ? " by the site" : "", hub.wait_answer(id, std::chrono::milliseconds(0)) ? ", prompt answered" : "");
  }
  if (x.outcome == web::HttpExchange::Outcome::kAnswered && (status < 100 || status > 599)) finding("status " + std::to_string(status));
  if (x.outcome == web::HttpExchange::Outcome::kAnswered && !x.by_site) check_refusal(x.response);
  if (x.by_site) {
    const web::HttpRequest& r = x.request;
    if (!acceptable_path(r.path)) finding("the site saw the path '" + r.path + "'");
    if (r.method == "POST" && !r.operator_rights) finding("the site saw a POST without the operator token");
    if (r.method != "GET" && r.method != "HEAD" && r.method != "POST") finding("the site saw the method " + r.method);
  }
  if (hub.wait_answer(id, std::chrono::milliseconds(0))) {
    if (!x.by_site || x.request.method != "POST" || !x.request.operator_rights || x.request.path != "/api/answer" || status != 200) {
      finding("the prompt was answered by a request that may not answer it");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  try {
    const char* tmp = std::getenv("TMPDIR");
    const fs::path dir = fs::path(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") / ("piezobench-fuzz-http-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(database.parent_path(), ec);
    });
    database = dir / "station.db";
    make_database(database);
    values_station = station::read_station_file(PIEZOBENCH_STATION_VALUES);
    if (values_station.phases.size() != 2) finding("the values station file has not its two phases");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "piezobench fuzz: the web target's set-up failed: %s\n", e.what());
    std::exit(2);
  }
  for (Server* s : {&loopback_server, &network_server}) {
    s->options.address = s == &loopback_server ? "127.0.0.1" : "0.0.0.0";
    s->options.port = 8080;
    s->options.operator_token = kOperatorToken;
    if (s == &network_server) s->options.view_token = kViewToken;
    s->hub.emplace();
    s->site = std::make_unique<web::StationSite>(database, &*s->hub);
  }
  (void)argc, (void)argv;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  serve_once(loopback_server, bytes);
  serve_once(network_server, bytes);
  return 0;
}
