#include "isolated.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>

#include "piezobench/core/error.hpp"

// Set by the sanitizer runtimes (libFuzzer registers its crash handler there): a weak reference,
// null in a build without them.
extern "C" __attribute__((weak)) void __sanitizer_set_death_callback(void (*callback)());
// The coverage counters of a libFuzzer build (-fsanitize=fuzzer: inline 8-bit counters), bounds
// the linker defines; absent (null) otherwise.
extern "C" __attribute__((weak)) std::uint8_t __start___sancov_cntrs[];
extern "C" __attribute__((weak)) std::uint8_t __stop___sancov_cntrs[];

namespace piezobench::io::detail {

namespace {

constexpr char kData = 'D', kError = 'E', kEnd = 'Z', kCoverage = 'C';
constexpr std::size_t kBuffered = 1 << 16;  // puts smaller than this are gathered into one frame

// The answer stopped before its end (the child died or exited) or broke the framing.
struct ShortAnswer {};
struct Malformed {
  std::string what;
};
struct ChildError {
  std::string message;
};

// The coverage counters of this process (empty without libFuzzer).
struct Counters {
  std::uint8_t* begin = nullptr;
  std::size_t size = 0;
};
Counters coverage_counters() {
  std::uint8_t* begin = __start___sancov_cntrs;
  std::uint8_t* end = __stop___sancov_cntrs;
  if (begin == nullptr || end <= begin) return {};
  return {begin, static_cast<std::size_t>(end - begin)};
}

bool write_all(int fd, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t w = ::write(fd, p, bytes);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    bytes -= static_cast<std::size_t>(w);
  }
  return true;
}

}  // namespace

// ---- child side ---------------------------------------------------------------------------------

void IsolatedOut::frame(char kind, const void* data, std::size_t bytes) {
  char header[9];
  header[0] = kind;
  const std::uint64_t n = bytes;
  std::memcpy(header + 1, &n, sizeof n);
  // A parent that stopped reading (it closed the pipe): nothing more to do than to end.
  if (!write_all(fd_, header, sizeof header) || !write_all(fd_, data, bytes)) ::_exit(3);
}

void IsolatedOut::flush() {
  if (buffer_.empty()) return;
  frame(kData, buffer_.data(), buffer_.size());
  buffer_.clear();
}

void IsolatedOut::put(const void* data, std::size_t bytes) {
  if (bytes >= kBuffered) {
    flush();
    frame(kData, data, bytes);
    return;
  }
  const auto* p = static_cast<const char*>(data);
  buffer_.insert(buffer_.end(), p, p + bytes);
  if (buffer_.size() >= kBuffered) flush();
}

void IsolatedOut::put_string(const std::string& s) {
  put_u64(s.size());
  put(s.data(), s.size());
}

// The child: default actions for the crash signals (a sanitizer's or libFuzzer's handler would
// report the parent's input as a crash of its own), the work, its answer, _exit.
void run_child(int fd, const std::function<void(IsolatedOut&)>& child) {
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGPIPE}) std::signal(sig, SIG_DFL);
  if (__sanitizer_set_death_callback != nullptr) __sanitizer_set_death_callback(nullptr);
  int code = 0;
  {
    IsolatedOut out(fd);
    std::string error;
    try {
      child(out);
      out.flush();
    } catch (const std::exception& e) {
      error = e.what();
    } catch (...) {
      error = "an unknown error";
    }
    // Under libFuzzer, the child's coverage goes to the parent, whose counters the fuzzer reads:
    // the code that runs here stays visible to it (the counters die with the child otherwise).
    if (const Counters c = coverage_counters(); c.size > 0) out.frame(kCoverage, c.begin, c.size);
    if (error.empty()) {
      out.frame(kEnd, nullptr, 0);
    } else {
      out.frame(kError, error.data(), error.size());
      code = 1;
    }
  }
  ::close(fd);
  ::_exit(code);
}

// ---- parent side --------------------------------------------------------------------------------

std::size_t IsolatedIn::raw(void* out, std::size_t bytes) {
  auto* dst = static_cast<char*>(out);
  std::size_t done = 0;
  while (done < bytes) {
    if (head_ < tail_) {
      const std::size_t take = std::min(bytes - done, tail_ - head_);
      std::memcpy(dst + done, buffer_.data() + head_, take);
      head_ += take;
      done += take;
      continue;
    }
    // Large reads go straight to the destination; small ones refill the buffer.
    const bool direct = bytes - done >= buffer_.size();
    const ssize_t r = direct ? ::read(fd_, dst + done, bytes - done) : ::read(fd_, buffer_.data(), buffer_.size());
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw ShortAnswer{};
    if (direct) {
      done += static_cast<std::size_t>(r);
    } else {
      head_ = 0;
      tail_ = static_cast<std::size_t>(r);
    }
  }
  return done;
}

