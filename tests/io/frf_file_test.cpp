// FRF files: CSV and .mat round trips to the last digit, UFF dataset 58 round trips to the printed
// precision, a binary 58b file built byte by byte from the format description, malformed files.
#include "piezobench/io/frf_file.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "mat_file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

namespace fs = std::filesystem;
using test::all_near;
using test::TempDir;
using test::Tolerance;
using test::kExact;
using Eigen::Index;

// UFF58 prints ordinates as E20.12 (13 significant digits): each part within 5e-13 relative.
constexpr Tolerance kUffOrdinate{1e-12, 0.0};
// ... and abscissae as E13.5 (6 significant digits), also min and increment of even grids.
constexpr double kUffAbscissaRel = 1e-5;

// Two outputs with a lightly damped mode (complex values over several decades) and coherence.
dsp::Frf sample_frf(const Eigen::VectorXd& freq) {
  dsp::Frf frf;
  frf.freq_Hz = freq;
  frf.input = "u";
  frf.outputs = {"de", "Vs"};
  const Index n = freq.size();
  Eigen::VectorXcd h1(n), h2(n);
  Eigen::VectorXd c1(n), c2(n);
  for (Index k = 0; k < n; ++k) {
    const std::complex<double> s(0.0, 2.0 * M_PI * freq(k));
    const double w0 = 2.0 * M_PI * 95.4;
    h1(k) = -16.8e-6 * w0 * w0 / (s * s + 2.0 * 0.004 * w0 * s + w0 * w0);
    h2(k) = 0.5 * s / (s + 2.0 * M_PI * 5.0) + std::complex<double>(1e-3 / 3.0, -1.0 / 7.0);
    c1(k) = 0.5 + 0.5 * std::cos(0.01 * static_cast<double>(k)) / 3.0;
    c2(k) = 1.0 - 1e-9 * static_cast<double>(k);
  }
  frf.H = {h1, h2};
  frf.coherence = {c1, c2};
  frf.provenance.source = "bench/unit3.mat";
  frf.provenance.estimator = "H1";
  frf.provenance.window = "hann-periodic";
  frf.provenance.nfft = 10000;
  frf.provenance.overlap = 0.5;
  frf.provenance.detrend = "none";
  frf.provenance.averages = 119;
  frf.provenance.sample_rate = 10000.0;
  return frf;
}

Eigen::VectorXd even_grid(Index n = 201) { return Eigen::VectorXd::LinSpaced(n, 0.0, 1000.0); }  // 5 Hz steps
Eigen::VectorXd log_grid(Index n = 150) {
  Eigen::VectorXd f(n);
  for (Index k = 0; k < n; ++k) f(k) = std::pow(10.0, 0.3 + 3.0 * static_cast<double>(k) / static_cast<double>(n - 1));
  return f;
}

using test::contains;
using test::input_error;

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

void expect_exact(const dsp::Frf& got, const dsp::Frf& want, bool input_kept) {
  EXPECT_EQ(got.outputs, want.outputs);
  if (input_kept) {
    EXPECT_EQ(got.input, want.input);
  }
  EXPECT_TRUE(all_near(got.freq_Hz, want.freq_Hz, kExact));
  ASSERT_EQ(got.H.size(), want.H.size());
  ASSERT_EQ(got.coherence.size(), want.coherence.size());
  for (size_t i = 0; i < want.H.size(); ++i) {
    EXPECT_TRUE(all_near(got.H[i], want.H[i], kExact)) << want.outputs[i];
    if (!want.coherence.empty()) {
      EXPECT_TRUE(all_near(got.coherence[i], want.coherence[i], kExact)) << want.outputs[i];
    }
  }
}

// ---- CSV and MAT: exact -----------------------------------------------------------------------

TEST(FrfCsv, RoundTripIsExactWithAndWithoutCoherence) {
  TempDir dir;
  dsp::Frf frf = sample_frf(log_grid());
  const fs::path file = dir.path() / "frf.csv";
  write_frf(frf, file);
  const std::string text = test::read_text(file);
  EXPECT_EQ(text.substr(0, text.find('\n')), "freq_Hz,re_de,im_de,coh_de,re_Vs,im_Vs,coh_Vs");
  dsp::Frf back = read_frf(file);
  expect_exact(back, frf, /*input_kept=*/false);
  EXPECT_EQ(back.provenance.source, file.string());

  frf.coherence.clear();
  write_frf_csv(frf, file);
  back = read_frf_csv(file);
  EXPECT_TRUE(back.coherence.empty());
  expect_exact(back, frf, false);
}

