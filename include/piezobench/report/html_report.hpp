#pragma once
// The campaign's report: one self-contained HTML file (works offline: the plotting library is
// inlined) with the acceptance table, the per-unit figures and interactive plots.
//
// The report renders what it is given; the campaign decides what to plot. The document is JSON:
//   {
//     "title": "APA300ML batch ...",            string
//     "subtitle": "...",                         string, optional (campaign file, date, version)
//     "results": { ... },                        the results.json document (CLI.md keys): the
//                                                acceptance table is built from results.units
//                                                (id, accepted, reasons and the key figures)
//     "sections": [                              in order
//       { "title": "Frequency responses", "text": "optional paragraph",
//         "figures": [ FIGURE, ... ] } ]
//   }
//   FIGURE = { "id": "frf-de",                   unique, [a-z0-9-]
//              "title": "u -> d_e",
//              "x_label": "Frequency [Hz]", "x_log": true,
//              "panels": [                       stacked vertically, sharing the x axis
//                { "y_label": "|H| [um/V]", "y_log": true,
//                  "traces": [ { "name": "APA 1", "x": [..], "y": [..],
//                                "mode": "lines" | "markers" | "lines+markers",
//                                "dash": false, "group": "APA 1" } ] } ] }
//   Non-finite numbers in x/y are allowed as JSON null (gaps). "group" links traces of the same
//   unit across panels (one legend entry, toggled together).
#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace piezobench::report {

// The HTML text of the report. InputError (source "report document") naming the field for a
// document that does not follow the layout above (missing title, x and y of different lengths,
// duplicate figure ids, ...).
std::string render_html(const nlohmann::json& document);

// render_html written atomically to `file` (no half-written report on failure).
void write_html(const nlohmann::json& document, const std::filesystem::path& file);

}  // namespace piezobench::report