bool IsolatedIn::next_frame() {
  if (ended_) return false;
  char header[9];
  raw(header, sizeof header);
  std::uint64_t n = 0;
  std::memcpy(&n, header + 1, sizeof n);
  switch (header[0]) {
    case kData:
      left_ = n;
      return true;
    case kCoverage: {
      const Counters mine = coverage_counters();
      if (mine.size == 0 || n != mine.size) malformed("coverage counters of another size");
      std::vector<std::uint8_t> counters(mine.size);
      raw(counters.data(), mine.size);
      for (std::size_t i = 0; i < mine.size; ++i) mine.begin[i] = std::max(mine.begin[i], counters[i]);
      return next_frame();
    }
    case kEnd:
      if (n != 0) malformed("an end frame with data");
      ended_ = true;
      return false;
    case kError: {
      if (n > (1u << 20)) malformed("an error message of " + std::to_string(n) + " bytes");
      std::string message(n, '\0');
      raw(message.data(), n);
      throw ChildError{message};
    }
    default:
      malformed("a frame of unknown kind " + std::to_string(static_cast<unsigned char>(header[0])));
  }
}

void IsolatedIn::get(void* out, std::size_t bytes) {
  auto* dst = static_cast<char*>(out);
  while (bytes > 0) {
    while (left_ == 0) {
      if (!next_frame()) malformed("an answer shorter than announced");
    }
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(bytes, left_));
    raw(dst, take);
    dst += take;
    bytes -= take;
    left_ -= take;
  }
}

std::uint64_t IsolatedIn::get_u64() {
  std::uint64_t v = 0;
  get(&v, sizeof v);
  return v;
}

std::string IsolatedIn::get_string(std::size_t max_bytes) {
  const std::uint64_t n = get_u64();
  if (n > max_bytes) malformed("a string of " + std::to_string(n) + " bytes");
  std::string s(n, '\0');
  get(s.data(), n);
  return s;
}

void IsolatedIn::malformed(const std::string& what) { throw Malformed{what}; }

bool IsolatedIn::at_end() {
  while (left_ == 0) {
    if (!next_frame()) return true;
  }
  return false;
}

void run_isolated(const IsolatedOptions& options, const std::function<void(IsolatedOut&)>& child,
                  const std::function<void(IsolatedIn&)>& parent) {
  const auto fail = [&](const std::string& found) { return InputError(options.source, options.field, options.expected, found); };
  map_hdf5_library();  // before the pipe: a missing library leaves nothing open
  int fds[2];
  if (::pipe(fds) != 0) {
    const int err = errno;
    throw fail("no pipe for the isolated process (" + std::string(std::strerror(err)) + ")");
  }
  // 1 MiB instead of 64 KiB (when the system allows it): a 48 MB channel crosses in 50 wake-ups of
  // the parent rather than 750 (on a loaded machine each can wait for a time slice).
  (void)::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);
  std::fflush(nullptr);  // buffered output must not be written twice
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw fail("no isolated process (fork failed: " + std::string(std::strerror(err)) + ")");
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], child);  // does not return
  }
  ::close(fds[1]);
  // Reaps the child; `kill`: first end it (the parent stopped reading, it may be blocked writing).
  const auto reap = [&](bool kill) {
    ::close(fds[0]);
    if (kill) (void)::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  };
  // "(signal 11)", "(exit status 1)", else `otherwise`.
  const auto died = [&](int status, const std::string& otherwise) {
    if (WIFSIGNALED(status)) return fail(options.failure + " (signal " + std::to_string(WTERMSIG(status)) + ")");
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
      return fail(options.failure + " (exit status " + std::to_string(WEXITSTATUS(status)) + ")");
    }
    return fail(options.failure + " (" + otherwise + ")");
  };
  IsolatedIn in(fds[0]);
  try {
    parent(in);
    if (!in.at_end()) in.malformed("more data than the reader took");
  } catch (const ShortAnswer&) {
    throw died(reap(false), "its answer ended early");
  } catch (const Malformed& m) {
    (void)reap(true);
    throw fail(options.failure + " (a malformed answer: " + m.what + ")");
  } catch (const ChildError& e) {
    (void)reap(false);
    // The child's InputError names the file already.
    throw InputError(e.message);
  } catch (...) {
    (void)reap(true);
    throw;
  }
  const int status = reap(false);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw died(status, "an unexpected end");
}

}  // namespace piezobench::io::detail
