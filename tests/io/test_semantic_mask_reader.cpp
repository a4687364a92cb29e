#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/semantic_mask_reader.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// Class ids of a semantic network, 8x6: a wall (1) down the left, three chair regions (5), of
// which the lower two pixels touch only at a corner, a lamp (9) down the right, an unknown id
// (7) and unlabelled pixels (0, also not in the table).
cv::Mat classIds(int type) {
  const int ids[6][8] = {{1, 1, 5, 5, 0, 5, 5, 9}, {1, 1, 5, 5, 0, 5, 5, 9},
                         {1, 1, 0, 0, 0, 0, 0, 9}, {1, 1, 0, 0, 0, 0, 0, 9},
                         {7, 1, 0, 5, 0, 0, 0, 9}, {7, 1, 5, 0, 0, 0, 0, 9}};
  cv::Mat mat(6, 8, type);
  for (int v = 0; v < 6; ++v) {
    for (int u = 0; u < 8; ++u) {
      if (type == CV_16UC1) {
        mat.at<uint16_t>(v, u) = static_cast<uint16_t>(ids[v][u]);
      } else {
        mat.at<uint8_t>(v, u) = static_cast<uint8_t>(ids[v][u]);
      }
    }
  }
  return mat;
}

LabelTable tinyTable() {
  LabelTable table;
  table.set(1, {1, false, "wall"});
  table.set(5, {5, true, "chair"});
  table.set(9, {35, true, "lamp"});
  return table;
}

void writePng(const std::string& path, const cv::Mat& mat) {
  ASSERT_TRUE(cv::imwrite(path, mat)) << path;
}

TEST(SemanticMasks, StuffIsOneSegmentAndThingsSplitWhereTheyDoNotTouch) {
  for (const int type : {CV_8UC1, CV_16UC1}) {
    test::TempDir dir;
    writePng(dir.path("frame-000000.color.png"), classIds(type));
    SemanticMaskReader reader(dir.path(), tinyTable());
    EXPECT_TRUE(reader.has("frame-000000.color"));
    EXPECT_FALSE(reader.has("frame-000003.color"));
    const PanopticFrame f = reader.read("frame-000000.color");
    ASSERT_EQ(f.segments.size(), 5u) << type;
    EXPECT_EQ(f.segments[0], (PanopticSegment{1, 1, 1, false, 1.0f}));
    for (int k = 1; k <= 3; ++k) {
      EXPECT_EQ(f.segments[k], (PanopticSegment{1 + k, 5, 5, true, 1.0f})) << k;
    }
    EXPECT_EQ(f.segments[4], (PanopticSegment{5, 35, 9, true, 1.0f}));
    const int32_t expected[6][8] = {{1, 1, 2, 2, 0, 3, 3, 5}, {1, 1, 2, 2, 0, 3, 3, 5},
                                    {1, 1, 0, 0, 0, 0, 0, 5}, {1, 1, 0, 0, 0, 0, 0, 5},
                                    {0, 1, 0, 4, 0, 0, 0, 5}, {0, 1, 4, 0, 0, 0, 0, 5}};
    ASSERT_EQ(f.segment_ids.width(), 8);
    ASSERT_EQ(f.segment_ids.height(), 6);
    for (int v = 0; v < 6; ++v) {
      for (int u = 0; u < 8; ++u) EXPECT_EQ(f.segment_ids(u, v), expected[v][u]) << u << "," << v;
    }
    // Id 7 is not in the table: an unknown category, counted once. 0, not in it either, is
    // the PNG's "no class" (counted as unknown, it made the import suggest --contiguous-ids).
    EXPECT_EQ(reader.stats().unknown_category_segments, 1u);
    EXPECT_EQ(reader.stats().unknown_category_ids, (std::map<int32_t, size_t>{{7, 1}}));
    EXPECT_EQ(reader.stats().void_ids, (std::set<int32_t>{0}));
    EXPECT_EQ(reader.stats().segments, 5u);
  }
}

