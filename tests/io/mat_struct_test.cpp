#include "piezobench/io/mat_struct.hpp"

#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>

#include "test_util.hpp"

namespace piezobench::io {
namespace {

using json = nlohmann::json;

struct MatCloser {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};

// A results.json-like document.
json document() {
  return json::parse(R"({
    "units": [
      {"id": 1, "flatness_um": 8.9, "accepted": true, "reasons": [],
       "capacitance_uF": {"sensor": 5.1, "actuator": 10.03}, "hpf_corner_Hz": null},
      {"id": 3, "flatness_um": 9.1, "accepted": false, "reasons": ["capacitance", "stroke"],
       "capacitance_uF": {"sensor": 1.72, "actuator": 5.18}, "hpf_corner_Hz": 0.39}
    ],
    "iff": {"gains": [0, 1e5, 2e5], "damped_poles": [[-10, 600], [-50, 580], "nan"], "optimal_gain": 2.8e5},
    "batch": {"outliers": [3], "flags": [true, false, true], "ragged": [[1, 2], [3]], "spread": "nan"},
    "1st key-with.dots": "text"
  })");
}

// A char row in whichever width matio read it (8 bit for v5, 16 bit for v7.3).
std::string text_of(const matvar_t* v) {
  std::string out;
  const std::size_t n = v->dims[1];
  if (v->data_type == MAT_T_UINT16 || v->data_type == MAT_T_UTF16) {
    for (std::size_t i = 0; i < n; ++i) out += static_cast<char>(static_cast<const std::uint16_t*>(v->data)[i]);
  } else {
    out.assign(static_cast<const char*>(v->data), n);
  }
  return out;
}

double scalar(const matvar_t* v) {
  EXPECT_EQ(v->class_type, MAT_C_DOUBLE);
  return static_cast<const double*>(v->data)[0];
}

matvar_t* field(matvar_t* s, const char* name, std::size_t index = 0) {
  matvar_t* f = Mat_VarGetStructFieldByName(s, name, index);
  EXPECT_NE(f, nullptr) << name;
  return f;
}

void check_file(const std::filesystem::path& file) {
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  ASSERT_TRUE(mat);
  std::unique_ptr<matvar_t, VarFreer> units(Mat_VarRead(mat.get(), "units"));
  ASSERT_TRUE(units);
  // A 1x2 struct array: units(2).capacitance_uF.sensor = 1.72.
  ASSERT_EQ(units->class_type, MAT_C_STRUCT);
  EXPECT_EQ(units->dims[0], 1u);
  EXPECT_EQ(units->dims[1], 2u);
  EXPECT_EQ(scalar(field(units.get(), "id", 1)), 3.0);
  EXPECT_EQ(scalar(field(field(units.get(), "capacitance_uF", 1), "sensor")), 1.72);
  matvar_t* accepted = field(units.get(), "accepted", 1);
  EXPECT_TRUE(accepted->isLogical);
  EXPECT_EQ(static_cast<const unsigned char*>(accepted->data)[0], 0);
  // null -> [], an empty list -> [], a list of strings -> cell.
  EXPECT_EQ(field(units.get(), "hpf_corner_Hz", 0)->dims[0], 0u);
  EXPECT_EQ(field(units.get(), "reasons", 0)->dims[1], 0u);
  matvar_t* reasons = field(units.get(), "reasons", 1);
  ASSERT_EQ(reasons->class_type, MAT_C_CELL);
  matvar_t* second = Mat_VarGetCell(reasons, 1);
  ASSERT_EQ(second->class_type, MAT_C_CHAR);
  EXPECT_EQ(text_of(second), "stroke");

  std::unique_ptr<matvar_t, VarFreer> iff(Mat_VarRead(mat.get(), "iff"));
  ASSERT_TRUE(iff);
  matvar_t* gains = field(iff.get(), "gains");
  EXPECT_EQ(gains->dims[1], 3u);
  EXPECT_EQ(static_cast<const double*>(gains->data)[1], 1e5);
  // Pairs and a "nan": not a matrix (the "nan" is no row), so a cell of a 1x2 row, ... and NaN.
  matvar_t* poles = field(iff.get(), "damped_poles");
  ASSERT_EQ(poles->class_type, MAT_C_CELL);
  EXPECT_EQ(static_cast<const double*>(Mat_VarGetCell(poles, 1)->data)[1], 580.0);
  EXPECT_TRUE(std::isnan(scalar(Mat_VarGetCell(poles, 2))));

  std::unique_ptr<matvar_t, VarFreer> batch(Mat_VarRead(mat.get(), "batch"));
  ASSERT_TRUE(batch);
  EXPECT_TRUE(field(batch.get(), "flags")->isLogical);
  EXPECT_EQ(field(batch.get(), "ragged")->class_type, MAT_C_CELL);
  EXPECT_TRUE(std::isnan(scalar(field(batch.get(), "spread"))));

  std::unique_ptr<matvar_t, VarFreer> text(Mat_VarRead(mat.get(), "x1st_key_with_dots"));
  ASSERT_TRUE(text);
  EXPECT_EQ(text->class_type, MAT_C_CHAR);
}

TEST(MatStruct, NestedStructsReadBackV5) {
  test::TempDir dir;
  const auto file = dir.path() / "results.mat";
  write_json_as_mat(document(), file);
  check_file(file);
}

// Uncompressed: written by piezobench's own v5 encoder, read by matio.
TEST(MatStruct, NestedStructsReadBackV5Uncompressed) {
  test::TempDir dir;
  const auto file = dir.path() / "results_plain.mat";
  MatStructOptions o;
  o.compress = false;
  write_json_as_mat(document(), file, o);
  check_file(file);
}

TEST(MatStruct, NestedStructsReadBackV73) {
  test::TempDir dir;
  const auto file = dir.path() / "results73.mat";
  MatStructOptions o;
  o.version = MatVersion::kV73;
  write_json_as_mat(document(), file, o);
  check_file(file);
}

// A matrix of rows: N x M, column-major as MATLAB.
TEST(MatStruct, RowsBecomeAMatrix) {
  test::TempDir dir;
  const auto file = dir.path() / "m.mat";
  MatStructOptions o;
  o.variable = "results";
  write_json_as_mat(json{{"poles", json::array({json::array({-1.0, 2.0}), json::array({-3.0, "inf"}), json::array({-5.0, 6.0})})}}, file, o);
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  std::unique_ptr<matvar_t, VarFreer> r(Mat_VarRead(mat.get(), "results"));
  ASSERT_TRUE(r);
  matvar_t* p = field(r.get(), "poles");
  ASSERT_EQ(p->dims[0], 3u);
  ASSERT_EQ(p->dims[1], 2u);
  const double* d = static_cast<const double*>(p->data);
  EXPECT_EQ(d[1], -3.0);  // (2, 1)
  EXPECT_EQ(d[3], 2.0);   // (1, 2)
  EXPECT_TRUE(std::isinf(d[4]));
}

// Objects with different keys still make a struct array; a missing key is [] in that element.
TEST(MatStruct, ObjectsWithDifferentKeys) {
  test::TempDir dir;
  const auto file = dir.path() / "u.mat";
  write_json_as_mat(json::parse(R"({"units": [{"id": 1, "frf": {"resonance_Hz": 95.4}}, {"id": 2, "stroke_um": 250}]})"), file);
  std::unique_ptr<mat_t, MatCloser> mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  std::unique_ptr<matvar_t, VarFreer> u(Mat_VarRead(mat.get(), "units"));
  ASSERT_TRUE(u);
  ASSERT_EQ(u->class_type, MAT_C_STRUCT);
  EXPECT_EQ(u->dims[1], 2u);
  EXPECT_EQ(scalar(field(u.get(), "stroke_um", 1)), 250.0);
  EXPECT_EQ(field(u.get(), "stroke_um", 0)->dims[0], 0u);
  EXPECT_EQ(scalar(field(field(u.get(), "frf", 0), "resonance_Hz")), 95.4);
}

TEST(MatStruct, FieldNames) {
  EXPECT_EQ(matlab_field_name("stiffness_N_per_um"), "stiffness_N_per_um");
  EXPECT_EQ(matlab_field_name("u->de"), "u__de");
  EXPECT_EQ(matlab_field_name("3"), "x3");
  EXPECT_EQ(matlab_field_name(""), "x");
  EXPECT_EQ(matlab_field_name(std::string(80, 'a')).size(), 63u);
}

TEST(MatStruct, BadInputLeavesNoFile) {
  test::TempDir dir;
  const auto file = dir.path() / "r.mat";
  EXPECT_TRUE(test::contains(test::input_error([&] { write_json_as_mat(json::array({1, 2}), file); }, "document"), "r.mat"));
  MatStructOptions o;
  o.variable = "1bad";
  test::input_error([&] { write_json_as_mat(document(), file, o); }, "variable");
  test::input_error([&] { write_json_as_mat(document(), dir.path() / "missing" / "r.mat"); });
  EXPECT_FALSE(std::filesystem::exists(file));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace piezobench::io
