#pragma once
// Files linked into the binary by the assembler's .incbin (src/report/embedded_assets.cpp,
// src/web/embedded_assets.cpp): PIEZOBENCH_INCBIN(symbol, "path") is assembler text for an asm()
// statement in a .rodata section; it defines symbol_begin and symbol_end around the file's bytes,
// followed by a NUL that is not part of them. PIEZOBENCH_INCBIN_DECLARE(symbol) declares them.
// clang-format off
#define PIEZOBENCH_INCBIN(symbol, file) \
  ".balign 16\n"                        \
  ".globl " symbol "_begin\n"           \
  ".hidden " symbol "_begin\n"          \
  symbol "_begin:\n"                    \
  ".incbin \"" file "\"\n"              \
  ".globl " symbol "_end\n"             \
  ".hidden " symbol "_end\n"            \
  symbol "_end:\n"                      \
  ".byte 0\n"
// clang-format on

#define PIEZOBENCH_INCBIN_DECLARE(symbol)                                               \
  extern "C" __attribute__((visibility("hidden"))) const char symbol##_begin[]; \
  extern "C" __attribute__((visibility("hidden"))) const char symbol##_end[];
