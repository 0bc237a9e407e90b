// Tests of the private MAT-file layer: the own v5 encoder and reader (mat_file.cpp, the v5 parts of
// mat_reader.cpp) against scipy.io.loadmat and matio, and its helpers (reading is tested further
// through mat_reader_test, timeseries_test and frf_file_test).
#include "mat_file.hpp"

#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io::detail {
namespace {

using json = nlohmann::json;

TEST(MatlabIdentifier, FollowsMatlabRules) {
  EXPECT_TRUE(is_matlab_identifier("d_enc2"));
  EXPECT_FALSE(is_matlab_identifier("2d"));
  EXPECT_FALSE(is_matlab_identifier("_x"));
  EXPECT_FALSE(is_matlab_identifier("a b"));
  EXPECT_FALSE(is_matlab_identifier(std::string(64, 'a')));
  EXPECT_TRUE(is_matlab_identifier(std::string(63, 'a')));
}

TEST(MatText, Utf8AndUtf16RoundTrip) {
  const std::string text = "a\u00b5\u20ac\U0001F600z";
  const std::u16string units = utf16_from_utf8(text);
  EXPECT_EQ(units, u"a\u00b5\u20ac\U0001F600z");
  EXPECT_EQ(units.size(), 6u);  // the emoji is a surrogate pair
  const std::vector<double> d(units.begin(), units.end());
  EXPECT_EQ(utf8_from_units(d.data(), d.size()), text);
  // UTF-32 data hold code points; invalid bytes and unpaired surrogates become U+FFFD.
  const double code_point = 0x1F600;
  EXPECT_EQ(utf8_from_units(&code_point, 1), "\U0001F600");
  EXPECT_EQ(utf16_from_utf8("x\xff\xc3"), u"x\uFFFD\uFFFD");
  const double lone = 0xD800;
  EXPECT_EQ(utf8_from_units(&lone, 1), "\uFFFD");
  EXPECT_EQ(make_text("t", "\u00b5m").dims, (std::vector<size_t>{1, 2}));
}

// Every layout the writers of piezobench produce: real columns and matrices (with values that a
// conversion would change), complex columns, scalars, text (also empty), logical rows, [], nested
// structs, a struct array and a cell.
std::vector<MatValue> layouts(const Eigen::VectorXd& column) {
  std::vector<MatValue> v;
  v.push_back(make_real_column("col", column));
  v.push_back(make_matrix("mat", 2, 3, {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}));
  Eigen::VectorXcd z(3);
  z << std::complex<double>(1.0, 2.0), std::complex<double>(-3.5, -0.25), std::complex<double>(0.0, 1e-300);
  v.push_back(make_complex_column("z", z));
  v.push_back(make_scalar("s", 42.0));
  v.push_back(make_text("txt", "hello, world"));
  v.push_back(make_text("abc", ""));
  v.push_back(make_text("unit", "\u00b5m, \u00dc \u2192 \u221e"));  // UTF-8 in, UTF-16 in the file
  v.push_back(make_logical("flags", {1, 0, 1}));
  v.push_back(make_matrix("e", 0, 0, {}));
  v.push_back(make_struct("st", {{"a", make_scalar("", 1.0)},
                                 {"name", make_text("", "x")},
                                 {"inner", make_struct("", {{"v", make_matrix("", 1, 2, {7.0, 8.0})}})}}));
  MatValue array("arr", MAT_C_STRUCT, {1, 2});
  array.field_names = {"id", "why"};
  array.items = {make_scalar("id", 1.0), make_text("why", "ok"), make_scalar("id", 3.0), make_matrix("why", 0, 0, {})};
  v.push_back(array);
  MatValue cell("c", MAT_C_CELL, {1, 3});
  cell.items = {make_text("", "stroke"), make_matrix("", 1, 2, {-10.0, 600.0}), make_logical("", {0})};
  v.push_back(cell);
  return v;
}

Eigen::VectorXd awkward_column() {
  Eigen::VectorXd c(6);
  c << 0.1, -0.0, 1e-310, std::numeric_limits<double>::max(), -2.5, 1.0 / 3.0;
  return c;
}

std::filesystem::path write_layouts(const test::TempDir& dir, const Eigen::VectorXd& column) {
  const auto file = dir.path() / "layouts.mat";
  const std::vector<MatValue> vars = layouts(column);
  write_mat_atomically(file, false, false, [&](MatWriter& w) {
    for (const MatValue& v : vars) w.write(v);
  });
  return file;
}

// The reference reader's view of a value, compared with what was written.
void expect_same(const json& ref, const MatValue& v, const std::string& where) {
  SCOPED_TRACE(where);
  std::vector<size_t> shape;
  for (const auto& d : ref.at("shape")) shape.push_back(d.get<size_t>());
  EXPECT_EQ(shape, v.dims);
  const std::string cls = ref.at("class");
  switch (v.class_type) {
    case MAT_C_STRUCT: {
      ASSERT_EQ(cls, "struct");
      EXPECT_EQ(ref.at("fields").get<std::vector<std::string>>(), v.field_names);
      const size_t nf = v.field_names.size();
      ASSERT_EQ(ref.at("elements").size() * nf, v.items.size());
      for (size_t i = 0; i < v.items.size(); ++i) {
        expect_same(ref.at("elements").at(i / nf).at(v.field_names[i % nf]), v.items[i], where + "." + v.field_names[i % nf]);
      }
      return;
    }
    case MAT_C_CELL: {
      ASSERT_EQ(cls, "cell");
      ASSERT_EQ(ref.at("cells").size(), v.items.size());
      for (size_t i = 0; i < v.items.size(); ++i) expect_same(ref.at("cells").at(i), v.items[i], where + "{" + std::to_string(i) + "}");
      return;
    }
    case MAT_C_CHAR:
      ASSERT_EQ(cls, "char");
      EXPECT_EQ(ref.at("text").get<std::string>(), v.text);
      return;
    default: break;
  }
  EXPECT_EQ(cls, v.is_logical ? "uint8" : "double");  // scipy reads logical as uint8
  const auto& re = ref.at("re");
  ASSERT_EQ(re.size(), v.count());
  for (size_t i = 0; i < v.count(); ++i) {
    const double x = v.real()[i];
    EXPECT_EQ(std::signbit(re[i].get<double>()), std::signbit(x)) << i;
    EXPECT_EQ(re[i].get<double>(), x) << i;  // bit-exact (JSON holds repr's 17 digits)
    if (v.is_complex) {
      EXPECT_EQ(ref.at("im").at(i).get<double>(), v.im[i]) << i;
    }
  }
  EXPECT_EQ(ref.contains("im"), v.is_complex);
}

TEST(MatV5Writer, ScipyReadsEveryLayoutExactly) {
  test::TempDir dir;
  const Eigen::VectorXd column = awkward_column();
  const auto file = write_layouts(dir, column);
  const std::string command = "/usr/bin/python3 " PIEZOBENCH_SOURCE_DIR "/scripts/analysis/loadmat_json.py '" + file.string() + "'";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  const int status = ::pclose(pipe);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 77) GTEST_SKIP() << "scipy is not installed";
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  const json ref = json::parse(out);
  const std::vector<MatValue> written = layouts(column);
  ASSERT_EQ(ref.size(), written.size()) << out;
  for (const MatValue& v : written) {
    ASSERT_TRUE(ref.contains(v.name)) << v.name;
    expect_same(ref.at(v.name), v, v.name);
  }
}

