// libFuzzer targets of the station's readers (docs/fuzzing.md, issue 35): `fuzz_station_toml` reads
// its input as a station file (station::parse_station_file), `fuzz_answers_toml` as an answers file
// (station::parse_answers) against two fixed station files: docs/examples/station.toml (every
// phase from the bench) and fuzz/seeds/station_toml/values.toml (flatness from a file, capacitance
// typed in; scripts/fuzz/make_corpus.py), so that the answers of every kind of phase are reached. The executable's name selects the target.
//
// As for the readers (readers_fuzz.cpp): an input passes when the reader returns or throws a
// piezobench::Error (exit 3 or 4); any other exception (the CLI's exit 1) aborts, and a crash or a
// sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/station/answers.hpp"
#include "piezobench/station/station_file.hpp"

namespace {

namespace fs = std::filesystem;
namespace station = piezobench::station;

bool answers_target = false;
std::vector<station::StationFile> stations;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const std::string name = fs::path((*argv)[0]).filename().string();
  if (name != "fuzz_station_toml" && name != "fuzz_answers_toml") {
    std::fprintf(stderr, "piezobench fuzz: unknown target '%s' (fuzz_station_toml or fuzz_answers_toml)\n", name.c_str());
    std::exit(2);
  }
  answers_target = name == "fuzz_answers_toml";
  if (answers_target) {
    try {
      stations.push_back(station::read_station_file(PIEZOBENCH_STATION_EXAMPLE));
      stations.push_back(station::read_station_file(PIEZOBENCH_STATION_VALUES));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "piezobench fuzz: the answers target's station files do not read: %s\n", e.what());
      std::exit(2);
    }
  }
  (void)argc;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    if (!answers_target) {
      (void)station::parse_station_file(text, "station.toml");
    } else {
      for (const station::StationFile& s : stations) {
        try {
          (void)station::parse_answers(text, "answers.toml", s);
        } catch (const piezobench::Error&) {
          // refused for this station; the next one may read it further
        }
      }
    }
  } catch (const piezobench::Error&) {
    // exit 3 or 4: the expected end of a bad file
  } catch (const std::exception& e) {
    std::fprintf(stderr, "piezobench fuzz: not a piezobench::Error (the CLI's exit 1): %s\n", e.what());
    std::abort();
  }
  return 0;
}
