#pragma once
// The files inlined into every report.html, linked into the binary at build time (the assembler's
// .incbin; see src/report/embedded_assets.cpp and src/report/CMakeLists.txt): the plotting library from npm
// (src/report/js/node_modules/plotly.js-dist-min/plotly.min.js, version pinned by
// src/report/js/package-lock.json) and the report's own script and style sheet (src/report/assets/).
// The live station page (web) serves the same plotting library.
#include <string_view>

namespace piezobench::report {

// plotly.min.js, byte for byte.
std::string_view plotting_library();
// The version of the plotting library ("4.1.2"), read from its package.json at configure time.
std::string_view plotting_library_version();
// src/report/assets/report.js and report.css.
std::string_view report_script();
std::string_view report_style();

}  // namespace piezobench::report
