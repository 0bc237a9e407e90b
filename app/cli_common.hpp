#pragma once
// What every piezobench command shares: how it is registered, how it prints, how lists are parsed.
#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "piezobench/core/fit_quality.hpp"
#include "piezobench/io/frf_file.hpp"

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
CLI::App* add_superelement_update_command(CLI::App& superelement, Action& action);  // superelement update
void add_simulate_commands(CLI::App& app, Action& action);  // simulate
void add_measure_commands(CLI::App& app, Action& action);  // measure, bench serve
void add_run_commands(CLI::App& app, Action& action);  // run, merge, demo
void add_hysteresis_commands(CLI::App& app, Action& action);  // hysteresis fit, hysteresis creep
void add_qualify_commands(CLI::App& app, Action& action);  // qualify, db
void add_twin_commands(CLI::App& app, Action& action);        // twin
void add_station_commands(CLI::App& app, Action& action);  // station serve

// Prints exactly one JSON document on stdout (round-trip precision for doubles; invalid UTF-8 in a
// string replaced by U+FFFD).
void print_json(const nlohmann::json& document);

// "de, Vs" -> {"de", "Vs"} (items trimmed); InputError naming `option` for an empty item.
std::vector<std::string> split_list(const std::string& text, const std::string& option);

// "0,1000,1e4" -> {0, 1000, 10000}; InputError naming `option` for anything else.
std::vector<double> parse_number_list(const std::string& text, const std::string& option);

// A progress or log line on stderr.
void log_line(const std::string& message);

// A CLI11 check that runs the library's own parser of the option (e.g. dsp::window_type_from_string):
// its InputError becomes a command-line error, exit 2, before any computation.
CLI::Validator parsed_by(const std::function<void(const std::string&)>& parse, const std::string& description);

// A fit's verdict in JSON, its declared view (core/fit_quality.hpp): "quality" ("good"/"poor"),
// "quality_problems", "quality_advice", "quality_impossible".
nlohmann::json quality_json(const core::FitQuality& quality);
// core::kPoorFitExitCode (6) for a poor fit, else 0.
int exit_code_for(const core::FitQuality& quality);
// Prints a poor fit's problems and what to try on stderr; returns exit_code_for(quality).
int report_quality(const core::FitQuality& quality);

// `--units de=um,Vs=mV` (units of the input file's channels, replacing what the file says or
// giving what it does not), added the same way to every command that reads a measurement or an
// FRF file (frf, fit, fit iff-plant, model tune).
void add_units_option(CLI::App* command, std::string& text);
// "de=um, Vs=mV" -> {de: um, Vs: mV}; UsageError (option --units, exit 2) for an item without
// '=', a name twice or a unit the unit table cannot parse (io/units.hpp).
std::map<std::string, std::string> parse_units(const std::string& text);
// Each warning on stderr ("piezobench: warning: ...").
void print_warnings(const std::vector<std::string>& warnings);
// An FRF file read with the command's --units (io::read_frf_file); its warnings printed.
io::FrfFile read_frf_with_units(const std::string& file, const std::string& units);

// A check that an output file's extension is one of `extensions` (lower case, with the dot).
CLI::Validator output_extension(const std::vector<std::string>& extensions);

// An input file that exists and can be read. Unlike CLI11's ExistingFile (exit 2), a missing or
// unreadable input file is bad input data, exit 3, in every command (docs/cli.md): the check throws
// InputError(path, "file", ...), which main() maps like a reader's.
CLI::Validator input_file();

// A number in [lo, hi] (hi may be infinite: "a number >= lo"); the message prints the limits as
// people write them ("expected a number in [1000, 1e+15], found 5"), where CLI11's Range prints
// std::to_string of the double (309 digits for its NonNegativeNumber's upper limit).
CLI::Validator number_in(double lo, double hi);
// number_in(0, inf) and a number > 0.
CLI::Validator non_negative();
CLI::Validator positive();

// The long option of `app` (a subcommand, with its parents' options) nearest to `unknown` by edit
// distance, "" when none is near (more than a third of its letters, at least 2, differ).
std::string nearest_option(const CLI::App& app, const std::string& unknown);

}  // namespace piezobench::app
