// The station page's files, pulled into the object file by the assembler (incbin.hpp). The paths
// and a SHA-256 of the files are compile definitions (src/web/CMakeLists.txt), so ccache rebuilds
// this file when one changes.
#include "embedded_assets.hpp"

#include "piezobench/core/incbin.hpp"

#ifndef PIEZOBENCH_WEB_HTML
#error "PIEZOBENCH_WEB_HTML is set by src/web/CMakeLists.txt"
#endif

asm(".pushsection .rodata.piezobench_web,\"a\",@progbits\n"
    "# assets sha256 " PIEZOBENCH_WEB_ASSETS_SHA256 "\n"
    PIEZOBENCH_INCBIN("piezobench_web_html", PIEZOBENCH_WEB_HTML)
    PIEZOBENCH_INCBIN("piezobench_web_script", PIEZOBENCH_WEB_SCRIPT)
    PIEZOBENCH_INCBIN("piezobench_web_style", PIEZOBENCH_WEB_STYLE)
    ".popsection\n");

PIEZOBENCH_INCBIN_DECLARE(piezobench_web_html)
PIEZOBENCH_INCBIN_DECLARE(piezobench_web_script)
PIEZOBENCH_INCBIN_DECLARE(piezobench_web_style)

namespace piezobench::web::detail {

std::string_view page_html() { return {piezobench_web_html_begin, static_cast<std::size_t>(piezobench_web_html_end - piezobench_web_html_begin)}; }
std::string_view page_script() {
  return {piezobench_web_script_begin, static_cast<std::size_t>(piezobench_web_script_end - piezobench_web_script_begin)};
}
std::string_view page_style() {
  return {piezobench_web_style_begin, static_cast<std::size_t>(piezobench_web_style_end - piezobench_web_style_begin)};
}

}  // namespace piezobench::web::detail
