#include <fstream>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/coco_panoptic_reader.h"
#include "test_helpers.h"

namespace panmap {
namespace {

void expectFixtureFrame(const PanopticFrame& f) {
  ASSERT_EQ(f.segments.size(), 3u);
  EXPECT_EQ(f.segments[0], (PanopticSegment{1, 1, 1, false, 1.0f}));    // wall: stuff
  EXPECT_EQ(f.segments[1], (PanopticSegment{300, 5, 62, true, 0.8f}));  // COCO chair -> 5
  EXPECT_EQ(f.segments[2], (PanopticSegment{2, 0, 999, true, 0.25f}));  // unknown: class 0
  ASSERT_EQ(f.segment_ids.width(), 8);
  EXPECT_EQ(f.segment_ids(0, 0), 1);
  EXPECT_EQ(f.segment_ids(7, 0), 300);
  EXPECT_EQ(f.segment_ids(7, 4), 2);
  EXPECT_EQ(f.segment_ids(7, 5), 0);  // id 7 has no segments_info entry
}

TEST(CocoPanoptic, SingleJsonFile) {
  CocoPanopticReader reader(test::fixtureDir("coco_tiny/panoptic"),
                            test::fixtureDir("coco_tiny/panoptic.json"),
                            LabelTable::load(test::fixtureDir("coco_tiny/labels.tsv")));
  // Matched through images[].file_name, the colour image's stem.
  ASSERT_TRUE(reader.has("frame-000000.color"));
  EXPECT_FALSE(reader.has("frame-000003.color"));
  expectFixtureFrame(reader.read("frame-000000.color"));
  EXPECT_EQ(reader.stats().unknown_category_segments, 1u);
  EXPECT_THROW(reader.read("frame-000003.color"), Error);
}

TEST(CocoPanoptic, PerFrameJson) {
  CocoPanopticReader reader(test::fixtureDir("coco_tiny/perframe"), "",
                            LabelTable::load(test::fixtureDir("coco_tiny/labels.tsv")));
  expectFixtureFrame(reader.read("frame-000000.color"));
}

TEST(CocoPanoptic, BadInputNamesTheFile) {
  test::TempDir dir;
  const std::string json = dir.path("bad.json");
  std::ofstream(json) << "{\"annotations\": [ {\"file_name\": \"x.png\", ";  // truncated
  try {
    CocoPanopticReader(test::fixtureDir("coco_tiny/panoptic"), json, LabelTable::nyu40Identity());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: malformed JSON"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(CocoPanopticReader(dir.path("none"), "", LabelTable::nyu40Identity()), Error);
  EXPECT_THROW(CocoPanopticReader(dir.path(), "", LabelTable::nyu40Identity()), Error);  // empty
}

}  // namespace
}  // namespace panmap
