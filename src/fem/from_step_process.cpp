#include "from_step_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <system_error>
#include <thread>

extern char** environ;

namespace piezobench::fem::detail {
namespace {

bool is_executable_file(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

// RAII for posix_spawn_file_actions_t.
class FileActions {
 public:
  FileActions() { check(posix_spawn_file_actions_init(&fa_), "posix_spawn_file_actions_init"); }
  ~FileActions() { posix_spawn_file_actions_destroy(&fa_); }
  FileActions(const FileActions&) = delete;
  FileActions& operator=(const FileActions&) = delete;
  posix_spawn_file_actions_t* get() { return &fa_; }
  static void check(int rc, const char* what) {
    if (rc != 0) throw std::system_error(rc, std::generic_category(), what);
  }

 private:
  posix_spawn_file_actions_t fa_{};
};

// Reads what was appended to the log since `offset`; passes complete lines to `on_line`.
void pump(std::ifstream& in, std::string& pending, const std::function<void(std::string_view)>& on_line) {
  char buf[65536];
  in.clear();
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    pending.append(buf, static_cast<std::size_t>(in.gcount()));
    if (in.eof()) break;
  }
  std::size_t start = 0;
  for (std::size_t nl = pending.find('\n'); nl != std::string::npos; nl = pending.find('\n', start)) {
    std::string_view line(pending.data() + start, nl - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (on_line) on_line(line);
    start = nl + 1;
  }
  pending.erase(0, start);
}

}  // namespace

std::optional<std::filesystem::path> find_executable(const std::string& name_or_path) {
  if (name_or_path.empty()) return std::nullopt;
  if (name_or_path.find('/') != std::string::npos) {
    if (is_executable_file(name_or_path)) return std::filesystem::absolute(name_or_path);
    return std::nullopt;
  }
  const char* path_env = std::getenv("PATH");
  const std::string path = path_env != nullptr ? path_env : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t colon = std::min(path.find(':', start), path.size());
    const std::string dir = path.substr(start, colon - start);
    const std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / name_or_path;
    if (is_executable_file(candidate)) return std::filesystem::absolute(candidate);
    start = colon + 1;
  }
  return std::nullopt;
}

ProcessResult run_process(const std::filesystem::path& exe, const std::vector<std::string>& args,
                          const std::filesystem::path& cwd, const std::filesystem::path& log,
                          const std::function<void(std::string_view line)>& on_line, const ProcessLimits& limits) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> storage;
  storage.reserve(args.size() + 1);
  storage.push_back(exe.string());
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(storage.size() + 1);
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);

  FileActions fa;
  const std::string log_path = std::filesystem::absolute(log).string();
  FileActions::check(posix_spawn_file_actions_addopen(fa.get(), 0, "/dev/null", O_RDONLY, 0), "posix_spawn (stdin)");
  FileActions::check(posix_spawn_file_actions_addopen(fa.get(), 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644),
                     "posix_spawn (log file)");
  FileActions::check(posix_spawn_file_actions_adddup2(fa.get(), 1, 2), "posix_spawn (stderr)");
  const std::string dir = cwd.string();
  FileActions::check(posix_spawn_file_actions_addchdir_np(fa.get(), dir.c_str()), "posix_spawn (working directory)");

  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], fa.get(), nullptr, argv.data(), environ);
  if (rc != 0) throw std::system_error(rc, std::generic_category(), "cannot start " + exe.string());
  if (limits.address_space_bytes > 0.0) {
    struct rlimit lim {};
    lim.rlim_cur = lim.rlim_max = static_cast<rlim_t>(limits.address_space_bytes);
    (void)::prlimit(pid, RLIMIT_AS, &lim, nullptr);  // best effort: the process may already be gone
  }
  bool timed_out = false;

  std::ifstream in;
  std::string pending;
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) throw std::system_error(errno, std::generic_category(), "waitpid");
    if (limits.seconds > 0.0 && !timed_out &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limits.seconds) {
      ::kill(pid, SIGKILL);
      timed_out = true;
    }
    if (on_line) {
      if (!in.is_open()) in.open(log_path, std::ios::binary);
      if (in.is_open()) pump(in, pending, on_line);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  if (on_line) {
    if (!in.is_open()) in.open(log_path, std::ios::binary);
    if (in.is_open()) pump(in, pending, on_line);
    if (!pending.empty()) on_line(pending);
  }
  ProcessResult r;
  r.timed_out = timed_out;
  if (WIFEXITED(status)) {
    r.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.signaled = true;
    r.exit_code = 128 + WTERMSIG(status);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

std::optional<std::string> parse_version(std::string_view output) {
  std::size_t i = 0;
  while (i < output.size()) {
    while (i < output.size() && std::isspace(static_cast<unsigned char>(output[i])) != 0) ++i;
    const std::size_t start = i;
    while (i < output.size() && std::isspace(static_cast<unsigned char>(output[i])) == 0) ++i;
    std::string_view token = output.substr(start, i - start);
    while (!token.empty() && (token.back() == ',' || token.back() == ';' || token.back() == ')')) token.remove_suffix(1);
    if (token.size() >= 3 && std::isdigit(static_cast<unsigned char>(token.front())) != 0 &&
        token.find('.') != std::string_view::npos) {
      std::size_t end = 0;
      while (end < token.size() && (std::isdigit(static_cast<unsigned char>(token[end])) != 0 || token[end] == '.')) ++end;
      return std::string(token.substr(0, end));
    }
  }
  return std::nullopt;
}

int compare_versions(const std::string& a, const std::string& b) {
  // Digits only count (parse_version returns digits and dots); anything else is skipped.
  const auto number = [](const std::string& s, std::size_t& i) {
    long v = 0;
    for (; i < s.size() && s[i] != '.'; ++i) {
      if (std::isdigit(static_cast<unsigned char>(s[i])) != 0 && v < 100000000) v = 10 * v + (s[i] - '0');
    }
    return v;
  };
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    const long x = number(a, i);
    const long y = number(b, j);
    if (x != y) return x < y ? -1 : 1;
    if (i < a.size()) ++i;
    if (j < b.size()) ++j;
  }
  return 0;
}

std::string last_lines(std::string_view text, std::string_view needle, std::size_t count) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
    if (!line.empty() && (needle.empty() || line.find(needle) != std::string_view::npos)) lines.push_back(line);
    start = end + 1;
  }
  std::string out;
  for (std::size_t k = lines.size() > count ? lines.size() - count : 0; k < lines.size(); ++k) {
    if (!out.empty()) out += "\n";
    out += lines[k];
  }
  return out;
}

}  // namespace piezobench::fem::detail
