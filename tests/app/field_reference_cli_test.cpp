// `piezobench fields` (app/field_reference.cpp): docs/fields.md is what the program writes, and it
// holds every declared result the program shows, the rt module's included (campaign, which writes
// the rest of the document, does not depend on rt).
#include <gtest/gtest.h>

#include <string>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;

TEST(FieldReferenceCli, DocsAreCurrent) {
  test::TempDir dir;
  const std::string out = (dir.path() / "fields.md").string();
  const test::CliRun r = run_cli("fields --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string written = test::read_text(out);
  EXPECT_TRUE(test::read_text(std::string(PIEZOBENCH_SOURCE_DIR) + "/docs/fields.md") == written)
      << "docs/fields.md is stale: regenerate it with `build/app/piezobench fields --out docs/fields.md`";
  // rt's and bench's declarations are in it, each once, with their results.json keys.
  for (const char* table : {"\n## LoopReport\n", "\n## IoStats\n", "\n## TimingSummary\n", "\n## ActuatorLimits\n", "\n## TrackingSummary\n"}) {
    EXPECT_NE(written.find(table), std::string::npos) << table;
    EXPECT_EQ(written.find(table), written.rfind(table)) << table;
  }
  EXPECT_NE(written.find("`rate_Hz`"), std::string::npos);       // LoopReport's sample_rate
  EXPECT_NE(written.find("`stale_inputs`"), std::string::npos);  // IoStats' timeouts
  EXPECT_NE(written.find("\n## UnitAnalysis\n"), std::string::npos);  // campaign's part
}

}  // namespace
}  // namespace piezobench
