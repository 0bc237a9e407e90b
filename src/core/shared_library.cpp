#include "piezobench/core/shared_library.hpp"

#include <dlfcn.h>
#include <link.h>

#include <utility>

namespace piezobench::core {

SharedLibrary::SharedLibrary(std::string soname, std::string purpose)
    : soname_(std::move(soname)), purpose_(std::move(purpose)) {}

void* SharedLibrary::handle() {
  if (void* h = handle_.load(std::memory_order_acquire)) return h;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (void* h = handle_.load(std::memory_order_relaxed)) return h;
  // RTLD_NOW: a library whose own dependencies are missing fails here, with dlerror's message,
  // not later inside a call. RTLD_LOCAL: its symbols do not interpose on anything else.
  void* h = ::dlopen(soname_.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (h == nullptr) {
    const char* why = ::dlerror();
    throw SharedLibraryError("cannot load " + soname_ + ", needed for " + purpose_ + ": " +
                             (why != nullptr ? why : "dlopen failed"));
  }
  handle_.store(h, std::memory_order_release);
  return h;
}

void* SharedLibrary::symbol(const char* name) {
  void* h = handle();
  ::dlerror();  // clear a stale message
  void* address = ::dlsym(h, name);
  if (address == nullptr) {
    const char* why = ::dlerror();
    throw SharedLibraryError("symbol " + std::string(name) + " not found in " + soname_ + ", needed for " + purpose_ +
                             ": " + (why != nullptr ? why : "its address is null"));
  }
  return address;
}

bool is_shared_object_loaded(std::string_view name) {
  struct Search {
    std::string_view name;
    bool found = false;
  } search{name};
  ::dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* data) -> int {
        auto* s = static_cast<Search*>(data);
        const std::string_view path = info->dlpi_name != nullptr ? info->dlpi_name : "";
        const size_t slash = path.rfind('/');
        const std::string_view file = slash == std::string_view::npos ? path : path.substr(slash + 1);
        s->found = file.find(s->name) != std::string_view::npos;
        return s->found ? 1 : 0;
      },
      &search);
  return search.found;
}

}  // namespace piezobench::core
