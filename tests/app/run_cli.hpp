#pragma once
// Runs the piezobench command as a subprocess, as a user or a script would, for the end-to-end
// tests of tests/app/.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
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

// Writes `text` to dir/name and returns the path.
inline std::string write_text_file(const TempDir& dir, const std::string& name, const std::string& text) {
  const auto path = dir.path() / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace piezobench::test