TEST(FrfCsv, ColumnsInAnyOrderCommentsAndNoCoherence) {
  TempDir dir;
  const fs::path file = dir.path() / "hand.csv";
  write_bytes(file, "# exported by hand\nfreq_Hz, im_a ,re_a\n1,2,3\n\n2.5,-4e-3,+5\n");
  const dsp::Frf frf = read_frf_csv(file);
  ASSERT_EQ(frf.outputs, std::vector<std::string>{"a"});
  EXPECT_EQ(frf.H[0](0), std::complex<double>(3, 2));
  EXPECT_EQ(frf.H[0](1), std::complex<double>(5, -4e-3));
  EXPECT_EQ(frf.freq_Hz(1), 2.5);
}

TEST(FrfCsv, MalformedFilesNameFileAndColumn) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "header"},
      {"f,re_a,im_a\n1,2,3\n", "freq_Hz"},
      {"freq_Hz,re_a\n1,2\n", "im_a"},
      {"freq_Hz,re_a,im_a,mag_a\n1,2,3,4\n", "mag_a"},
      {"freq_Hz,re_a,im_a,re_a\n1,2,3,4\n", "twice"},
      {"freq_Hz,re_a,im_a\n", "data row"},
      {"freq_Hz,re_a,im_a\n1,2\n", "line 2"},
      {"freq_Hz,re_a,im_a\n1,2,x\n", "im_a (line 2)"},
      {"freq_Hz,re_a,im_a\n1,2,nan\n", "im_a (line 2)"},
      {"freq_Hz,re_a,im_a\n2,2,3\n1,2,3\n", "increasing"},
      {"freq_Hz,re_a,im_a,coh_a,re_b,im_b\n1,2,3,1,2,3\n", "coh_NAME columns for every output"},
      // Issue 21: coherence outside [0, 1] and negative frequencies were accepted.
      {"freq_Hz,re_a,im_a,coh_a\n1,2,3,0.5\n2,2,3,1.7\n", "a coherence"},
      {"freq_Hz,re_a,im_a,coh_a\n1,2,3,-0.2\n", "values in [0, 1]"},
      {"freq_Hz,re_a,im_a\n-5,2,3\n1,2,3\n", "frequencies >= 0 Hz"},
  };
  for (const auto& [text, expected] : cases) {
    const fs::path file = dir.path() / "bad.csv";
    write_bytes(file, text);
    const std::string msg = input_error([&] { (void)read_frf(file); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, expected)) << text::quote(text) << ": " << msg;
  }
}

TEST(FrfMat, V5AndV73RoundTripsAreExactWithProvenance) {
  TempDir dir;
  const dsp::Frf frf = sample_frf(log_grid());
  for (const MatVersion version : {MatVersion::kV5, MatVersion::kV73}) {
    SCOPED_TRACE(to_string(version));
    const fs::path file = dir.path() / ("frf_" + to_string(version) + ".mat");
    FrfWriteOptions options;
    options.mat_version = version;
    write_frf(frf, file, options);
    const dsp::Frf back = read_frf(file);
    expect_exact(back, frf, /*input_kept=*/true);
    EXPECT_EQ(back.provenance.source, "bench/unit3.mat");
    EXPECT_EQ(back.provenance.estimator, "H1");
    EXPECT_EQ(back.provenance.window, "hann-periodic");
    EXPECT_EQ(back.provenance.nfft, 10000);
    EXPECT_EQ(back.provenance.overlap, 0.5);
    EXPECT_EQ(back.provenance.averages, 119);
    EXPECT_EQ(back.provenance.sample_rate, 10000.0);
  }
}

