// The station's web page from the command line (station_ui.hpp) and `piezobench station serve`.
#include "station_ui.hpp"

#include <fmt/format.h>

#include <chrono>
#include <ctime>
#include <thread>

#include "cli_common.hpp"
#include "measure_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"

namespace piezobench::app {

namespace {

// "HOST:PORT" (HOST an IP literal, IPv6 in brackets) -> host, port.
std::pair<std::string, unsigned short> split_listen(const std::string& text) {
  const std::size_t colon = text.rfind(':');
  std::string host = colon == std::string::npos ? "" : text.substr(0, colon);
  const std::string port = colon == std::string::npos ? "" : text.substr(colon + 1);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const bool digits = !port.empty() && port.size() <= 5 && std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (host.empty() || !digits || std::stol(port) > 65535) {
    throw UsageError("--ui", "ADDRESS:PORT, e.g. 127.0.0.1:8080 (port 0: any free port)", "'" + text + "'");
  }
  return {host, static_cast<unsigned short>(std::stol(port))};
}

// Seconds since 1970 of "2026-11-27T12:00:00.123Z"; NaN when it is not one.
double iso_seconds(const std::string& s) {
  std::tm tm{};
  int ms = 0;
  if (std::sscanf(s.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &ms) < 6) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  tm.tm_year -= 1900, tm.tm_mon -= 1;
  return static_cast<double>(timegm(&tm)) + ms / 1000.0;
}

}  // namespace

void add_ui_options(CLI::App* command, UiCli& ui, const std::string& default_listen) {
  ui.listen = default_listen;
  command->add_option("--ui", ui.listen,
                      "serve the station's page on ADDRESS:PORT (127.0.0.1 unless told otherwise; any other address needs the printed token)");
  command->add_option("--ui-linger", ui.linger_s, "serve the page this many seconds after the qualification (default: until Ctrl-C)");
  command->add_option("--ui-max-pages", ui.max_streams, "pages that may follow the station at once")->capture_default_str()->check(CLI::Range(1, 256));
}

StationUi::StationUi(const UiCli& cli, const std::filesystem::path& database, web::LiveHub* hub) : cli_(cli) {
  const auto [host, port] = split_listen(cli.listen);
  web::HttpServerOptions so;
  so.address = host;
  so.port = port;
  so.operator_token = web::random_token();
  if (!web::is_loopback_address(host)) so.view_token = web::random_token();
  so.max_streams = cli.max_streams;
  so.max_connections = std::max<std::size_t>(64, 4 * cli.max_streams);
  site_ = std::make_unique<web::StationSite>(database, hub);
  server_ = std::make_unique<web::HttpServer>(so, *site_);
  server_->start();
  const std::string base = fmt::format("http://{}:{}/", host.find(':') != std::string::npos ? "[" + host + "]" : host, server_->port());
  log_line(fmt::format("station page: {}#token={}  (operator: answers the prompts; keep this address private)", base, so.operator_token));
  if (server_->loopback()) {
    log_line(fmt::format("station page, read-only: {}  (this machine only)", base));
  } else {
    log_line(fmt::format("station page, read-only: {}#token={}  (every request must carry a token on {})", base, so.view_token, host));
  }
}

void StationUi::linger(const std::atomic<bool>* stop) const {
  if (cli_.linger_s == 0.0) return;
  log_line(cli_.linger_s < 0 ? std::string("station page: still served; Ctrl-C ends it")
                             : fmt::format("station page: still served for {} s (Ctrl-C ends it)", cli_.linger_s));
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(cli_.linger_s < 0 ? 1e9 : cli_.linger_s);
  while (std::chrono::steady_clock::now() < end && !(stop && stop->load())) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

std::map<std::string, double> expected_phase_durations(const station::RecordStore& store, const std::string& station_name) {
  std::map<std::string, double> out;
  for (const auto& q : store.list("", 200)) {
    if (q.status != "complete" || q.station != station_name) continue;
    for (const auto& t : store.phase_tries(q.id)) {
      const double d = iso_seconds(t.finished) - iso_seconds(t.started);
      if (t.status == "complete" && std::isfinite(d) && d >= 0) out[t.phase_name] = d;
    }
    break;
  }
  return out;
}

namespace {

struct StationServeCli {
  std::string db = "station.db";
  UiCli ui;
};

int run_station_serve(const StationServeCli& o) {
  if (!std::filesystem::exists(o.db)) throw InputError(o.db, "database", "an existing station database (qualify writes it)", "no such file");
  StationUi ui(o.ui, o.db, nullptr);
  ui.linger(stop_on_sigint());
  return 0;
}

}  // namespace

void add_station_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<StationServeCli>();
  CLI::App* st = app.add_subcommand("station", "The station's web page (docs/station.md)");
  st->require_subcommand(1);
  CLI::App* serve = st->add_subcommand("serve", "Serve the station database's page: units, batches, control charts, certificates");
  serve->add_option("--db", o->db, "station database (SQLite)")->capture_default_str();
  add_ui_options(serve, o->ui, "127.0.0.1:8080");
  serve->callback([o, &action] { action = [o] { return run_station_serve(*o); }; });
}

}  // namespace piezobench::app
