#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

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
  EXPECT_EQ(reader.stats().unknown_category_ids, (std::map<int32_t, size_t>{{999, 1}}));
  EXPECT_THROW(reader.read("frame-000003.color"), Error);
}

TEST(CocoPanoptic, PerFrameJson) {
  CocoPanopticReader reader(test::fixtureDir("coco_tiny/perframe"), "",
                            LabelTable::load(test::fixtureDir("coco_tiny/labels.tsv")));
  expectFixtureFrame(reader.read("frame-000000.color"));
}

// Cityscapes' panoptic files number images by strings: they match as COCO's integers do. The
// reader lists what it found, for the import to name the masks no frame took.
TEST(CocoPanoptic, StringImageIdsMatchAndTheMasksFoundAreListed) {
  test::TempDir dir;
  std::ifstream in(test::fixtureDir("coco_tiny/panoptic.json"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string from : {"\"id\": 5,", "\"image_id\": 5,"}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, from.size(), from.substr(0, from.size() - 2) + "\"frankfurt_5\",");
  }
  std::ofstream(dir.path("strings.json")) << text;
  CocoPanopticReader reader(test::fixtureDir("coco_tiny/panoptic"), dir.path("strings.json"),
                            LabelTable::load(test::fixtureDir("coco_tiny/labels.tsv")));
  EXPECT_EQ(reader.stems(), std::vector<std::string>{"frame-000000.color"});
  const PanopticFrame f = reader.read("frame-000000.color");
  expectFixtureFrame(f);
  // Every one of the 8 x 6 pixels has an id; those of id 7 are listed nowhere: counted, void.
  EXPECT_EQ(reader.stats().labelled_pixels, 48u);
  EXPECT_EQ(reader.stats().unlisted_pixels, 4u);
  EXPECT_EQ(reader.stats().unlisted_bgr_pixels, 0u);
  EXPECT_EQ(std::count(f.segment_ids.data(), f.segment_ids.data() + f.segment_ids.size(), 0), 4);
}

// Fields of the wrong JSON type were nlohmann's own message ("type must be number, but is
// string"), naming neither the file nor the field.
TEST(CocoPanoptic, FieldsOfTheWrongTypeAreNamedWithTheirFile) {
  test::TempDir dir;
  const std::pair<std::string, std::string> cases[] = {
      {R"([{"id": 1, "category_id": 1, "isthing": "yes"}])", "isthing of segment 1 is not 0/1"},
      {R"([{"id": 1, "category_id": 1, "score": "high"}])", "score of segment 1 is not a number"},
      {R"([{"id": "1", "category_id": 1}])", "lacks integer id/category_id"}};
  for (const auto& [segments, message] : cases) {
    std::ofstream(dir.path("frame.json")) << segments;
    std::ifstream png(test::fixtureDir("coco_tiny/perframe/frame-000000.color.png"),
                      std::ios::binary);
    std::ofstream(dir.path("frame.png"), std::ios::binary) << png.rdbuf();
    CocoPanopticReader reader(dir.path(), "", LabelTable::nyu40Identity());
    test::expectError([&] { reader.read("frame"); }, {dir.path("frame.json"), message});
  }
  std::ofstream(dir.path("coco.json"))
      << R"({"images": [{"id": [5], "file_name": "a.jpg"}], "annotations": []})";
  test::expectError(
      [&] { CocoPanopticReader(dir.path(), dir.path("coco.json"), LabelTable::nyu40Identity()); },
      {dir.path("coco.json"), "an image's id is neither an integer nor a string"});
  std::ofstream(dir.path("coco.json"))
      << R"({"annotations": [{"file_name": 3, "segments_info": []}]})";
  test::expectError(
      [&] { CocoPanopticReader(dir.path(), dir.path("coco.json"), LabelTable::nyu40Identity()); },
      {dir.path("coco.json"), "an annotation's file_name is not a string"});
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