// std_H (dsp/frf_variance.hpp) goes through CSV and .mat exactly and is recomputed from the
// coherence and ID line 5 for UFF 58, which has no function type for it.
TEST(FrfFiles, StandardDeviationRoundTrips) {
  TempDir dir;
  dsp::Frf frf = sample_frf(even_grid());
  frf.provenance.effective_averages = dsp::effective_averages(dsp::WindowType::kHannPeriodic, 10000, 5000, 119);
  for (size_t i = 0; i < frf.H.size(); ++i) {
    frf.std_H.push_back(dsp::frf_standard_deviation(frf.H[i], frf.coherence[i], frf.provenance.effective_averages));
  }
  write_frf(frf, dir.path() / "frf.csv");
  const std::string text = test::read_text(dir.path() / "frf.csv");
  EXPECT_EQ(text.substr(0, text.find('\n')), "freq_Hz,re_de,im_de,coh_de,std_de,re_Vs,im_Vs,coh_Vs,std_Vs");
  write_frf(frf, dir.path() / "frf.mat");
  write_frf(frf, dir.path() / "frf.uff");
  for (const char* name : {"frf.csv", "frf.mat", "frf.uff"}) {
    SCOPED_TRACE(name);
    const dsp::Frf back = read_frf(dir.path() / name);
    ASSERT_EQ(back.std_H.size(), 2u);
    // UFF: H to 13 digits and the coherence to 13 digits, so std_H to ~1e-11 relative.
    const Tolerance tol = std::string(name) == "frf.uff" ? Tolerance{1e-10, 0.0} : kExact;
    for (size_t i = 0; i < 2; ++i) EXPECT_TRUE(all_near(back.std_H[i], frf.std_H[i], tol)) << frf.outputs[i];
    // CSV keeps no provenance; .mat stores n_d, UFF recomputes it from ID line 5.
    if (std::string(name) != "frf.csv") {
      EXPECT_NEAR(back.provenance.effective_averages, frf.provenance.effective_averages, 1e-9);
    }
  }
  // A CSV with std_ for one output of two is refused.
  write_bytes(dir.path() / "half.csv", "freq_Hz,re_a,im_a,std_a,re_b,im_b\n1,1,0,0.1,2,0\n");
  (void)input_error([&] { (void)read_frf(dir.path() / "half.csv"); }, "header");
}

TEST(FrfMat, MissingAndWrongVariablesAreNamed) {
  TempDir dir;
  const fs::path file = dir.path() / "x.mat";
  detail::write_mat_atomically(file, false, false, [](detail::MatWriter& w) {
    w.write(detail::make_real_column("f", Eigen::VectorXd::LinSpaced(3, 1, 3)));
  });
  EXPECT_TRUE(contains(input_error([&] { (void)read_frf(file); }), "freq_Hz"));
  detail::write_mat_atomically(file, false, false, [](detail::MatWriter& w) {
    w.write(detail::make_real_column("freq_Hz", Eigen::VectorXd::LinSpaced(3, 1, 3)));
    w.write(detail::make_text("outputs", "a,b"));
    w.write(detail::make_complex_column("H_a", Eigen::VectorXcd::Ones(3)));
  });
  const std::string msg = input_error([&] { (void)read_frf(file); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "H_b")) << msg;
  detail::write_mat_atomically(file, false, false, [](detail::MatWriter& w) {
    w.write(detail::make_real_column("freq_Hz", Eigen::VectorXd::LinSpaced(3, 1, 3)));
    w.write(detail::make_complex_column("H_a", Eigen::VectorXcd::Ones(4)));
  });
  const std::string msg2 = input_error([&] { (void)read_frf(file); });
  EXPECT_TRUE(contains(msg2, file.string()) && contains(msg2, "a: ") && contains(msg2, "3 values")) << msg2;
}

// ---- UFF 58 ---------------------------------------------------------------------------------

void expect_uff_round_trip(const dsp::Frf& back, const dsp::Frf& frf) {
  EXPECT_EQ(back.outputs, frf.outputs);
  EXPECT_EQ(back.input, frf.input);
  EXPECT_TRUE(all_near(back.freq_Hz, frf.freq_Hz, Tolerance{kUffAbscissaRel, 1e-12}));
  ASSERT_EQ(back.H.size(), 2u);
  ASSERT_EQ(back.coherence.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    // Each part is printed to 13 digits, so compare parts, not the complex modulus.
    EXPECT_TRUE(all_near(back.H[i].real(), frf.H[i].real(), kUffOrdinate)) << frf.outputs[i];
    EXPECT_TRUE(all_near(back.H[i].imag(), frf.H[i].imag(), kUffOrdinate)) << frf.outputs[i];
    EXPECT_TRUE(all_near(back.coherence[i], frf.coherence[i], kUffOrdinate)) << frf.outputs[i];
  }
  EXPECT_EQ(back.provenance.estimator, "H1");
  EXPECT_EQ(back.provenance.nfft, 10000);
  EXPECT_EQ(back.provenance.averages, 119);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  for (std::string_view l : text::split(text, '\n')) out.emplace_back(l);
  return out;
}

