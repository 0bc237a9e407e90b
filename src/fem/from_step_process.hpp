#pragma once
// Private to fem/from_step.cpp: runs the external programs (gmsh, ccx) without a shell.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace piezobench::fem::detail {

// The executable for `name_or_path`: a name without '/' is looked up in $PATH (the first regular,
// executable file), a path is taken as is when it is an executable file. nullopt otherwise.
[[nodiscard]] std::optional<std::filesystem::path> find_executable(const std::string& name_or_path);

struct ProcessResult {
  int exit_code = -1;   // the program's exit status; 128 + N when killed by signal N
  bool signaled = false;
  bool timed_out = false;  // killed (SIGKILL) after `limits.seconds`
  double seconds = 0.0;
};

// Bounds of a run (0: none): wall time (the process is killed past it) and address space
// (RLIMIT_AS of the child, set with prlimit right after it starts: allocations past it fail).
struct ProcessLimits {
  double seconds = 0.0;
  double address_space_bytes = 0.0;
};

// Runs `exe` with `args` (argv[1..]; no shell, no word splitting) in `cwd`, stdin from /dev/null,
// stdout and stderr both into `log` (created or truncated). While it runs, each complete line the
// program writes is passed to `on_line` (may be empty), at most every 0.2 s. Throws
// std::system_error when the process cannot be started.
ProcessResult run_process(const std::filesystem::path& exe, const std::vector<std::string>& args,
                          const std::filesystem::path& cwd, const std::filesystem::path& log,
                          const std::function<void(std::string_view line)>& on_line = {},
                          const ProcessLimits& limits = {});

// "4.8.4" from `gmsh --version`, "2.20" from `ccx -v` ("This is Version 2.20"): the first
// token that starts with a digit and has a dot; nullopt when there is none.
[[nodiscard]] std::optional<std::string> parse_version(std::string_view output);
// Compares dotted versions numerically: -1, 0, 1.
[[nodiscard]] int compare_versions(const std::string& a, const std::string& b);

// The last `count` lines of `text` that contain `needle` (all lines when needle is empty).
[[nodiscard]] std::string last_lines(std::string_view text, std::string_view needle, std::size_t count);

}  // namespace piezobench::fem::detail
