#include "piezobench/campaign/field_reference.hpp"

#include <gtest/gtest.h>


namespace piezobench::campaign {
namespace {

// docs/fields.md is campaign's document with the program's further tables (rt's): its test is
// FieldReferenceCli.DocsAreCurrent (tests/app). Here: campaign's part.
TEST(FieldReference, EveryStructOnceWithUnitsKeysAndMeanings) {
  const std::string doc = field_reference_markdown();
  EXPECT_NE(doc.find("\n## UnitAnalysis\n"), std::string::npos);
  EXPECT_NE(doc.find("\n## FrfAnalysis\n"), std::string::npos);
  EXPECT_EQ(doc.find("\n## FitQuality\n"), doc.rfind("\n## FitQuality\n"));  // reached from many structs, written once
  // A field's row: SI unit, the shown unit with its factor, its results.json key and meaning.
  EXPECT_NE(doc.find("| `shell_stiffness` |  | N/m | N/um (SI x 1e-06) | `shell_stiffness_N_per_um` | m_sus w_z^2 (report table) |"),
            std::string::npos);
  EXPECT_NE(doc.find("\"nan\""), std::string::npos);  // the one encoding of non-finite numbers
  // A "|" in a meaning is escaped (it would end the cell); a shown unit with factor 1 has no "SI x 1".
  EXPECT_NE(doc.find("| \\|pole\\| |"), std::string::npos);
  EXPECT_EQ(doc.find("(SI x 1)"), std::string::npos);
}

}  // namespace
}  // namespace piezobench::campaign
