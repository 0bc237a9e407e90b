#pragma once
// Runs the piezobench command as a subprocess, as a user or a script would, for the end-to-end
// tests of tests/app/.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.hpp"

namespace piezobench::test {

struct CliRun {
  int exit_code = -1;  // -1 when the process did not exit normally (a crash)
  std::string out;     // stdout
  std::string err;     // stderr
};

// `args` is appended to the binary's path as is (shell words).
inline CliRun run_cli(const std::string& args) {
  TempDir dir;
  const auto out = dir.path() / "stdout";
  const auto err = dir.path() / "stderr";
  const std::string command = std::string(PIEZOBENCH_BINARY) + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

// True when a failed run printed no result: stdout empty, or (with --json) only the JSON error
// document {"error": {...}} of docs/cli.md.
inline bool no_result(const CliRun& r) {
  if (r.out.empty()) return true;
  const auto doc = nlohmann::json::parse(r.out, nullptr, false);
  return doc.is_object() && doc.size() == 1 && doc.contains("error") && doc["error"]["exit_code"] == r.exit_code;
}

// Writes `text` to dir/name and returns the path.
inline std::string write_text_file(const TempDir& dir, const std::string& name, const std::string& text) {
  const auto path = dir.path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace piezobench::test