TEST(FrfUff, EvenGridRoundTripToPrintedPrecision) {
  TempDir dir;
  const dsp::Frf frf = sample_frf(even_grid());
  const fs::path file = dir.path() / "frf.uff";
  write_frf(frf, file);
  const std::vector<std::string> lines = lines_of(test::read_text(file));
  // First dataset: FRF of de, complex double, even spacing, Hz.
  EXPECT_EQ(lines[0], "    -1");
  EXPECT_EQ(lines[1], "    58");
  EXPECT_EQ(lines[3], "piezobench response: de");
  EXPECT_EQ(lines[5], "piezobench reference: u");
  EXPECT_EQ(lines[7].substr(0, 5), "    4");                           // record 6: function type 4
  EXPECT_EQ(lines[7].substr(41, 14), "         1   3");               // response node 1, +Z
  EXPECT_EQ(lines[8].substr(0, 30), "         6       201         1");  // complex double, 201, even
  EXPECT_EQ(lines[8].substr(30, 26), "  0.00000E+00  5.00000E+00");
  EXPECT_EQ(lines[6], "welch: est=H1 win=hann-periodic nfft=10000 ovl=0.5 dtr=none avg=119 fs=10000");
  EXPECT_EQ(lines[9].substr(0, 10), "        18");                      // abscissa: frequency
  EXPECT_EQ(lines[13].size(), 80u);  // 4E20.12: two complex values per line
  expect_uff_round_trip(read_frf(file), frf);
}

TEST(FrfUff, UnitsLabelsAreHonouredOrRefused) {
  TempDir dir;
  const dsp::Frf frf = sample_frf(even_grid());
  const fs::path file = dir.path() / "frf.uff";
  write_frf(frf, file);
  std::vector<std::string> lines = lines_of(test::read_text(file));
  // Every abscissa in kHz (record 8), the first FRF's ordinate in um (record 9; denominator NONE = V).
  ASSERT_EQ(lines[9].substr(47, 2), "Hz");
  const auto relabel = [&](size_t i, const std::string& unit) { lines[i] = lines[i].substr(0, 47) + unit; };
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].size() > 47 && lines[i].substr(0, 10) == "        18" && lines[i].substr(47, 2) == "Hz") relabel(i, "kHz");
  }
  relabel(10, "um");
  const auto write_lines = [&] {
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    write_bytes(file, text);
  };
  write_lines();
  const dsp::Frf back = read_frf(file);
  EXPECT_TRUE(test::near(back.freq_Hz(1), 1e3 * frf.freq_Hz(1), {1e-5, 0.0}));
  EXPECT_TRUE(test::near(back.H[0](7), 1e-6 * frf.H[0](7), {1e-11, 0.0}));
  EXPECT_TRUE(test::near(back.H[1](7), frf.H[1](7), {1e-11, 0.0}));  // the second dataset is unlabelled
  relabel(10, "furlong");
  write_lines();
  test::expect_input_error([&] { (void)read_frf(file); }, {"frf.uff", "record 9 (ordinate units)", "'furlong'", "known unit"});
  relabel(10, "NONE");
  relabel(9, "s");  // a time abscissa
  write_lines();
  test::expect_input_error([&] { (void)read_frf(file); }, {"record 8 (abscissa units)", "a frequency unit"});
}

// pyuff's sample FRF (tests/fixtures/io/pyuff/README.md): its ordinate unit "(1/N)*(m/s\xB2)" is
// Latin-1 text, read as (1/N)*(m/s^2): H stays in SI (the factor is 1) and is no longer refused.
TEST(FrfUff, PyuffLatin1UnitLabel) {
  const FrfFile f = read_frf_file(test::fixture_path("io/pyuff/non_ascii_header.uff"));
  ASSERT_EQ(f.frf.H.size(), 1u);
  ASSERT_EQ(f.units.size(), 1u);
  EXPECT_EQ(f.units[0], "m/N/s^2");
  EXPECT_TRUE(f.warnings.empty()) << text::join(f.warnings, "; ");
  // The file's six complex values as printed (record 7: 6 values from 0 Hz, 0.1953125 Hz apart).
  ASSERT_EQ(f.frf.freq_Hz.size(), 6);
  EXPECT_TRUE(test::near(f.frf.freq_Hz(5), 5 * 1.95313e-01, {1e-6, 0.0}));
  EXPECT_EQ(f.frf.H[0](0), std::complex<double>(4.07994e-01, 0.0));
  EXPECT_EQ(f.frf.H[0](1), std::complex<double>(-5.99924e-02, -5.53260e-02));
  EXPECT_EQ(f.frf.H[0](5), std::complex<double>(3.75037e+00, 2.93363e+00));
}

