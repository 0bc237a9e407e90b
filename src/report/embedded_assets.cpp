// The report's assets, pulled into the object file by the assembler (.incbin) rather than compiled
// as a multi-megabyte C++ string literal. The paths and a SHA-256 of the files are compile
// definitions set by src/report/CMakeLists.txt; the hash is part of the preprocessed text, so
// ccache rebuilds this file whenever an asset changes.
#include "report/embedded_assets.hpp"

#ifndef PIEZOBENCH_REPORT_PLOTLY_JS
#error "PIEZOBENCH_REPORT_PLOTLY_JS is set by src/report/CMakeLists.txt"
#endif

// begin/end symbol pairs in .rodata; each blob is followed by a NUL that is not part of it.
// clang-format off
#define PIEZOBENCH_REPORT_BLOB(name, file)              \
  ".balign 16\n"                                        \
  ".globl piezobench_report_" name "_begin\n"           \
  ".hidden piezobench_report_" name "_begin\n"          \
  "piezobench_report_" name "_begin:\n"                 \
  ".incbin \"" file "\"\n"                              \
  ".globl piezobench_report_" name "_end\n"             \
  ".hidden piezobench_report_" name "_end\n"            \
  "piezobench_report_" name "_end:\n"                   \
  ".byte 0\n"

asm(".pushsection .rodata.piezobench_report,\"a\",@progbits\n"
    "# assets sha256 " PIEZOBENCH_REPORT_ASSETS_SHA256 "\n"
    PIEZOBENCH_REPORT_BLOB("plotly", PIEZOBENCH_REPORT_PLOTLY_JS)
    PIEZOBENCH_REPORT_BLOB("script", PIEZOBENCH_REPORT_SCRIPT_JS)
    PIEZOBENCH_REPORT_BLOB("style", PIEZOBENCH_REPORT_STYLE_CSS)
    ".popsection\n");
// clang-format on

#define PIEZOBENCH_REPORT_DECLARE(name)                                                           \
  extern "C" __attribute__((visibility("hidden"))) const char piezobench_report_##name##_begin[]; \
  extern "C" __attribute__((visibility("hidden"))) const char piezobench_report_##name##_end[];

PIEZOBENCH_REPORT_DECLARE(plotly)
PIEZOBENCH_REPORT_DECLARE(script)
PIEZOBENCH_REPORT_DECLARE(style)

namespace piezobench::report::detail {

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

}  // namespace piezobench::report::detail
