// libFuzzer targets, one per reader (docs/fuzzing.md). This file is compiled once and linked into
// every fuzz_READER executable (fuzz/CMakeLists.txt); the executable's name selects the reader.
//
// Every input must end in a piezobench::Error (InputError or NumericalError: exit 3 or 4 on the
// command line) or in a successful read. Anything else is a bug the fuzzer reports: a crash, a
// sanitizer report, a leak, an RSS or time limit, or another exception (the CLI's exit 1,
// "internal error"), which is turned into an abort here.
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "piezobench/core/error.hpp"

#include "piezobench/apa/two_dof_file.hpp"
#include "piezobench/bench/twin.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/lti_toml.hpp"
#include "piezobench/io/timeseries.hpp"

namespace {

namespace fs = std::filesystem;

// A private folder for the files the path-based readers need (removed at exit). The path is never
// destroyed: a function-local static path was destroyed before the exit handler that removes the
// folder ran (registered first, run last), which then removed nothing and left a folder in /tmp
// per run.
const fs::path& work_dir() {
  static const fs::path* const dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    auto* d = new fs::path(fs::path(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") / ("piezobench-fuzz-" + std::to_string(::getpid())));
    fs::create_directories(*d);
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(work_dir(), ec);
    });
    return d;
  }();
  return *dir;
}

fs::path write_input(const std::string& name, std::string_view bytes) {
  const fs::path file = work_dir() / name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return file;
}

// Multi-file readers take one input split at lines "@@@@" (the seeds use the same layout).
std::vector<std::string_view> split_parts(std::string_view data, std::size_t parts) {
  std::vector<std::string_view> out;
  constexpr std::string_view kSep = "\n@@@@\n";
  while (out.size() + 1 < parts) {
    const std::size_t at = data.find(kSep);
    if (at == std::string_view::npos) break;
    out.push_back(data.substr(0, at));
    data.remove_prefix(at + kSep.size());
  }
  out.push_back(data);
  while (out.size() < parts) out.emplace_back();
  return out;
}

std::string& reader() {
  static std::string name;
  return name;
}

void read(std::string_view data) {
  const std::string& reader = ::reader();
  if (reader == "mat_timeseries") {
    // Both ways `frf` and the other commands read a record: in place from a mapping of the file,
    // and into memory.
    const auto file = write_input("input.mat", data);
    try {
      (void)piezobench::io::read_timeseries_view(file);
    } catch (const piezobench::Error&) {
    }
    (void)piezobench::io::read_timeseries(file);
  }
  if (reader == "csv_timeseries") (void)piezobench::io::read_timeseries(write_input("input.csv", data));
  if (reader == "mat_frf") (void)piezobench::io::read_frf(write_input("input.mat", data));
  if (reader == "csv_frf") (void)piezobench::io::read_frf(write_input("input.csv", data));
  if (reader == "uff58") (void)piezobench::io::read_frf(write_input("input.uff", data));
  if (reader == "lti_toml") (void)piezobench::io::parse_lti_toml(std::string(data), "input.toml");
  if (reader == "campaign_toml") (void)piezobench::campaign::parse_campaign(std::string(data), work_dir() / "campaign.toml", false);
  if (reader == "two_dof_toml") (void)piezobench::apa::parse_two_dof_params(std::string(data), "input.toml");
  if (reader == "twin_toml") {
    // As `simulate --twin` takes it: read, then the twin's bench built (its chain on the default
    // switches) and its linear model formed; a twin read is written back and read the same.
    const piezobench::bench::Twin twin = piezobench::bench::parse_twin(std::string(data), "twin.toml");
    piezobench::bench::BenchOptions options;
    piezobench::bench::apply_chain(twin, options);
    const piezobench::bench::VirtualBench bench(twin.unit, options, 1);
    (void)bench.linear_model();
    const std::string written = piezobench::bench::twin_toml(twin);
    if (piezobench::bench::twin_toml(piezobench::bench::parse_twin(written, "written.toml")) != written) {
      std::fprintf(stderr, "piezobench fuzz: a twin written and read back differs\n");
      std::abort();
    }
  }
  if (reader == "ansys_text") {
    // K, M, master DOF listing (with or without its node list).
    const auto p = split_parts(data, 3);
    (void)piezobench::fem::read_ansys_super_element(write_input("k.txt", p[0]), write_input("m.txt", p[1]),
                                                   write_input("master.txt", p[2]));
  }
  if (reader == "calculix") {
    // .sti, .mas, .dof, .inp (node coordinates).
    const auto p = split_parts(data, 4);
    (void)piezobench::fem::read_calculix_super_element(write_input("a.sti", p[0]), write_input("a.mas", p[1]),
                                                      write_input("a.dof", p[2]), write_input("a.inp", p[3]));
  }
  if (reader == "matrix_market") {
    // K, M, DOF list.
    const auto p = split_parts(data, 3);
    (void)piezobench::fem::read_matrix_market_super_element(write_input("k.mtx", p[0]), write_input("m.mtx", p[1]),
                                                           write_input("dofs.txt", p[2]));
  }
}

}  // namespace

// The reader is the executable's name without "fuzz_" (fuzz_lti_toml -> lti_toml).
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const std::string name = fs::path((*argv)[0]).filename().string();
  const std::vector<std::string> known = {"mat_timeseries", "csv_timeseries", "mat_frf",       "csv_frf",
                                          "uff58",          "lti_toml",       "campaign_toml", "two_dof_toml",
                                          "ansys_text",     "calculix",       "matrix_market", "twin_toml"};
  reader() = name.rfind("fuzz_", 0) == 0 ? name.substr(5) : name;
  if (std::find(known.begin(), known.end(), reader()) == known.end()) {
    std::fprintf(stderr, "piezobench fuzz: unknown reader '%s' (the executable must be named fuzz_READER)\n", reader().c_str());
    std::exit(2);
  }
  (void)argc;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    read(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const piezobench::Error&) {
    // exit 3 or 4: the expected end of a bad file
  } catch (const std::exception& e) {
    std::fprintf(stderr, "piezobench fuzz: not a piezobench::Error (the CLI's exit 1): %s\n", e.what());
    std::abort();
  }
  return 0;
}