// The same file read by the own reader (no matio) and by matio itself: the same values.
TEST(MatV5Writer, OwnReaderAndMatioReadItBack) {
  test::TempDir dir;
  const Eigen::VectorXd column = awkward_column();
  const auto file = write_layouts(dir, column);
  const MatFilePtr in = open_mat_for_reading(file);
  EXPECT_TRUE(read_without_matio(in.get()));
  const std::vector<MatValue> written = layouts(column);
  const std::vector<MatVarInfo> listed = list_mat_variables(in.get(), file);
  ASSERT_EQ(listed.size(), written.size());
  mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  for (size_t i = 0; i < written.size(); ++i) {
    const MatValue& w = written[i];
    SCOPED_TRACE(w.name);
    EXPECT_EQ(listed[i].name, w.name);
    EXPECT_EQ(listed[i].dims, w.dims);
    const MatValue own = read_mat_variable(in.get(), file, w.name);
    matvar_t* raw = Mat_VarRead(mat, w.name.c_str());
    ASSERT_NE(raw, nullptr);
    const MatValue by_matio = from_matvar(*raw, file.string());
    Mat_VarFree(raw);
    for (const MatValue* r : {&own, &by_matio}) {
      EXPECT_EQ(r->class_type, w.class_type);
      EXPECT_EQ(r->is_logical, w.is_logical);
      EXPECT_EQ(r->is_complex, w.is_complex);
      EXPECT_EQ(r->dims, w.dims);
      EXPECT_EQ(r->field_names, w.field_names);
      EXPECT_EQ(r->text, w.text);
      EXPECT_EQ(r->items.size(), w.items.size());
      ASSERT_EQ(r->re.size(), w.class_type == MAT_C_DOUBLE || w.is_logical ? w.count() : 0u);
      for (size_t k = 0; k < r->re.size(); ++k) EXPECT_EQ(std::memcmp(&r->re[k], w.real() + k, 8), 0) << k;
      EXPECT_EQ(r->im, w.im);
    }
    for (size_t k = 0; k < w.items.size(); ++k) {
      EXPECT_EQ(own.items[k].text, w.items[k].text);
      EXPECT_EQ(own.items[k].re, w.items[k].re);
      EXPECT_EQ(by_matio.items[k].re, w.items[k].re);
    }
  }
  Mat_Close(mat);
  // The long column also through the fast paths.
  Eigen::VectorXd back(column.size());
  ASSERT_TRUE(read_double_vector_into(in.get(), "col", back, 4));
  EXPECT_EQ(std::memcmp(back.data(), column.data(), 8 * column.size()), 0);
  EXPECT_EQ(read_double_element(in.get(), "col", column.size(), 5), column(5));
}

