#pragma once
// The one shared helper for numeric tests.
//
// Tolerance rule, used everywhere: a value `actual` matches `expected` when
//     |actual - expected| <= abs_tol + rel_tol * |expected|
// (complex values: the modulus of the difference). Vectors and matrices are compared entry by
// entry with that rule, so a relative tolerance stays relative for small entries too unless an
// abs_tol is given. Every failure prints the index, expected, actual and both tolerances.
//
// Named tolerances below say why they are what they are; use them instead of bare literals.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>
#include <unistd.h>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

// Tests that need the external data (the Ansys APA95ML export in ../shared/data next to the
// repository; CMake option PIEZOBENCH_SHARED_DATA_DIR) call this first: without the data the test
// is skipped with a message naming the missing path. `relative` is inside that folder.
#define PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA(relative)                                                     \
  do {                                                                                                   \
    const std::filesystem::path pb_needed_ = std::filesystem::path(PIEZOBENCH_SHARED_DATA_DIR) / (relative); \
    if (!std::filesystem::exists(pb_needed_)) {                                                          \
      GTEST_SKIP() << "external data not found: " << pb_needed_.string()                                 \
                   << " (the Ansys APA95ML export; set the CMake option PIEZOBENCH_SHARED_DATA_DIR)";    \
    }                                                                                                    \
  } while (0)

namespace piezobench::test {

// A sanitizer build (ASan, MSan, TSan; GCC says __SANITIZE_ADDRESS__, clang __has_feature): it
// replaces malloc and reserves terabytes of address space.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

// Double round-off accumulated through O(n) operations on well-conditioned data.
inline constexpr double kRoundoff = 1e-12;
// What a backward-stable algorithm achieves on the lightly damped (0.1 %) systems of the tests:
// cond ~ 1/(2 zeta) ~ 500 times the round-off of the entries.
inline constexpr double kLightlyDamped = 1e-10;
// Fixtures are written by the reference tools with 17 significant digits; their own algorithms
// (Octave's control package, scipy) differ from ours in round-off only.
inline constexpr double kReferenceTool = 1e-9;

struct Tolerance {
  double rel = 0.0;
  double abs = 0.0;
};
// Bit-for-bit equality (two readers of one file, a round trip through an exact format).
inline constexpr Tolerance kExact{0.0, 0.0};

inline bool within(double actual, double expected, Tolerance tol) {
  if (std::isnan(expected)) return std::isnan(actual);
  if (std::isinf(expected)) return actual == expected;
  return std::abs(actual - expected) <= tol.abs + tol.rel * std::abs(expected);
}

inline bool within(std::complex<double> actual, std::complex<double> expected, Tolerance tol) {
  return std::abs(actual - expected) <= tol.abs + tol.rel * std::abs(expected);
}

template <typename T>
::testing::AssertionResult near(T actual, T expected, Tolerance tol) {
  if (within(actual, expected, tol)) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(17);
  os << "expected " << expected << ", actual " << actual << " (rel_tol " << tol.rel << ", abs_tol "
     << tol.abs << ")";
  return ::testing::AssertionFailure() << os.str();
}

inline ::testing::AssertionResult near(double actual, double expected, double rel_tol) {
  return near<double>(actual, expected, Tolerance{rel_tol, 0.0});
}

template <typename DerivedA, typename DerivedB>
::testing::AssertionResult all_near(const Eigen::DenseBase<DerivedA>& actual,
                                    const Eigen::DenseBase<DerivedB>& expected, Tolerance tol) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols()) {
    return ::testing::AssertionFailure() << "shape: expected " << expected.rows() << "x" << expected.cols()
                                         << ", actual " << actual.rows() << "x" << actual.cols();
  }
  for (Eigen::Index j = 0; j < expected.cols(); ++j) {
    for (Eigen::Index i = 0; i < expected.rows(); ++i) {
      if (!within(actual(i, j), expected(i, j), tol)) {
        std::ostringstream os;
        os.precision(17);
        os << "entry (" << i << ", " << j << "): expected " << expected(i, j) << ", actual " << actual(i, j)
           << " (rel_tol " << tol.rel << ", abs_tol " << tol.abs << ")";
        return ::testing::AssertionFailure() << os.str();
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Path of a committed fixture under tests/fixtures/.
inline std::filesystem::path fixture_path(const std::string& relative) {
  return std::filesystem::path(PIEZOBENCH_FIXTURE_DIR) / relative;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open fixture " + path.string());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs f, which must throw InputError; returns its message ("" and a test failure otherwise).
// With a non-empty `field`, the error must also name that field.
template <typename F>
std::string input_error(F&& f, const std::string& field = "") {
  try {
    f();
  } catch (const InputError& e) {
    if (!field.empty()) {
      EXPECT_EQ(e.field(), field) << e.what();
    }
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError" << (field.empty() ? std::string() : " for " + field);
  return "";
}

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Expects an InputError whose message contains every one of `needles`.
template <typename F>
void expect_input_error(F&& f, const std::vector<std::string>& needles) {
  const std::string what = input_error(std::forward<F>(f));
  for (const auto& needle : needles) EXPECT_TRUE(contains(what, needle)) << "'" << needle << "' not in: " << what;
}

// n angular frequencies [rad/s], log-spaced from f_lo to f_hi [Hz] (both included).
inline Eigen::VectorXd log_grid(double f_lo, double f_hi, Eigen::Index n) {
  Eigen::VectorXd w(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    w(k) = kTwoPi * f_lo * std::pow(f_hi / f_lo, static_cast<double>(k) / static_cast<double>(n - 1));
  }
  return w;
}

// n samples of zero-mean Gaussian noise of standard deviation rms, from a fixed seed.
inline Eigen::VectorXd gaussian_noise(Eigen::Index n, double rms, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> d(0.0, rms);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = d(rng);
  return v;
}

// Writes `text` to `path` (test input files).
inline void write_text(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

// A fresh empty directory under the system temp dir, removed at destruction.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "piezobench-test-";
    if (info != nullptr) name += std::string(info->test_suite_name()) + "-" + info->name() + "-";
    static int counter = 0;  // several TempDirs may live in one test
    path_ = std::filesystem::temp_directory_path() /
            (name + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace piezobench::test
