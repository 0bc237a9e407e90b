// Writes the representative report (sample_document.hpp) to the file named by its argument; the
// headless Chromium test (render_check.js) opens it. Registered in tests/report/CMakeLists.txt.
#include <exception>
#include <iostream>

#include "piezobench/report/html_report.hpp"
#include "report/sample_document.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: report_render_sample OUT.html\n";
    return 2;
  }
  try {
    piezobench::report::write_html(piezobench::test::report_sample::document(), argv[1]);
  } catch (const std::exception& e) {
    std::cerr << "report_render_sample: " << e.what() << "\n";
    return 1;
  }
  std::cout << "wrote " << argv[1] << "\n";
  return 0;
}