// Written by matio (compressed) the same variables read back the same through the matio path.
TEST(MatV5Writer, CompressedFilesGoThroughMatio) {
  test::TempDir dir;
  const auto file = dir.path() / "z.mat";
  const Eigen::VectorXd column = awkward_column();
  const std::vector<MatValue> vars = layouts(column);
  write_mat_atomically(file, false, true, [&](MatWriter& w) {
    for (const MatValue& v : vars) w.write(v);
  });
  const MatFilePtr in = open_mat_for_reading(file);
  EXPECT_FALSE(read_without_matio(in.get()));
  const MatValue st = read_mat_variable(in.get(), file, "st");
  ASSERT_NE(st.field("inner"), nullptr);
  ASSERT_NE(st.field("inner")->field("v"), nullptr);
  EXPECT_EQ(st.field("inner")->field("v")->re, (std::vector<double>{7.0, 8.0}));
  const MatValue c = read_mat_variable(in.get(), file, "c");
  ASSERT_EQ(c.items.size(), 3u);
  EXPECT_EQ(c.items[0].text, "stroke");
  EXPECT_EQ(to_real_vector(read_mat_variable(in.get(), file, "col"), file.string(), "col"), column);
}

// Two reads of one variable hold the same values (numbers compared bit by bit).
void expect_equal_values(const MatValue& a, const MatValue& b, const std::string& where) {
  SCOPED_TRACE(where);
  EXPECT_EQ(a.class_type, b.class_type);
  EXPECT_EQ(a.is_complex, b.is_complex);
  EXPECT_EQ(a.is_logical, b.is_logical);
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.text, b.text);
  EXPECT_EQ(a.field_names, b.field_names);
  ASSERT_EQ(a.re.size(), b.re.size());
  ASSERT_EQ(a.im.size(), b.im.size());
  for (size_t i = 0; i < a.re.size(); ++i) EXPECT_EQ(std::memcmp(&a.re[i], &b.re[i], 8), 0) << i;
  for (size_t i = 0; i < a.im.size(); ++i) EXPECT_EQ(std::memcmp(&a.im[i], &b.im[i], 8), 0) << i;
  ASSERT_EQ(a.items.size(), b.items.size());
  for (size_t i = 0; i < a.items.size(); ++i) expect_equal_values(a.items[i], b.items[i], where + "[" + std::to_string(i) + "]");
}

