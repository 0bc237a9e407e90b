#pragma once
// What every piezobench command shares: how it is registered, how it prints, how lists are parsed.
#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace piezobench::app {

// A command's work, run by main() after the command line is parsed, inside the handler that maps
// errors to exit codes. Returns the exit code.
using Action = std::function<int()>;

// Each command module adds its subcommands to `app`; the selected one stores its work in `action`.
void add_frf_commands(CLI::App& app, Action& action);  // frf, fit
void add_iff_commands(CLI::App& app, Action& action);  // iff rlocus, iff study
void add_rt_commands(CLI::App& app, Action& action);  // rt
void add_model_commands(CLI::App& app, Action& action);  // model 2dof, model tune, piezo
void add_superelement_commands(CLI::App& app, Action& action);  // superelement
void add_simulate_commands(CLI::App& app, Action& action);  // simulate
void add_measure_commands(CLI::App& app, Action& action);  // measure, bench serve
void add_run_commands(CLI::App& app, Action& action);  // run, demo

// Prints exactly one JSON document on stdout (round-trip precision for doubles).
void print_json(const nlohmann::json& document);

// "de, Vs" -> {"de", "Vs"} (items trimmed); InputError naming `option` for an empty item.
std::vector<std::string> split_list(const std::string& text, const std::string& option);

// "0,1000,1e4" -> {0, 1000, 10000}; InputError naming `option` for anything else.
std::vector<double> parse_number_list(const std::string& text, const std::string& option);

// A progress or log line on stderr.
void log_line(const std::string& message);

}  // namespace piezobench::app