TEST(FrfCsv, LabDialectsAndScipysWelchFile) {
  TempDir dir;
  const fs::path file = dir.path() / "semi.csv";
  write_bytes(file, "freq [kHz];re_a;im_a\n0,5;1,5;-2\n1;3;4\n");
  const dsp::Frf frf = read_frf(file);
  EXPECT_EQ(frf.freq_Hz(0), 500.0);
  EXPECT_EQ(frf.H[0](0), std::complex<double>(1.5, -2.0));
  write_bytes(file, "freq_Hz;re_a;im_a\n1;2;3\n2;3\n");
  test::expect_input_error([&] { (void)read_frf(file); }, {"semi.csv", "line 3", "';'-separated (detected)"});
  // scipy's Welch H1 and coherence, 17 digits (scripts/fixtures/make_io_lab_fixtures.py).
  const dsp::Frf w = read_frf(test::fixture_path("io/lab/welch_frf.csv"));
  const auto ref = nlohmann::json::parse(test::read_text(test::fixture_path("io/lab/expected.json")));
  ASSERT_EQ(w.outputs, (std::vector<std::string>{"d_e", "Vs"}));
  ASSERT_EQ(static_cast<size_t>(w.freq_Hz.size()), ref["freq_Hz"].size());
  for (size_t i = 0; i < 2; ++i) {
    const auto& e = ref["outputs"][w.outputs[i]];
    for (size_t k = 0; k < e["H"].size(); ++k) {
      const std::complex<double> want(e["H"][k][0].get<double>(), e["H"][k][1].get<double>());
      ASSERT_EQ(w.H[i](static_cast<Index>(k)), want) << w.outputs[i] << " bin " << k;
      ASSERT_EQ(w.coherence[i](static_cast<Index>(k)), e["coherence"][k].get<double>());
    }
  }
}

TEST(FrfUff, UnevenGridRoundTripToPrintedPrecision) {
  TempDir dir;
  const dsp::Frf frf = sample_frf(log_grid());
  const fs::path file = dir.path() / "frf.unv";
  write_frf(frf, file);
  const std::vector<std::string> lines = lines_of(test::read_text(file));
  EXPECT_EQ(lines[8].substr(20, 10), "         0");  // uneven
  EXPECT_EQ(lines[13].size(), 53u);  // E13.5,2E20.12: one point per line
  expect_uff_round_trip(read_frf_uff58(file), frf);
}

// ---- 58b built by hand from the format description ---------------------------------------------

std::string pad80(const std::string& s) { return s + std::string(80 - std::min<size_t>(80, s.size()), ' '); }

template <typename T>
void put(std::string& out, T v, bool big_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian == (std::endian::native == std::endian::little)) std::reverse(b, b + sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// One dataset 58b. Records 6..11 in their Fortran formats, then the raw bytes and "    -1" right
// after them (the format puts no line break between).
std::string dataset_58b(bool big_endian, bool even, int x_bytes, int response_node, const std::string& ord_label,
                        const std::vector<double>& x, const std::vector<std::complex<double>>& y, bool newline_after = false) {
  std::string data;
  for (size_t k = 0; k < y.size(); ++k) {
    if (!even) {
      if (x_bytes == 4) put<float>(data, static_cast<float>(x[k]), big_endian);
      else put<double>(data, x[k], big_endian);
    }
    put<double>(data, y[k].real(), big_endian);
    put<double>(data, y[k].imag(), big_endian);
  }
  char buf[200];
  std::string out = "    -1\n";
  // Format(I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12)
  std::snprintf(buf, sizeof buf, "%6d%c%6d%6d%12d%12zu%6d%6d%12d%12d\n", 58, 'b', big_endian ? 2 : 1, 2, 11, data.size(), 0, 0, 0, 0);
  out += buf;
  out += pad80("Hammer test point " + std::to_string(response_node)) + "\n";
  out += "NONE\nNONE\nNONE\nNONE\n";
  // Record 6: Format(2(I5,I10),2(1X,10A1,I10,I4))
  std::snprintf(buf, sizeof buf, "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", 4, 1, 0, 0, "NONE", response_node, -2, "NONE", 7, 3);
  out += buf;
  // Record 7: Format(3I10,3E13.5)
  std::snprintf(buf, sizeof buf, "%10d%10zu%10d%13.5E%13.5E%13.5E\n", 6, y.size(), even ? 1 : 0, even ? x[0] : 0.0,
                even ? x[1] - x[0] : 0.0, 0.0);
  out += buf;
  // Records 8..11: Format(I10,3I5,2(1X,20A1))
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 18, 0, 0, 0, "Frequency", "Hz");
  out += buf;
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 12, 0, 0, 0, ord_label.c_str(), "m/s^2");
  out += buf;
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 13, 0, 0, 0, "NONE", "N");
  out += buf;
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  out += buf;
  out += data;
  if (newline_after) out += "\n";
  out += "    -1\n";
  return out;
}