// 0, 255 and 65535 are void only where the table does not list them as classes: a
// network's classes counted from 0 make 0 a class (ADE20K's wall after --contiguous-ids).
TEST(SemanticMasks, VoidValuesAreNoClassUnlessTheTableListsThem) {
  LabelTable table = tinyTable();
  for (int32_t id : {0, 255, 65535}) EXPECT_TRUE(isSemanticVoid(id, table)) << id;
  for (int32_t id : {1, 7, 254, 256}) EXPECT_FALSE(isSemanticVoid(id, table)) << id;
  LabelImage classes(3, 1, 0);
  classes(1, 0) = 255;
  classes(2, 0) = 1;
  size_t unknown = 0;
  std::set<int32_t> void_ids;
  PanopticFrame f = panopticFromClasses(classes, table, &unknown, nullptr, &void_ids);
  EXPECT_EQ(unknown, 0u);
  EXPECT_EQ(void_ids, (std::set<int32_t>{0, 255}));
  ASSERT_EQ(f.segments.size(), 1u);
  EXPECT_EQ(f.segment_ids(0, 0), 0);
  EXPECT_EQ(f.segment_ids(1, 0), 0);
  EXPECT_EQ(f.segment_ids(2, 0), 1);
  table.set(0, {1, false, "wall"});
  EXPECT_FALSE(isSemanticVoid(0, table));
  void_ids.clear();
  f = panopticFromClasses(classes, table, &unknown, nullptr, &void_ids);
  EXPECT_EQ(void_ids, (std::set<int32_t>{255}));
  ASSERT_EQ(f.segments.size(), 2u);
  EXPECT_EQ(f.segments[0].source_category, 0);
  EXPECT_EQ(f.segment_ids(0, 0), 1);
}

TEST(SemanticMasks, ColourImagesAndMissingFoldersAreNamed) {
  test::TempDir dir;
  cv::Mat colour(6, 8, CV_8UC3, cv::Scalar(5, 0, 0));
  const std::string path = dir.path("frame-000000.color.png");
  writePng(path, colour);
  SemanticMaskReader reader(dir.path(), tinyTable());
  try {
    reader.read("frame-000000.color");
    FAIL() << "a colour PNG was read as class ids";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": a semantic mask must be a greyscale PNG"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(SemanticMaskReader(dir.path("none"), tinyTable()), Error);
  test::TempDir empty;
  EXPECT_THROW(SemanticMaskReader(empty.path(), tinyTable()), Error);
  writeFileBytes(dir.path("frame-000003.color.png"), {0x89, 'P', 'N', 'G'});
  // Not a PNG at all, with a non-zero byte where a PNG keeps its colour type.
  writeFileBytes(dir.path("frame-000006.color.png"), std::vector<uint8_t>(64, 'x'));
  SemanticMaskReader cut(dir.path(), tinyTable());
  EXPECT_THROW(cut.read("frame-000003.color"), Error);
  try {
    cut.read("frame-000006.color");
    FAIL() << "a file that is no PNG was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("must be a PNG"), std::string::npos) << e.what();
  }
}

TEST(SemanticMasks, APanopticFrameLosesItsInstancesWhereTheyTouch) {
  // Three chairs (NYU40 5) of which two touch, on a floor (2); a void segment (0).
  PanopticFrame panoptic;
  panoptic.utime = 42;
  panoptic.frame_id = 7;
  panoptic.segment_ids = LabelImage(8, 2, 1);
  const int32_t ids[2][8] = {{10, 10, 11, 11, 1, 12, 1, 9}, {10, 10, 11, 11, 1, 12, 1, 9}};
  for (int v = 0; v < 2; ++v) {
    for (int u = 0; u < 8; ++u) panoptic.segment_ids(u, v) = ids[v][u];
  }
  panoptic.segments = {{1, 2, 2, false, 1.0f},
                       {9, 0, 0, true, 0.5f},
                       {10, 5, 5, true, 0.9f},
                       {11, 5, 5, true, 0.8f},
                       {12, 5, 5, true, 0.7f}};
  const PanopticFrame semantic = withoutInstances(panoptic, LabelTable::nyu40Identity());
  EXPECT_EQ(semantic.utime, 42);
  EXPECT_EQ(semantic.frame_id, 7);
  ASSERT_EQ(semantic.segments.size(), 3u);
  EXPECT_EQ(semantic.segments[0], (PanopticSegment{1, 2, 2, false, 1.0f}));  // floor
  EXPECT_EQ(semantic.segments[1], (PanopticSegment{2, 5, 5, true, 1.0f}));   // chairs 10 + 11
  EXPECT_EQ(semantic.segments[2], (PanopticSegment{3, 5, 5, true, 1.0f}));   // chair 12
  const int32_t expected[8] = {2, 2, 2, 2, 1, 3, 1, 0};
  for (int v = 0; v < 2; ++v) {
    for (int u = 0; u < 8; ++u) EXPECT_EQ(semantic.segment_ids(u, v), expected[u]) << u;
  }
}

}  // namespace
}  // namespace panmap
