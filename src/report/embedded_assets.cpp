// The report's assets, pulled into the object file by the assembler (.incbin) rather than compiled
// as a multi-megabyte C++ string literal. The paths and a SHA-256 of the files are compile
// definitions set by src/report/CMakeLists.txt; the hash is part of the preprocessed text, so
// ccache rebuilds this file whenever an asset changes.
#include "piezobench/report/embedded_assets.hpp"
#include "piezobench/core/incbin.hpp"

#ifndef PIEZOBENCH_REPORT_PLOTLY_JS
#error "PIEZOBENCH_REPORT_PLOTLY_JS is set by src/report/CMakeLists.txt"
#endif

// begin/end symbol pairs in .rodata (incbin.hpp).
#define PIEZOBENCH_REPORT_BLOB(name, file) PIEZOBENCH_INCBIN("piezobench_report_" name, file)

asm(".pushsection .rodata.piezobench_report,\"a\",@progbits\n"
    "# assets sha256 " PIEZOBENCH_REPORT_ASSETS_SHA256 "\n"
    PIEZOBENCH_REPORT_BLOB("plotly", PIEZOBENCH_REPORT_PLOTLY_JS)
    PIEZOBENCH_REPORT_BLOB("script", PIEZOBENCH_REPORT_SCRIPT_JS)
    PIEZOBENCH_REPORT_BLOB("style", PIEZOBENCH_REPORT_STYLE_CSS)
    ".popsection\n");

#define PIEZOBENCH_REPORT_DECLARE(name) PIEZOBENCH_INCBIN_DECLARE(piezobench_report_##name)

PIEZOBENCH_REPORT_DECLARE(plotly)
PIEZOBENCH_REPORT_DECLARE(script)
PIEZOBENCH_REPORT_DECLARE(style)

namespace piezobench::report {

namespace {
std::string_view blob(const char* begin, const char* end) {
  return {begin, static_cast<std::string_view::size_type>(end - begin)};
}
}  // namespace

std::string_view plotting_library() {
  return blob(piezobench_report_plotly_begin, piezobench_report_plotly_end);
}
std::string_view plotting_library_version() {
  return PIEZOBENCH_REPORT_PLOTLY_VERSION;
}
std::string_view report_script() {
  return blob(piezobench_report_script_begin, piezobench_report_script_end);
}
std::string_view report_style() {
  return blob(piezobench_report_style_begin, piezobench_report_style_end);
}

}  // namespace piezobench::report
