#include <fstream>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/core/label_table.h"
#include "test_helpers.h"

namespace panmap {
namespace {

TEST(LabelTable, LoadsRowsAndComments) {
  const LabelTable table = LabelTable::load(test::fixtureDir("coco_tiny/labels.tsv"));
  EXPECT_EQ(table.size(), 2u);
  const auto chair = table.lookup(62);
  ASSERT_TRUE(chair.has_value());
  EXPECT_EQ(chair->panmap_class, 5);
  EXPECT_TRUE(chair->is_thing);
  EXPECT_EQ(chair->name, "chair");
  EXPECT_FALSE(table.lookup(999).has_value());
}

TEST(LabelTable, MalformedRowNamesFileAndLine) {
  test::TempDir dir;
  const std::string path = dir.path("bad.tsv");
  std::ofstream(path) << "# header\n1 1 0 wall\n2 five 1 chair\n";
  try {
    LabelTable::load(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "1 41 0 beyond nyu40\n";
  EXPECT_THROW(LabelTable::load(path), Error);
  EXPECT_THROW(LabelTable::load(dir.path("missing.tsv")), Error);
}

TEST(LabelTable, Nyu40IdentityKnowsStuff) {
  const LabelTable table = LabelTable::nyu40Identity();
  EXPECT_EQ(table.size(), 40u);
  EXPECT_FALSE(table.lookup(2)->is_thing);
  EXPECT_TRUE(table.lookup(3)->is_thing);
  EXPECT_EQ(table.lookup(24)->name, "refridgerator");
}

}  // namespace
}  // namespace panmap
