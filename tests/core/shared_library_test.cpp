#include "piezobench/core/shared_library.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "test_util.hpp"

namespace piezobench::core {
namespace {

using test::contains;

std::string error_of(SharedLibrary& library, const char* symbol) {
  try {
    (void)library.symbol(symbol);
  } catch (const SharedLibraryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SharedLibraryError for " << symbol;
  return "";
}

TEST(SharedLibrary, LoadsOnFirstUseAndResolvesFunctions) {
  SharedLibrary libm("libm.so.6", "a test");
  EXPECT_FALSE(libm.loaded());
  const auto cosine = libm.function<double (*)(double)>("cos");
  EXPECT_TRUE(libm.loaded());
  EXPECT_EQ(cosine(0.0), 1.0);
  EXPECT_EQ(cosine(0.5), std::cos(0.5));
  EXPECT_EQ(libm.soname(), "libm.so.6");
}

TEST(SharedLibrary, MissingLibraryOrSymbolNamesLibraryPurposeAndSymbol) {
  SharedLibrary missing("libpiezobench-no-such-library.so.7", "testing a missing library");
  const std::string m = error_of(missing, "anything");
  EXPECT_TRUE(contains(m, "cannot load libpiezobench-no-such-library.so.7")) << m;
  EXPECT_TRUE(contains(m, "testing a missing library")) << m;
  EXPECT_TRUE(contains(m, "No such file")) << m;  // dlerror's reason
  EXPECT_FALSE(missing.loaded());
  // Still missing at the next call (no half-loaded state).
  EXPECT_FALSE(error_of(missing, "anything").empty());

  SharedLibrary libm("libm.so.6", "a test");
  const std::string s = error_of(libm, "piezobench_no_such_symbol");
  EXPECT_TRUE(contains(s, "symbol piezobench_no_such_symbol not found in libm.so.6")) << s;
  EXPECT_TRUE(contains(s, "a test")) << s;
  EXPECT_TRUE(libm.loaded());
}

TEST(SharedLibrary, ConcurrentFirstUsesGetTheSameAddress) {
  SharedLibrary libm("libm.so.6", "a test");
  std::vector<void*> seen(8, nullptr);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < seen.size(); ++i) threads.emplace_back([&, i] { seen[i] = libm.symbol("sin"); });
  for (std::thread& t : threads) t.join();
  for (void* p : seen) EXPECT_EQ(p, seen[0]);
  EXPECT_NE(seen[0], nullptr);
}

TEST(SharedLibrary, IsSharedObjectLoadedLooksAtFileNames) {
  EXPECT_TRUE(is_shared_object_loaded("libc.so"));
  EXPECT_TRUE(is_shared_object_loaded("libstdc++"));
  EXPECT_FALSE(is_shared_object_loaded("libpiezobench-no-such-library"));
}

}  // namespace
}  // namespace piezobench::core