// Files written by Octave and scipy: the own reader reads what matio reads.
TEST(MatV5Reader, OctaveAndScipyFilesReadAsMatioReadsThem) {
  for (const char* name : {"io/octave_v6.mat", "io/scipy_types.mat", "io/scipy_struct.mat", "io/scipy_two_outputs.mat"}) {
    SCOPED_TRACE(name);
    const auto file = test::fixture_path(name);
    const MatFilePtr in = open_mat_for_reading(file);
    EXPECT_TRUE(read_without_matio(in.get()));
    mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
    ASSERT_NE(mat, nullptr);
    const std::vector<MatVarInfo> listed = list_mat_variables(in.get(), file);
    EXPECT_FALSE(listed.empty());
    for (const MatVarInfo& v : listed) {
      matvar_t* raw = Mat_VarRead(mat, v.name.c_str());
      ASSERT_NE(raw, nullptr) << v.name;
      const MatValue by_matio = from_matvar(*raw, file.string());
      Mat_VarFree(raw);
      expect_equal_values(read_mat_variable(in.get(), file, v.name), by_matio, v.name);
      EXPECT_EQ(v.dims, by_matio.dims) << v.name;
      EXPECT_EQ(v.class_type, by_matio.class_type) << v.name;
    }
    Mat_Close(mat);
  }
  // And the values Octave saved (scripts/fixtures/make_io_v5_fixtures.py).
  const auto file = test::fixture_path("io/octave_v6.mat");
  const MatFilePtr in = open_mat_for_reading(file);
  const MatValue s = read_mat_variable(in.get(), file, "s");
  EXPECT_EQ(to_text(*s.field("label"), file.string(), "label"), "unit 3");
  EXPECT_EQ(s.field("inner")->field("v")->re, (std::vector<double>{7.0, 8.0}));
  const MatValue arr = read_mat_variable(in.get(), file, "arr");
  EXPECT_EQ(arr.dims, (std::vector<size_t>{1, 2}));
  EXPECT_TRUE(arr.field("ok", 1)->is_logical);
  EXPECT_EQ(arr.field("ok", 1)->re, std::vector<double>{0.0});
  EXPECT_EQ(arr.field("id", 1)->re, std::vector<double>{2.0});
  const MatValue c = read_mat_variable(in.get(), file, "c");
  ASSERT_EQ(c.items.size(), 3u);
  EXPECT_EQ(c.items[0].text, "stroke");
  EXPECT_EQ(c.items[1].re, (std::vector<double>{1.0, 3.0, 2.0, 4.0}));
  EXPECT_EQ(c.items[2].class_type, MAT_C_INT8);
  EXPECT_EQ(c.items[2].re, std::vector<double>{-5.0});
  EXPECT_EQ(read_mat_variable(in.get(), file, "k").re, (std::vector<double>{-8.0, 0.0, 7.0}));
  EXPECT_EQ(read_mat_variable(in.get(), file, "cm").text, "adbecf");  // 2x3, column-major
  const Eigen::VectorXcd z = to_complex_vector(read_mat_variable(in.get(), file, "z"), file.string(), "z");
  EXPECT_EQ(z(1), std::complex<double>(-3.5, -0.25));
  const Eigen::VectorXd x = to_real_vector(read_mat_variable(in.get(), file, "x"), file.string(), "x");
  EXPECT_TRUE(std::signbit(x(1)));
  EXPECT_EQ(x(2), 1e-310);
}

// A file in the other byte order is left to matio (and read the same).
TEST(MatV5Reader, BigEndianFilesAreReadByMatio) {
  const auto file = test::fixture_path("io/big_endian.mat");
  const MatFilePtr in = open_mat_for_reading(file);
  EXPECT_FALSE(read_without_matio(in.get()));
  EXPECT_EQ(to_real_vector(read_mat_variable(in.get(), file, "x"), file.string(), "x"), Eigen::Vector3d(1.5, -2.0, 1e10));
  EXPECT_EQ(to_text(read_mat_variable(in.get(), file, "name"), file.string(), "name"), "be");
}

// Truncated or garbage elements: a clear InputError naming the file and the variable, never a crash.
TEST(MatV5Reader, DamagedFilesAreInputErrors) {
  test::TempDir dir;
  const auto good = write_layouts(dir, awkward_column());
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto damaged = dir.path() / "damaged.mat";
  const auto write = [&](const std::string& b) {
    std::ofstream out(damaged, std::ios::binary | std::ios::trunc);
    out << b;
  };
  // Cut in the middle of the first variable's data.
  write(bytes.substr(0, 128 + 60));
  std::string message = test::input_error([&] { (void)open_mat_for_reading(damaged); }, "file");
  EXPECT_NE(message.find(damaged.string()), std::string::npos) << message;
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  // A dimension that claims more data than the element holds (col: 6x1 -> 6000x1).
  std::string big = bytes;
  const std::int32_t rows = 6000;
  std::memcpy(big.data() + 128 + 8 + 16 + 8, &rows, 4);
  write(big);
  message = test::input_error([&] { (void)open_mat_for_reading(damaged); });
  EXPECT_NE(message.find("'col'"), std::string::npos) << message;
  EXPECT_NE(message.find("6000 elements"), std::string::npos) << message;
  // Any 8 bytes garbled: an InputError or values, never a crash (the sanitizer build checks memory).
  for (size_t at = 128; at + 8 <= bytes.size(); at += 8) {
    std::string garbage = bytes;
    for (size_t k = 0; k < 8; ++k) garbage[at + k] = static_cast<char>(0xA5 ^ k);
    write(garbage);
    try {
      const MatFilePtr in = open_mat_for_reading(damaged);
      for (const MatVarInfo& v : list_mat_variables(in.get(), damaged)) (void)read_mat_variable(in.get(), damaged, v.name);
    } catch (const InputError&) {
    }
  }
}

}  // namespace
}  // namespace piezobench::io::detail