TEST(FrfUff, BinaryDataset58bBuiltByHand) {
  TempDir dir;
  // Little endian, even spacing (x = 2.5 + 0.5 k, exact in E13.5), double precision.
  const std::vector<double> x_even = {2.5, 3.0, 3.5, 4.0, 4.5};
  std::vector<std::complex<double>> y1, y2;
  for (size_t k = 0; k < x_even.size(); ++k) {
    y1.emplace_back(1.0 / (1.0 + static_cast<double>(k)), -0.1 * static_cast<double>(k) - 1e-300);
    y2.emplace_back(std::sqrt(2.0) * static_cast<double>(k), 1.0 / 3.0);
  }
  // A dataset 151 (header) and an ASCII dataset of another type come first and must be skipped.
  std::string file_text = "    -1\n   151\nmodel\nNONE\nNONE\nNONE\nNONE\nNONE\nNONE\n    -1\n";
  file_text += dataset_58b(false, true, 0, 11, "accel 11", x_even, y1);
  file_text += dataset_58b(false, true, 0, 12, "NONE", x_even, y2, /*newline_after=*/true);
  const fs::path file = dir.path() / "hammer.uff";
  write_bytes(file, file_text);
  const dsp::Frf frf = read_frf(file);
  ASSERT_EQ(frf.outputs, (std::vector<std::string>{"accel 11", "12-Y"}));  // label, else node/direction
  EXPECT_EQ(frf.input, "7+Z");
  EXPECT_TRUE(all_near(frf.freq_Hz, Eigen::Map<const Eigen::VectorXd>(x_even.data(), 5), kExact));
  for (size_t k = 0; k < y1.size(); ++k) {
    EXPECT_EQ(frf.H[0](static_cast<Index>(k)), y1[k]);  // binary: bit-exact
    EXPECT_EQ(frf.H[1](static_cast<Index>(k)), y2[k]);
  }
  EXPECT_TRUE(frf.coherence.empty());

  // Big endian, uneven spacing, abscissa as float32 (the format's text) and as float64 (pyuff).
  const std::vector<double> x_uneven = {1.0, 2.0, 4.0, 8.0, 16.0};
  for (const int x_bytes : {4, 8}) {
    SCOPED_TRACE(x_bytes);
    write_bytes(file, dataset_58b(true, false, x_bytes, 3, "NONE", x_uneven, y2));
    const dsp::Frf be = read_frf_uff58(file);
    EXPECT_EQ(be.outputs, std::vector<std::string>{"3-Y"});
    EXPECT_TRUE(all_near(be.freq_Hz, Eigen::Map<const Eigen::VectorXd>(x_uneven.data(), 5), kExact));
    for (size_t k = 0; k < y2.size(); ++k) EXPECT_EQ(be.H[0](static_cast<Index>(k)), y2[k]);
  }
}

TEST(FrfUff, MalformedFilesAreInputErrorsNamingFileAndRecord) {
  TempDir dir;
  const fs::path file = dir.path() / "bad.uff";
  const std::vector<double> x = {1.0, 2.0, 3.0};
  const std::vector<std::complex<double>> y = {{1, 2}, {3, 4}, {5, 6}};
  const std::string good_b = dataset_58b(false, true, 0, 1, "NONE", x, y);
  // Every truncation of a binary and of an ASCII file.
  const dsp::Frf frf = sample_frf(even_grid(9));
  const fs::path ascii_file = dir.path() / "ascii.uff";
  write_frf_uff58(frf, ascii_file);
  const std::string good_a = test::read_text(ascii_file);
  for (const auto& [name, good] : std::vector<std::pair<std::string, std::string>>{{"58b", good_b}, {"58", good_a}}) {
    size_t failures = 0, cases = 0;
    const size_t step = std::max<size_t>(1, good.size() / 150);
    for (size_t cut = 0; cut + 8 < good.size(); cut += step) {
      write_bytes(file, good.substr(0, cut));
      ++cases;
      try {
        (void)read_frf_uff58(file);
      } catch (const InputError& e) {
        ++failures;
        EXPECT_TRUE(contains(e.what(), file.string())) << e.what();
      }
    }
    EXPECT_EQ(failures, cases) << name << ": every truncated file must be rejected";
  }
  const auto replace = [](std::string s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {replace(good_b, "     1     2          11", "     1     1          11"), "floating-point format"},
      {replace(good_b, "     1     2          11", "     3     2          11"), "byte order"},
      {replace(good_b, "          11          48", "          11          40"), "number of bytes"},
      {replace(good_b, "          11          48", "          11          4x"), "number of bytes"},
      {replace(good_b, "         6         3", "         7         3"), "ordinate data type"},
      {replace(good_b, "    4         1", "    1         1"), "none an FRF"},
      {replace(good_a, "         6         9", "         6        10"), "record 12"},
      {replace(good_a, "E-", "X-"), "record 12"},
      {"    -1\n    58\n", "ID lines"},
      {"hello\n", "line 1"},
      {good_a + good_a, "twice"},
  };
  for (const auto& [text, expected] : cases) {
    write_bytes(file, text);
    const std::string msg = input_error([&] { (void)read_frf(file); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, expected)) << expected << ": " << msg;
  }
}

