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
//
// Details and additions to the layout above (docs/report.md shows the page):
//   - Required: "title", "results" (an object), "sections"; per section "title" and "figures"; per
//     figure "id", "title" and "panels" (at least one); per trace "name", "x" and "y". Everything
//     else is optional: "x_label"/"y_label" default to "", "x_log"/"y_log" and "dash" to false,
//     "mode" to "lines", "group" to none (the trace is its own legend entry). Unknown keys in the
//     document, sections, figures, panels and traces are errors (they are typos of known ones).
//   - x and y have the same length. Their entries are numbers, null, or the strings "nan", "inf",
//     "-inf" that io::to_json writes (all three are drawn as gaps). An x made only of strings is a
//     category axis (unit names for batch comparisons); every trace of that figure then has one
//     and "x_log" must be false.
//   - "mode" may also be "bars" (a bar per x, bars of one x side by side), or "band": a shaded area
//     between y (lower edge) and "y_upper" (upper edge, as many values; only a band has it), drawn
//     under the group's curves without a legend entry of its own (the 95 % bands of the FRFs).
//   - Additions: section "id" ([a-z0-9-], unique, default "section-N"), figure "text" (a caption),
//     section "warnings" (a list of strings, shown highlighted above everything else of the
//     section), section "tables" (before the figures): [{ "title", "text" (optional caption),
//     "columns": [strings], "rows": [[cell, ...], ...] }] with one cell per column, each a number
//     (shown to 3 significant digits), a string, true/false or null ("–"); trace "text": one hover
//     label per point (string or null), shown with the point's x and y.
//   - A trace's colour is its group's (its name's when it has no group), the same in every figure.
//   - results.units: a list of objects with "id" (string or number, unique), optional "name" (shown
//     instead of the id), "accepted" (bool), "reasons" (a list of strings, at least one for a unit
//     not accepted) and optional "not_analysed" {"file", "key", "reason"} (a unit whose data could
//     not be analysed: neither accepted, which is then an error, nor rejected). The key figures
//     of the table are read where CLI.md puts them (flatness_um, capacitance_uF.{sensor,actuator},
//     stroke_um, stiffness_N_per_um.{k1,k2,resonance}, frf.{resonance_Hz,antiresonance_Hz,
//     static_gain_um_per_V}, hpf_corner_Hz); a missing or null one reads "not measured". The
//     batch summary counts the units and names the rejected and not analysed ones. Other keys of
//     results are ignored (results.batch must be an object when present; its tables belong in a
//     section), except results.iff.optimal_gain.
//   Every string is escaped: a unit name or a reason cannot inject HTML or script.
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

namespace piezobench::report {

// The HTML text of the report. InputError (source "report document") naming the field for a
// document that does not follow the layout above (missing title, x and y of different lengths,
// duplicate figure ids, ...).
std::string render_html(const nlohmann::json& document);

// render_html written atomically to `file` (no half-written report on failure).
void write_html(const nlohmann::json& document, const std::filesystem::path& file);

}  // namespace piezobench::report
