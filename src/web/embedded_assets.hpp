#pragma once
// The station page's own files (src/web/assets/), linked into the binary at build time (the
// assembler's .incbin; src/web/CMakeLists.txt). The plotting library is the report's
// (report/embedded_assets.hpp).
#include <string_view>

namespace piezobench::web::detail {

std::string_view page_html();
std::string_view page_script();
std::string_view page_style();

}  // namespace piezobench::web::detail