TEST(FrfUff, GridsAndReferencesMustAgree) {
  TempDir dir;
  const fs::path a = dir.path() / "a.uff", b = dir.path() / "b.uff", both = dir.path() / "both.uff";
  dsp::Frf one = sample_frf(even_grid(11));
  write_frf_uff58(one, a);
  one.outputs = {"x", "y"};
  one.freq_Hz *= 2.0;
  write_frf_uff58(one, b);
  write_bytes(both, test::read_text(a) + test::read_text(b));
  EXPECT_TRUE(contains(input_error([&] { (void)read_frf(both); }), "frequency grid"));
  one.freq_Hz /= 2.0;
  one.input = "v";
  write_frf_uff58(one, b);
  write_bytes(both, test::read_text(a) + test::read_text(b));
  EXPECT_TRUE(contains(input_error([&] { (void)read_frf(both); }), "reference"));
}

// ---- writers --------------------------------------------------------------------------------

TEST(FrfWrite, InvalidFrfOrNamesWriteNothing) {
  TempDir dir;
  dsp::Frf frf = sample_frf(even_grid(20));
  frf.H[1](4) = {std::nan(""), 0.0};
  for (const char* name : {"x.csv", "x.mat", "x.uff"}) {
    const fs::path file = dir.path() / name;
    const std::string msg = input_error([&] { write_frf(frf, file); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "Vs")) << msg;
  }
  frf = sample_frf(even_grid(20));
  frf.outputs[0] = "d e";
  EXPECT_TRUE(contains(input_error([&] { write_frf(frf, dir.path() / "y.mat"); }), "MATLAB"));
  frf.outputs[0] = "a,b";
  EXPECT_TRUE(contains(input_error([&] { write_frf(frf, dir.path() / "y.csv"); }), "commas"));
  EXPECT_TRUE(contains(input_error([&] { write_frf(frf, dir.path() / "y.txt"); }), ".txt"));
  EXPECT_TRUE(fs::is_empty(dir.path()));
  // A target that cannot be replaced (a directory) leaves nothing behind either.
  const fs::path taken = dir.path() / "taken.uff";
  fs::create_directory(taken);
  frf = sample_frf(even_grid(20));
  EXPECT_THROW(write_frf(frf, taken), InputError);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(FrfFormat, NamesAndExtensions) {
  for (const FrfFormat f : {FrfFormat::kCsv, FrfFormat::kMat, FrfFormat::kUff58}) {
    EXPECT_EQ(frf_format_from_string(to_string(f)), f);
  }
  EXPECT_EQ(frf_format_from_path("x/y.UNV"), FrfFormat::kUff58);
  EXPECT_EQ(frf_format_from_path("y.Mat"), FrfFormat::kMat);
  EXPECT_THROW((void)frf_format_from_string("xls"), InputError);
  FrfWriteOptions o;
  o.reference_node = -1;
  EXPECT_TRUE(contains(input_error([&] { o.validate(); }), "reference_node"));
}

// ---- units of FRF files (scripts/fixtures/make_io_units_fixtures.py) ---------------------------

TEST(FrfUnits, FilesStateTheirUnitsAndAreReadInSi) {
  const auto ref = nlohmann::json::parse(test::read_text(test::fixture_path("io/units/expected.json")));
  for (const char* name : {"frf_um_per_V.csv", "frf_um_per_V.mat"}) {
    SCOPED_TRACE(name);
    const FrfFile f = read_frf_file(test::fixture_path(std::string("io/units/") + name));
    ASSERT_EQ(f.frf.outputs, (std::vector<std::string>{"d_e", "Vs"}));
    EXPECT_EQ(f.units, (std::vector<std::string>{"m/V", "1"}));
    EXPECT_TRUE(f.warnings.empty()) << text::join(f.warnings, "; ");
    for (size_t k = 0; k < ref["freq_Hz"].size(); k += 7) {
      const std::complex<double> de(ref["H_d_e"]["re"][k].get<double>(), ref["H_d_e"]["im"][k].get<double>());
      const std::complex<double> vs(ref["H_Vs"]["re"][k].get<double>(), ref["H_Vs"]["im"][k].get<double>());
      EXPECT_LE(std::abs(f.frf.H[0](static_cast<Index>(k)) - de), 1e-14 * std::abs(de)) << k;
      EXPECT_LE(std::abs(f.frf.H[1](static_cast<Index>(k)) - vs), 1e-14 * std::abs(vs)) << k;
    }
  }
  // A compound UFF unit, (1/N)*(m/s^2) over N, is not divided twice: H = 2 x H_d_e in SI.
  const FrfFile c = read_frf_file(test::fixture_path("io/units/frf_compound.uff"));
  EXPECT_EQ(c.units, (std::vector<std::string>{"m/N/s^2"}));
  for (size_t k = 1; k < ref["freq_Hz"].size(); k += 7) {
    const std::complex<double> de(ref["H_d_e"]["re"][k].get<double>(), ref["H_d_e"]["im"][k].get<double>());
    EXPECT_LE(std::abs(c.frf.H[0](static_cast<Index>(k)) - 2.0 * de), 1e-11 * std::abs(de)) << k;
  }
}

TEST(FrfUnits, MissingUnitsWarnOverridesReplaceAndTyposAreRefused) {
  const fs::path none = test::fixture_path("io/units/frf_no_units.csv");
  const FrfFile plain = read_frf_file(none);
  EXPECT_EQ(plain.units, (std::vector<std::string>{""}));
  ASSERT_EQ(plain.warnings.size(), 1u);
  EXPECT_TRUE(contains(plain.warnings[0], "frf_no_units.csv: output d_e has no unit: H taken as SI")) << plain.warnings[0];
  FrfReadOptions o;
  o.unit_overrides = {{"d_e", "um"}, {"input", "mV"}};
  const FrfFile scaled = read_frf_file(none, o);
  EXPECT_EQ(scaled.units, (std::vector<std::string>{"m/V"}));
  EXPECT_EQ(scaled.frf.H[0](3), plain.frf.H[0](3) * 1e-3);
  o.unit_overrides = {{"H_d_e", "nm/V"}};
  EXPECT_EQ(read_frf_file(none, o).frf.H[0](3), plain.frf.H[0](3) * 1e-9);
  o.unit_overrides = {{"H_d_e", "nm/V"}};
  const FrfFile replaced = read_frf_file(test::fixture_path("io/units/frf_um_per_V.csv"), o);
  EXPECT_TRUE(contains(replaced.warnings.at(0), "output d_e: unit 'nm/V' from --units replaces 'um/V' in the file")) << replaced.warnings[0];
  o.unit_overrides = {{"de", "um"}};
  test::expect_input_error([&] { (void)read_frf_file(none, o); }, {"frf_no_units.csv", "--units de", "'de', which names no channel"});
  TempDir dir;
  const fs::path file = dir.path() / "mixed.csv";
  write_bytes(file, "freq_Hz,re_a [um/V],im_a [mm/V]\n1,2,3\n");
  test::expect_input_error([&] { (void)read_frf(file); }, {"mixed.csv", "header column 3", "'um/V'"});
  write_bytes(file, "freq_Hz,re_a [furlong],im_a [furlong]\n1,2,3\n");
  test::expect_input_error([&] { (void)read_frf(file); }, {"mixed.csv", "unit of H_a", "'furlong'"});
}

TEST(FrfUnits, WrittenUnitsReadBack) {
  TempDir dir;
  const dsp::Frf frf = sample_frf(even_grid());
  FrfWriteOptions w;
  w.output_units.assign(frf.outputs.size(), "m");
  w.input_unit = "V";
  for (const char* name : {"u.csv", "u.mat", "u.uff"}) {
    SCOPED_TRACE(name);
    const fs::path file = dir.path() / name;
    write_frf(frf, file, w);
    const FrfFile back = read_frf_file(file);
    EXPECT_EQ(back.units, std::vector<std::string>(frf.outputs.size(), "m/V"));
    EXPECT_TRUE(back.warnings.empty()) << text::join(back.warnings, "; ");
  }
}

}  // namespace
}  // namespace piezobench::io
