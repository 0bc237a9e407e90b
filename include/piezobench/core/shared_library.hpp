#pragma once
// A shared library opened on first use (dlopen) instead of at program start. The dependencies only
// some commands need (matio and HDF5 for MAT files, CHOLMOD for Craig-Bampton) are reached this
// way: a command that never calls them never maps them nor pays their relocations (with them the
// program started with 57 shared libraries, without them 11; docs/performance.md, "Start-up").
//
// Each such dependency has one stub file (src/io/matio_stubs.cpp, src/io/hdf5_stubs.cpp,
// src/fem/cholmod_stubs.cpp) that defines the C functions piezobench calls, with the signatures of
// the library's own header, each forwarding to the real function resolved here.
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

namespace piezobench::core {

// The library or one of its symbols is missing: a broken installation, not bad input.
class SharedLibraryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SharedLibrary {
 public:
  // soname: the name given to dlopen (the SONAME of the library the build was configured with,
  // e.g. "libmatio.so.11"); purpose: what piezobench needs it for, quoted in error messages.
  SharedLibrary(std::string soname, std::string purpose);
  // The library stays loaded until the process ends (C libraries keep global state and exit
  // handlers; unloading them buys nothing).
  ~SharedLibrary() = default;
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  // The address of `name`, loading the library first when needed (thread-safe).
  // SharedLibraryError naming the library, its purpose, the symbol and dlerror() when the library
  // cannot be loaded or does not define the symbol.
  [[nodiscard]] void* symbol(const char* name);
  // The same as a function pointer of type Function (e.g. decltype(&::Mat_Open)).
  template <typename Function>
  [[nodiscard]] Function function(const char* name) {
    return reinterpret_cast<Function>(symbol(name));
  }

  [[nodiscard]] bool loaded() const { return handle_.load(std::memory_order_acquire) != nullptr; }
  [[nodiscard]] const std::string& soname() const { return soname_; }

 private:
  void* handle();

  std::string soname_;
  std::string purpose_;
  std::mutex mutex_;
  std::atomic<void*> handle_{nullptr};
};

// Stub-file helpers. A stub file lists its library's functions as an X-macro
//   #define FUNCTIONS(X) X(return type, name, (parameters), (arguments)) ...
// with each signature as the library's header declares it, and defines `functions()`, which
// returns a struct of the real functions, resolved all at once on the first call (so that a missing
// symbol is reported at the first use, and a later call, e.g. from a destructor, cannot throw).
//   struct Functions { FUNCTIONS(PIEZOBENCH_STUB_MEMBER) };                   the table
//   FUNCTIONS(PIEZOBENCH_STUB_RESOLVE)            fills `Functions table` from `SharedLibrary& library()`
//   FUNCTIONS(PIEZOBENCH_STUB_DEFINE)             the C functions themselves (at global scope)
// The stubs are hidden: a program that links the real library too keeps the library's own
// functions for every other caller, and the library cannot bind its internal calls to a stub.
#define PIEZOBENCH_STUB_MEMBER(ret, name, params, args) decltype(&::name) name = nullptr;
#define PIEZOBENCH_STUB_RESOLVE(ret, name, params, args) table.name = library().function<decltype(&::name)>(#name);
#define PIEZOBENCH_STUB_DEFINE(ret, name, params, args) \
  extern "C" __attribute__((visibility("hidden"))) ret name params { return functions().name args; }

// Whether a shared object whose file name contains `name` is mapped into this process
// (dl_iterate_phdr). Tests use it to prove that work which does not need a library does not load it.
[[nodiscard]] bool is_shared_object_loaded(std::string_view name);

}  // namespace piezobench::core
