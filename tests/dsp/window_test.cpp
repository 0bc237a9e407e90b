#include "piezobench/dsp/window.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::dsp {
namespace {

using Eigen::Index;
using Eigen::VectorXd;
using test::all_near;
using test::Tolerance;

// scipy evaluates the same cosine sums; libm's last bits differ, and 0.5 - 0.5 cos(x) near the ends
// turns that into an absolute (not relative) round-off of the O(1) window.
constexpr Tolerance kSameFormula{1e-14, 1e-15};

const WindowType kAll[] = {WindowType::kRectangular,      WindowType::kHanning,         WindowType::kHannPeriodic,    WindowType::kHannSymmetric,
                           WindowType::kHammingPeriodic,  WindowType::kHammingSymmetric, WindowType::kFlatTopPeriodic,
                           WindowType::kFlatTopSymmetric};

TEST(Window, NamesRoundTripAndOtherProgramsNamesAreAccepted) {
  for (WindowType t : kAll) EXPECT_EQ(window_type_from_string(to_string(t)), t);
  EXPECT_EQ(to_string(WindowType::kHannPeriodic), "hann-periodic");
  EXPECT_EQ(to_string(WindowType::kHannSymmetric), "hann-symmetric");
  // scipy's names (periodic, its Welch default) and MATLAB's, in any case: one parser for the
  // command line and the campaign file.
  EXPECT_EQ(window_type_from_string("hann"), WindowType::kHannPeriodic);
  EXPECT_EQ(window_type_from_string("Hann"), WindowType::kHannPeriodic);
  EXPECT_EQ(window_type_from_string("hanning"), WindowType::kHanning);
  EXPECT_EQ(window_type_from_string("hamming"), WindowType::kHammingPeriodic);
  EXPECT_EQ(window_type_from_string("flattop"), WindowType::kFlatTopPeriodic);
  EXPECT_EQ(window_type_from_string("flattopwin"), WindowType::kFlatTopSymmetric);
  EXPECT_EQ(window_type_from_string("boxcar"), WindowType::kRectangular);
  EXPECT_EQ(window_type_from_string("RECTWIN"), WindowType::kRectangular);
  try {
    (void)window_type_from_string("triangle");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "window");
    EXPECT_NE(std::string(e.what()).find("hann-periodic"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("hanning"), std::string::npos);
  }
}

TEST(Window, HanningIsMatlabsHanning) {
  // MATLAB hanning(5) = hann(7)(2:6); scipy.signal.windows.hann(7, sym=True)[1:-1].
  VectorXd e(5);
  e << 0.24999999999999994, 0.75, 1.0, 0.7500000000000002, 0.25000000000000033;
  EXPECT_TRUE(all_near(make_window(WindowType::kHanning, 5), e, kSameFormula));
}

TEST(Window, EqualsScipyGetWindow) {
  // Every window type appears in one case of the Welch fixture, with scipy's samples stored.
  const auto signals = nlohmann::json::parse(test::read_text(test::fixture_path("dsp/welch_signals.json")));
  const auto scipy = nlohmann::json::parse(test::read_text(test::fixture_path("dsp/welch_scipy.json")));
  int seen = 0;
  for (std::size_t i = 0; i < scipy.at("cases").size(); ++i) {
    const auto& c = signals.at("cases")[i];
    const auto samples = scipy.at("cases")[i].at("window_samples").get<std::vector<double>>();
    const WindowType type = window_type_from_string(c.at("window").get<std::string>());
    const VectorXd w = make_window(type, c.at("nfft").get<Index>());
    EXPECT_TRUE(all_near(w, Eigen::Map<const VectorXd>(samples.data(), static_cast<Index>(samples.size())), kSameFormula))
        << to_string(type);
    ++seen;
  }
  EXPECT_EQ(seen, 7);
}

TEST(Window, KnownSamples) {
  VectorXd e(4);
  e << 0.0, 0.5, 1.0, 0.5;
  EXPECT_TRUE(all_near(make_window(WindowType::kHannPeriodic, 4), e, Tolerance{0, 1e-16}));
  VectorXd s(5);
  s << 0.0, 0.5, 1.0, 0.5, 0.0;  // Octave 7 hann(5) and hanning(5)
  EXPECT_TRUE(all_near(make_window(WindowType::kHannSymmetric, 5), s, Tolerance{0, 1e-16}));
  VectorXd h(3);
  h << 0.08, 1.0, 0.08;
  EXPECT_TRUE(all_near(make_window(WindowType::kHammingSymmetric, 3), h, Tolerance{0, 1e-15}));
  // Flat-top: sum of the coefficients at the centre, 1.000000003 (scipy's rounding of them).
  EXPECT_NEAR(make_window(WindowType::kFlatTopSymmetric, 9)(4), 1.000000003, 1e-15);
  EXPECT_NEAR(make_window(WindowType::kFlatTopSymmetric, 9)(0), -0.000421051, 1e-15);
}

TEST(Window, SymmetryPeriodicityAndLengthOne) {
  for (WindowType t : kAll) {
    for (Index n : {1, 2, 7, 8, 1001}) {
      const VectorXd w = make_window(t, n);
      ASSERT_EQ(w.size(), n);
      if (n == 1) {
        EXPECT_EQ(w(0), 1.0);
        continue;
      }
      const std::string name = to_string(t);
      if (name.find("symmetric") != std::string::npos || t == WindowType::kRectangular || t == WindowType::kHanning) {
        EXPECT_TRUE(all_near(w, w.reverse().eval(), Tolerance{0, 1e-15})) << name << " " << n;
      } else {
        // Periodic: w[k] = w[n - k] for k = 1..n-1 (one period without its end point).
        EXPECT_TRUE(all_near(w.tail(n - 1), w.tail(n - 1).reverse().eval(), Tolerance{0, 1e-15})) << name << " " << n;
      }
    }
  }
  EXPECT_THROW((void)make_window(WindowType::kHannPeriodic, 0), InputError);
}

}  // namespace
}  // namespace piezobench::dsp
