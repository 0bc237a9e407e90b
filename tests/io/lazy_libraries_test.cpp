// matio and HDF5 are loaded on first use (src/io/matio_stubs.cpp, src/io/hdf5_stubs.cpp): work that
// does not need them does not map them, and the first call through a stub loads the library and
// gives the real function's result. One test in its own program, so that nothing has loaded the
// libraries before it looks (ctest or the program run alone give the same answer).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <matio.h>

#include <array>
#include <nlohmann/json.hpp>

#include "piezobench/core/shared_library.hpp"
#include "piezobench/io/timeseries.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

using core::is_shared_object_loaded;

nlohmann::json expected(const std::string& fixture) {
  return nlohmann::json::parse(test::read_text(test::fixture_path(fixture)));
}

TEST(LazyLibraries, CsvWorkLoadsNeitherMatioNorHdf5AndTheirFirstCallsLoadThem) {
  ASSERT_TRUE(is_shared_object_loaded("libc.so"));  // the search itself works
  EXPECT_FALSE(is_shared_object_loaded("libmatio"));
  EXPECT_FALSE(is_shared_object_loaded("libhdf5"));

  // A CSV record, read in SI (semicolon, mm): the work of most commands.
  const nlohmann::json lab = expected("io/lab/expected.json");
  const TimeSeries csv = read_timeseries(test::fixture_path("io/lab/semicolon_mm.csv"));
  ASSERT_EQ(csv.samples(), lab["samples"].get<Eigen::Index>());
  EXPECT_TRUE(test::near(csv.channel("d_e")(1), lab["first"]["d_e"][1].get<double>(), 1e-9));
  EXPECT_FALSE(is_shared_object_loaded("libmatio"));
  EXPECT_FALSE(is_shared_object_loaded("libhdf5"));

  // matio through its stubs: a compressed v5 file (scipy.io.savemat) reads back scipy's numbers.
  const nlohmann::json scipy = expected("io/scipy_mat_expected.json")["two_outputs"];
  mat_t* mat = Mat_Open(test::fixture_path("io/scipy_compressed.mat").c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  EXPECT_TRUE(is_shared_object_loaded("libmatio"));
  matvar_t* u = Mat_VarRead(mat, "u_dac");
  ASSERT_NE(u, nullptr);
  ASSERT_EQ(u->data_type, MAT_T_DOUBLE);
  EXPECT_EQ(static_cast<const double*>(u->data)[3], scipy["first"]["u_dac"][3].get<double>());
  Mat_VarFree(u);
  EXPECT_EQ(Mat_Close(mat), 0);

  // HDF5 through its stubs, with the predefined type H5T_NATIVE_DOUBLE (a global variable of the
  // library, copied when it is loaded): a v7.3 file written by h5py.
  const hid_t file = H5Fopen(test::fixture_path("io/lab/v73_h5py.mat").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_TRUE(is_shared_object_loaded("libhdf5"));
  EXPECT_NE(H5T_NATIVE_DOUBLE, H5I_INVALID_HID);
  const hid_t dataset = H5Oopen(file, "u", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  const hid_t space = H5Dget_space(dataset);
  EXPECT_EQ(H5Sget_simple_extent_npoints(space), lab["samples"].get<hssize_t>());
  const std::array<hsize_t, 1> start{0}, count{3};
  const hid_t memory = H5Screate_simple(1, count.data(), nullptr);
  ASSERT_GE(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), 0);
  std::array<double, 3> first{};
  ASSERT_GE(H5Dread(dataset, H5T_NATIVE_DOUBLE, memory, space, H5P_DEFAULT, first.data()), 0);
  for (size_t k = 0; k < first.size(); ++k) EXPECT_EQ(first[k], lab["first"]["u"][k].get<double>()) << k;
  H5Sclose(memory);
  H5Sclose(space);
  H5Oclose(dataset);
  EXPECT_GE(H5Fclose(file), 0);
}

}  // namespace
}  // namespace piezobench::io
