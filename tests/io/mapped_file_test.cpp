// Read-only file mappings (io/mapped_file.cpp): contents, bounds and alignment of doubles(), and
// the files that cannot be mapped (the caller then reads them).
#include "mapped_file.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <vector>

#include "test_util.hpp"

namespace piezobench::io::detail {
namespace {

namespace fs = std::filesystem;

TEST(MappedFile, MapsTheBytesAndBoundsTheDoubles) {
  test::TempDir dir;
  const fs::path file = dir.path() / "d.bin";
  std::vector<double> values = {1.5, -2.25, 3e300, 0.0, 7.0};
  {
    std::ofstream out(file, std::ios::binary);
    out.write("12345678", 8);  // an 8-byte header, as before a v5 data element
    out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(double)));
  }
  const auto map = MappedFile::open(file);
  ASSERT_NE(map, nullptr);
  ASSERT_EQ(map->size(), 8 + values.size() * sizeof(double));
  EXPECT_EQ(std::memcmp(map->data(), "12345678", 8), 0);
  const double* d = map->doubles(8, values.size());
  ASSERT_NE(d, nullptr);
  for (std::size_t k = 0; k < values.size(); ++k) EXPECT_EQ(d[k], values[k]);
  EXPECT_NE(map->doubles(16, values.size() - 1), nullptr);
  EXPECT_EQ(map->doubles(8, values.size() + 1), nullptr);          // one past the end
  EXPECT_EQ(map->doubles(16, values.size()), nullptr);
  EXPECT_EQ(map->doubles(map->size() + 8, 0), nullptr);            // offset past the end
  EXPECT_EQ(map->doubles(8, ~std::size_t{0} / 4), nullptr);        // count * 8 would overflow
  EXPECT_EQ(map->doubles(4, 1), nullptr);                          // not aligned for double
}

TEST(MappedFile, WhatCannotBeMappedGivesNull) {
  test::TempDir dir;
  EXPECT_EQ(MappedFile::open(dir.path() / "missing.bin"), nullptr);
  EXPECT_EQ(MappedFile::open(dir.path()), nullptr);  // a directory
  const fs::path empty = dir.path() / "empty.bin";
  std::ofstream(empty).close();
  EXPECT_EQ(MappedFile::open(empty), nullptr);
}

}  // namespace
}  // namespace piezobench::io::detail
