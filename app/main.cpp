// The piezobench command: parses the command line, runs the selected command, and maps failures to
// the exit codes of CLI.md (0 done, 2 bad command line, 3 bad input data, 4 numerical failure).
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/version.hpp"

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(piezobench::ExitCode::kUsage);
  }
  try {
    return action ? action() : 0;
  } catch (const piezobench::Error& e) {
    std::cerr << "piezobench: error: " << e.what() << '\n';
    return static_cast<int>(e.exit_code());
  } catch (const std::bad_alloc&) {
    std::cerr << "piezobench: error: out of memory\n";
    return static_cast<int>(piezobench::ExitCode::kNumerical);
  } catch (const std::exception& e) {
    std::cerr << "piezobench: internal error: " << e.what() << '\n';
    return 1;
  }
}
