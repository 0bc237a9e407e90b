#pragma once
// The station's web page from the command line (docs/station.md, "The live page"): `qualify --ui
// ADDRESS:PORT` and `station serve --db DB`.
#include <CLI/CLI.hpp>
#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "piezobench/station/record_store.hpp"
#include "piezobench/web/http_server.hpp"
#include "piezobench/web/live_hub.hpp"
#include "piezobench/web/station_site.hpp"

namespace piezobench::app {

struct UiCli {
  std::string listen;       // "127.0.0.1:8080", "[::1]:8080", "0.0.0.0:8080"; empty: no page
  double linger_s = -1.0;   // after the qualification: serve this long (< 0: until Ctrl-C)
  std::size_t max_streams = 16;
};
// --ui, --ui-linger, --ui-max-pages on `command`.
void add_ui_options(CLI::App* command, UiCli& ui, const std::string& default_listen);

// The server and its site; prints the page's addresses (with the tokens) on stderr when started.
class StationUi {
 public:
  StationUi(const UiCli& cli, const std::filesystem::path& database, web::LiveHub* hub);
  // Serves until Ctrl-C (`stop`) or the linger time; prints why it ends.
  void linger(const std::atomic<bool>* stop) const;
  [[nodiscard]] const web::HttpServer& server() const { return *server_; }

 private:
  UiCli cli_;
  std::unique_ptr<web::StationSite> site_;
  std::unique_ptr<web::HttpServer> server_;
};

// Each phase's duration (s) in the newest complete qualification of `station_name` in the database,
// as the live page's estimate of what remains. Empty when there is none.
std::map<std::string, double> expected_phase_durations(const station::RecordStore& store, const std::string& station_name);

}  // namespace piezobench::app
