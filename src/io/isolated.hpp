#pragma once
// Running work on hostile files in a forked child (private to io). HDF5 (Debian's 1.10) overreads
// heap buffers, leaks and keeps global state on corrupt files; it cannot be fixed here, so every
// call into it (reading and writing MAT v7.3 files) runs in a child process whose answer comes
// back through a pipe. A child that dies by a signal, exits non-zero or sends a short or malformed
// answer becomes an InputError naming the file: the fault stays in the child.
//
// The answer is a stream of frames (kind byte, 64-bit length, bytes) that the parent reads while
// the child writes, so an answer of any size (a 100 MB record) never deadlocks on the pipe's
// buffer; a large put() goes to the pipe without an intermediate copy and a large get() lands in
// the caller's buffer directly.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace piezobench::io::detail {

// The child's end: what it sends to the parent.
class IsolatedOut {
 public:
  explicit IsolatedOut(int fd) : fd_(fd) {}
  IsolatedOut(const IsolatedOut&) = delete;
  IsolatedOut& operator=(const IsolatedOut&) = delete;
  void put(const void* data, std::size_t bytes);
  void put_u64(std::uint64_t v) { put(&v, sizeof v); }
  void put_string(const std::string& s);
  // Sends what is buffered (called by run_isolated before the end frame).
  void flush();

 private:
  friend void run_child(int, const std::function<void(IsolatedOut&)>&);
  void frame(char kind, const void* data, std::size_t bytes);
  int fd_;
  std::vector<char> buffer_;
};

// The parent's end: reads exactly what the child put, in the same order. A short or malformed
// answer, or the child's own error, throws (run_isolated turns it into the InputError).
class IsolatedIn {
 public:
  explicit IsolatedIn(int fd) : fd_(fd) {}
  IsolatedIn(const IsolatedIn&) = delete;
  IsolatedIn& operator=(const IsolatedIn&) = delete;
  void get(void* out, std::size_t bytes);
  [[nodiscard]] std::uint64_t get_u64();
  // A length-prefixed string of at most max_bytes (longer: a malformed answer).
  [[nodiscard]] std::string get_string(std::size_t max_bytes = 1 << 20);
  // Throws a malformed-answer error (the parent's own checks of what it received).
  [[noreturn]] static void malformed(const std::string& what);
  // True when the child has ended its answer (its end frame read); false if data remain.
  [[nodiscard]] bool at_end();

 private:
  bool next_frame();  // false at the end frame
  std::size_t raw(void* out, std::size_t bytes);  // from the pipe (through the small buffer)
  int fd_;
  std::uint64_t left_ = 0;  // bytes left in the current data frame
  bool ended_ = false;
  std::vector<char> buffer_ = std::vector<char>(1 << 16);
  std::size_t head_ = 0, tail_ = 0;
};

// What a failed child becomes: InputError(source, field, expected, failure + " (signal 11)").
struct IsolatedOptions {
  std::string source;                                   // the file (every message names it)
  std::string field = "file";
  std::string expected = "a file the HDF5 library can read";
  std::string failure = "the HDF5 library failed on it";
};

// Forks; the child runs `child` (sending its answer through the IsolatedOut) and ends with
// _exit (no exit handlers, no leak check: what HDF5 leaves behind dies with it). An exception in
// the child is sent as its message and rethrown in the parent as an InputError with that text.
// The parent runs `parent` on the answer as it arrives, then requires the answer's end and the
// child's exit status 0. If `parent` throws its own exception, the child is killed and that
// exception propagates. The child's crash signals get their default action (no sanitizer or
// fuzzer handler runs in it), so a fault there is a plain signal to report. In a libFuzzer build
// the child's coverage counters are merged into the parent's, so the fuzzer still sees the code
// that ran in the child.
void run_isolated(const IsolatedOptions& options, const std::function<void(IsolatedOut&)>& child,
                  const std::function<void(IsolatedIn&)>& parent);

// Maps the HDF5 library into this process without initializing it (src/io/hdf5_stubs.cpp; HDF5 is
// loaded on first use), so that the children inherit the mapping instead of each loading HDF5 and
// its 40 dependencies again. run_isolated calls it before it forks.
void map_hdf5_library();

}  // namespace piezobench::io::detail
