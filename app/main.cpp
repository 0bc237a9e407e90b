// The piezobench command: parses the command line, runs the selected command, and maps failures to
// the exit codes of docs/cli.md (0 done, 2 bad command line, 3 bad input data, 4 numerical failure;
// 5, 6 and 7 are returned by the commands). With --json a failure is also one JSON document on
// stdout ({"error": {...}}), so a script reading stdout always gets one document.
#include <CLI/CLI.hpp>
#include <cstring>
#include <exception>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/version.hpp"

namespace {

// The subcommand the command line names (the deepest one), else the application.
const CLI::App* selected_command(const CLI::App& app, int argc, char** argv) {
  const CLI::App* current = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.empty() || arg.front() == '-') continue;
    const auto named = current->get_subcommands([&](const CLI::App* s) { return s->check_name(arg); });
    if (!named.empty()) current = named.front();
  }
  return current;
}

bool wants_json(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) return false;
    if (std::strcmp(argv[i], "--json") == 0) return true;
  }
  return false;
}

// The JSON error document of --json: kind (usage, input, numerical, internal), message, exit code,
// and for bad input the file (source) and field.
void print_json_error(const std::string& kind, const std::string& message, int code, const piezobench::InputError* input = nullptr) {
  nlohmann::json error = {{"kind", kind}, {"message", message}, {"exit_code", code}};
  if (input != nullptr) {
    error["source"] = input->source();
    error["field"] = input->field();
  }
  piezobench::app::print_json({{"error", error}});
}

}  // namespace

int main(int argc, char** argv) {
  using piezobench::app::Action;
  CLI::App app{"piezobench: characterize, model and damp amplified piezoelectric actuators on a test bench",
               "piezobench"};
  app.set_version_flag("--version", std::string("piezobench ") + piezobench::kVersion);
  app.require_subcommand(1);
  Action action;
  piezobench::app::add_frf_commands(app, action);
  piezobench::app::add_iff_commands(app, action);
  piezobench::app::add_rt_commands(app, action);
  piezobench::app::add_model_commands(app, action);
  piezobench::app::add_superelement_commands(app, action);
  piezobench::app::add_simulate_commands(app, action);
  piezobench::app::add_measure_commands(app, action);
  piezobench::app::add_run_commands(app, action);
  piezobench::app::add_hysteresis_commands(app, action);
  piezobench::app::add_qualify_commands(app, action);
  piezobench::app::add_twin_commands(app, action);
  piezobench::app::add_station_commands(app, action);

  const bool json = wants_json(argc, argv);
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
      std::string message = e.what();
      if (const auto* extras = dynamic_cast<const CLI::ExtrasError*>(&e)) {
        (void)extras;
        const CLI::App* command = selected_command(app, argc, argv);
        for (int i = 1; i < argc; ++i) {
          const std::string arg = argv[i];
          if (arg.size() < 2 || arg[0] != '-' || message.find(arg) == std::string::npos) continue;
          const std::string near = piezobench::app::nearest_option(*command, arg);
          if (!near.empty()) message += "; did you mean " + near + " (instead of " + arg.substr(0, arg.find('=')) + ")?";
        }
      }
      std::cerr << "piezobench: error: " << message << "\nRun with --help for more information.\n";
      if (json) print_json_error("usage", message, static_cast<int>(piezobench::ExitCode::kUsage));
      return static_cast<int>(piezobench::ExitCode::kUsage);
    }
    return action ? action() : 0;
  } catch (const piezobench::InputError& e) {
    std::cerr << "piezobench: error: " << e.what() << '\n';
    if (json) print_json_error("input", e.what(), static_cast<int>(e.exit_code()), &e);
    return static_cast<int>(e.exit_code());
  } catch (const piezobench::Error& e) {
    std::cerr << "piezobench: error: " << e.what() << '\n';
    const int code = static_cast<int>(e.exit_code());
    if (json) print_json_error(code == static_cast<int>(piezobench::ExitCode::kUsage) ? "usage" : "numerical", e.what(), code);
    return code;
  } catch (const std::bad_alloc&) {
    std::cerr << "piezobench: error: out of memory\n";
    if (json) print_json_error("numerical", "out of memory", static_cast<int>(piezobench::ExitCode::kNumerical));
    return static_cast<int>(piezobench::ExitCode::kNumerical);
  } catch (const std::exception& e) {
    std::cerr << "piezobench: internal error: " << e.what() << '\n';
    if (json) print_json_error("internal", e.what(), 1);
    return 1;
  }
}
