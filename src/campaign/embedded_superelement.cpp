// The shipped APA300ML super element, pulled into the object file by the assembler (.incbin). The
// folder and a SHA-256 of the files are compile definitions set by src/campaign/CMakeLists.txt; the
// hash is part of the preprocessed text, so ccache rebuilds this file whenever a file changes.
#include "embedded_superelement.hpp"

#include "piezobench/io/atomic_file.hpp"

#ifndef PIEZOBENCH_SE_DIR
#error "PIEZOBENCH_SE_DIR is set by src/campaign/CMakeLists.txt"
#endif

// clang-format off
#define PIEZOBENCH_SE_BLOB(name, file)                  \
  ".balign 16\n"                                        \
  ".globl piezobench_se_" name "_begin\n"               \
  ".hidden piezobench_se_" name "_begin\n"              \
  "piezobench_se_" name "_begin:\n"                     \
  ".incbin \"" PIEZOBENCH_SE_DIR "/" file "\"\n"        \
  ".globl piezobench_se_" name "_end\n"                 \
  ".hidden piezobench_se_" name "_end\n"                \
  "piezobench_se_" name "_end:\n"                       \
  ".byte 0\n"

asm(".pushsection .rodata.piezobench_se,\"a\",@progbits\n"
    "# files sha256 " PIEZOBENCH_SE_SHA256 "\n"
    PIEZOBENCH_SE_BLOB("k", "apa300ml_K.mtx")
    PIEZOBENCH_SE_BLOB("m", "apa300ml_M.mtx")
    PIEZOBENCH_SE_BLOB("dofs", "apa300ml_dofs.txt")
    PIEZOBENCH_SE_BLOB("toml", "apa300ml.toml")
    ".popsection\n");
// clang-format on

#define PIEZOBENCH_SE_DECLARE(name)                                                           \
  extern "C" __attribute__((visibility("hidden"))) const char piezobench_se_##name##_begin[]; \
  extern "C" __attribute__((visibility("hidden"))) const char piezobench_se_##name##_end[];

PIEZOBENCH_SE_DECLARE(k)
PIEZOBENCH_SE_DECLARE(m)
PIEZOBENCH_SE_DECLARE(dofs)
PIEZOBENCH_SE_DECLARE(toml)

namespace piezobench::campaign::detail {
namespace {
std::string_view blob(const char* begin, const char* end) { return {begin, static_cast<std::string_view::size_type>(end - begin)}; }
}  // namespace

std::vector<EmbeddedFile> apa300ml_superelement_files() {
  return {{"apa300ml_K.mtx", blob(piezobench_se_k_begin, piezobench_se_k_end)},
          {"apa300ml_M.mtx", blob(piezobench_se_m_begin, piezobench_se_m_end)},
          {"apa300ml_dofs.txt", blob(piezobench_se_dofs_begin, piezobench_se_dofs_end)},
          {"apa300ml.toml", blob(piezobench_se_toml_begin, piezobench_se_toml_end)}};
}

std::filesystem::path write_apa300ml_superelement(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  for (const EmbeddedFile& f : apa300ml_superelement_files()) io::write_text_atomically(dir / f.name, std::string(f.text));
  return dir / "apa300ml.toml";
}

}  // namespace piezobench::campaign::detail
