#include <fstream>
#include <string>
#include <utility>

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
  std::ofstream(path) << "62 5 1 chair\n1 1 0 wall\n62 6 1 couch\n";
  try {
    LabelTable::load(path);
    FAIL() << "a repeated source id was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3: source id 62 already on line 1"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(path) << "4294967358 5 1 chair past int32\n";
  EXPECT_THROW(LabelTable::load(path), Error);
  std::ofstream(path) << "1 41 0 beyond nyu40\n";
  EXPECT_THROW(LabelTable::load(path), Error);
  EXPECT_THROW(LabelTable::load(dir.path("missing.tsv")), Error);
}

// Each (source id, NYU40 class) pair is a row of the table.
template <size_t N>
void expectClasses(const LabelTable& table, const std::pair<int32_t, int32_t> (&expected)[N]) {
  for (const auto& [source, nyu40] : expected) {
    const auto row = table.lookup(source);
    ASSERT_TRUE(row.has_value()) << source;
    EXPECT_EQ(row->panmap_class, nyu40) << source << " " << row->name;
  }
}

TEST(LabelTable, ShippedCocoPanopticTableHasEveryCategoryOnce) {
  const std::string path = test::shippedLabelTable("coco_panoptic_nyu40.tsv");
  const LabelTable table = LabelTable::load(path);
  // A repeated source id would replace a row and leave fewer than COCO's 133 categories.
  EXPECT_EQ(table.size(), 133u);
  std::ifstream in(path);
  int rows = 0;
  for (std::string line; std::getline(in, line);) rows += !line.empty() && line[0] != '#';
  EXPECT_EQ(rows, 133);
  // COCO numbers its 80 things 1-90 and its 53 stuff classes 92-200.
  for (int32_t id = 1; id <= 200; ++id) {
    const auto row = table.lookup(id);
    if (row) {
      EXPECT_EQ(row->is_thing, id <= 90) << id;
    }
  }
  const std::pair<int32_t, int32_t> expected[] = {
      {1, 31},   {62, 5},  {63, 6},   {65, 4},   {67, 7},  {70, 33},  {72, 25},  {81, 34},
      {82, 24},  {84, 23}, {107, 12}, {109, 16}, {112, 8}, {141, 18}, {156, 15}, {168, 27},
      {180, 13}, {181, 9}, {186, 22}, {188, 3},  {189, 7}, {190, 2},  {199, 1},  {118, 2},
      {3, 0},    {17, 0},  {187, 0},  {44, 40},  {200, 40}};
  expectClasses(table, expected);
  EXPECT_EQ(table.lookup(62)->name, "chair");
  EXPECT_EQ(table.lookup(188)->name, "cabinet-merged");
  EXPECT_FALSE(table.lookup(12).has_value());  // a gap in COCO's numbering
}

TEST(LabelTable, ShippedAde20kTableHasEveryCategoryOnce) {
  const LabelTable table = LabelTable::load(test::shippedLabelTable("ade20k_nyu40.tsv"));
  EXPECT_EQ(table.size(), 150u);
  for (int32_t id = 0; id < 150; ++id) EXPECT_TRUE(table.lookup(id).has_value()) << id;
  const std::pair<int32_t, int32_t> expected[] = {
      {0, 1},    {3, 2},   {5, 22},  {7, 4},   {8, 9},   {10, 3},  {14, 8},  {15, 7},
      {19, 5},   {23, 6},  {30, 5},  {33, 14}, {37, 36}, {44, 17}, {47, 34}, {50, 24},
      {57, 18},  {62, 10}, {63, 13}, {65, 33}, {67, 23}, {75, 5},  {81, 27}, {89, 25},
      {115, 37}, {1, 0},   {2, 0},   {20, 0},  {147, 40}};
  expectClasses(table, expected);
  EXPECT_TRUE(table.lookup(19)->is_thing);
  EXPECT_FALSE(table.lookup(0)->is_thing);
}

TEST(LabelTable, ContiguousIdsCountTheRowsInIdOrder) {
  LabelTable tiny;
  tiny.set(9, {40, true, "lamp"});
  tiny.set(1, {1, false, "wall"});
  tiny.set(5, {5, true, "chair"});
  const LabelTable renumbered = tiny.contiguous();
  EXPECT_EQ(renumbered.size(), 3u);
  const std::pair<int32_t, int32_t> tiny_expected[] = {{0, 1}, {1, 5}, {2, 40}};
  expectClasses(renumbered, tiny_expected);
  EXPECT_EQ(renumbered.lookup(1).value_or(LabelTable::Entry{}).name, "chair");
  EXPECT_TRUE(renumbered.lookup(2).value_or(LabelTable::Entry{}).is_thing);
  EXPECT_FALSE(renumbered.lookup(3).has_value());
  EXPECT_FALSE(renumbered.lookup(9).has_value());

  // Mask2Former's COCO panoptic indices: person 0, car 2, chair 56, the first stuff class
  // (banner) 80, wall 131, the last (rug) 132.
  const LabelTable coco =
      LabelTable::load(test::shippedLabelTable("coco_panoptic_nyu40.tsv")).contiguous();
  const std::pair<int32_t, int32_t> expected[] = {{0, 31},  {2, 0},   {56, 5},  {80, 40},
                                                  {120, 3}, {122, 2}, {131, 1}, {132, 40}};
  expectClasses(coco, expected);
  EXPECT_EQ(coco.lookup(56).value_or(LabelTable::Entry{}).name, "chair");
  EXPECT_FALSE(coco.lookup(133).has_value());

  // ADE20K's ids are its indices already.
  const LabelTable ade = LabelTable::load(test::shippedLabelTable("ade20k_nyu40.tsv"));
  const LabelTable ade_contiguous = ade.contiguous();
  for (int32_t id = 0; id < 150; ++id) {
    const auto row = ade_contiguous.lookup(id), original = ade.lookup(id);
    ASSERT_TRUE(row.has_value() && original.has_value()) << id;
    EXPECT_EQ(row->panmap_class, original->panmap_class) << id;
    EXPECT_EQ(row->name, original->name) << id;
  }
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
