#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/ply.h"
#include "panmap/io/scannet_ground_truth.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::expectError;

const char kTable[] = "scannet-meta/scannetv2-labels.combined.tsv";

std::string tiny(const std::string& name) {
  return test::fixtureDir("scannet_gt_tiny/scene0000_00" + name);
}

// Hand-computed from tests/fixtures/scannet_gt_tiny/make_fixture.py: segIndices
// 5 5 5 9 9 12 12 12 40 77 99; chair [5] -> 5, Kitchen-Cabinets [9 12] -> 3, trash bin
// [12 40] -> 39 (segment 12 stays with the cabinets), flux capacitor [77] -> unknown.
const std::vector<int32_t> kSemantic = {5, 5, 5, 3, 3, 3, 3, 3, 39, 0, 0};
const std::vector<int32_t> kInstance = {1, 1, 1, 2, 2, 2, 2, 2, 3, 5, 0};

ScanNetGroundTruth loadTiny(const ScanNetLabelTable& table) {
  return loadScanNetGroundTruth(tiny("_vh_clean_2.ply"), tiny(".aggregation.json"),
                                tiny("_vh_clean_2.0.010000.segs.json"), table);
}

TEST(ScanNetLabelTable, RealTableLookups) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  EXPECT_EQ(table.nyu40FromRawCategory("chair"), 5);
  EXPECT_EQ(table.nyu40FromRawCategory("kitchen cabinets"), 3);  // exact row
  EXPECT_EQ(table.nyu40FromRawCategory("Kitchen-Cabinets"), 3);  // forgiving match only
  EXPECT_EQ(table.nyu40FromRawCategory(" TRASH_bin "), 39);
  EXPECT_EQ(table.nyu40FromRawCategory("flux capacitor"), 0);
  EXPECT_EQ(table.nyu40FromRawCategory(""), 0);
  EXPECT_EQ(table.nyu40FromRawCategory("--"), 0);
  EXPECT_EQ(table.nyu40FromScanNetId(2), 5);      // chair
  EXPECT_EQ(table.nyu40FromScanNetId(1), 1);      // wall
  EXPECT_EQ(table.nyu40FromScanNetId(1169), 39);  // trash bin
  EXPECT_EQ(table.nyu40FromScanNetId(1357), 40);  // starbucks cup, the last row
  EXPECT_EQ(table.nyu40FromScanNetId(385), 3);    // cabinet door 8, cabinet doors 3: last
  EXPECT_EQ(table.nyu40FromScanNetId(0), 0);
  EXPECT_EQ(table.nyu40FromScanNetId(5000), 0);
}

TEST(ScanNetLabelTable, BadTableNamesTheFile) {
  test::TempDir dir;
  expectError([&] { ScanNetLabelTable::load(dir.path("absent.tsv")); },
              {"cannot read", "absent.tsv"});
  std::ofstream(dir.path("no_nyu.tsv")) << "id\traw_category\tnyu40class\n1\twall\twall\n";
  expectError([&] { ScanNetLabelTable::load(dir.path("no_nyu.tsv")); },
              {"no_nyu.tsv", "no column 'nyu40id'"});
  std::ofstream(dir.path("bad_row.tsv")) << "raw_category\tnyu40id\tid\nwall\t1\t1\nchair\tx\t2\n";
  expectError([&] { ScanNetLabelTable::load(dir.path("bad_row.tsv")); },
              {"bad_row.tsv", "line 3", "nyu40id 'x'"});
  // Columns are found by name, in any order, with CRLF line ends.
  std::ofstream(dir.path("ok.tsv")) << "raw_category\tnyu40id\tid\r\nwall\t1\t1\r\nChair\t5\t2\r\n";
  const ScanNetLabelTable table = ScanNetLabelTable::load(dir.path("ok.tsv"));
  EXPECT_EQ(table.nyu40FromRawCategory("chair"), 5);
  EXPECT_EQ(table.nyu40FromScanNetId(1), 1);
}

TEST(ScanNetGroundTruth, TinySceneVertexLabels) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  const ScanNetGroundTruth gt = loadTiny(table);
  ASSERT_EQ(gt.mesh.numVertices(), 11u);
  for (int i = 0; i < 11; ++i) {
    EXPECT_EQ(gt.mesh.vertices[i], Eigen::Vector3f(0.25f * (i % 4), 0.5f * (i / 4), 0.125f * i));
    EXPECT_EQ(gt.mesh.colors[i], (Rgb8{static_cast<uint8_t>(10 * i), static_cast<uint8_t>(20 + i),
                                       static_cast<uint8_t>(250 - i)}));
  }
  EXPECT_EQ(gt.mesh.faces,
            (std::vector<Eigen::Vector3i>{{0, 1, 2}, {3, 4, 5}, {5, 6, 7}, {7, 8, 9}, {8, 9, 10}}));
  EXPECT_EQ(gt.mesh.semantic, kSemantic);
  EXPECT_EQ(gt.mesh.instance, kInstance);
  EXPECT_TRUE(gt.mesh.superpoint.empty());
  // chair, cabinets, trash bin, flux capacitor; table's segment is absent, the last two empty.
  EXPECT_EQ(gt.num_instances, 4);
  EXPECT_EQ(gt.unknown_labels, (std::vector<std::string>{"aardvark", "flux capacitor"}));
}

TEST(ScanNetGroundTruth, LabelsPlyAgreesWithAggregation) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  const std::string labels_ply = tiny("_vh_clean_2.labels.ply");
  // The file holds ScanNet ids; readPly must not take them for NYU40 ids.
  EXPECT_EQ(readPlyVertexIntProperty(labels_ply, "label"),
            (std::vector<int32_t>{2, 2, 2, 29, 29, 29, 29, 29, 1169, 0, 0}));
  EXPECT_TRUE(readPly(labels_ply).semantic.empty());
  EXPECT_EQ(readScanNetLabelsPly(labels_ply, table), kSemantic);
  EXPECT_EQ(readScanNetLabelsPly(labels_ply, table), loadTiny(table).mesh.semantic);
}

TEST(ScanNetGroundTruth, InstanceFileLineByLine) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  test::TempDir dir;
  writeScanNetInstanceFile(dir.path("scene0000_00.txt"), loadTiny(table).mesh);
  std::ifstream in(dir.path("scene0000_00.txt"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // The flux capacitor vertex has instance 5 but class 0: written as 0.
  EXPECT_EQ(lines, (std::vector<std::string>{"5001", "5001", "5001", "3002", "3002", "3002", "3002",
                                             "3002", "39003", "0", "0"}));
  EXPECT_EQ(readScanNetInstanceFile(dir.path("scene0000_00.txt")),
            (std::vector<int32_t>{5001, 5001, 5001, 3002, 3002, 3002, 3002, 3002, 39003, 0, 0}));

  // A mesh without label arrays writes zeros; a bad line names the file.
  LabelledMesh bare;
  bare.vertices = {{0, 0, 0}, {1, 1, 1}};
  writeScanNetInstanceFile(dir.path("bare.txt"), bare);
  EXPECT_EQ(readScanNetInstanceFile(dir.path("bare.txt")), (std::vector<int32_t>{0, 0}));
  std::ofstream(dir.path("bad.txt")) << "5001\n3oo2\n";
  expectError([&] { readScanNetInstanceFile(dir.path("bad.txt")); },
              {"bad.txt", "line 2", "'3oo2'"});
  // Blank lines at the end are no vertex; one among the ids would shift the rest.
  std::ofstream(dir.path("trailing.txt")) << "5001\n3002\n\n \n";
  EXPECT_EQ(readScanNetInstanceFile(dir.path("trailing.txt")), (std::vector<int32_t>{5001, 3002}));
  std::ofstream(dir.path("gap.txt")) << "5001\n\n3002\n";
  expectError([&] { readScanNetInstanceFile(dir.path("gap.txt")); },
              {"gap.txt", "line 2: a blank line among the ids"});
}

TEST(ScanNetGroundTruth, SegsLengthMismatchNamesBothFiles) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  test::TempDir dir;
  std::ofstream(dir.path("short.segs.json"))
      << R"({"segIndices": [5, 5, 5, 9, 9, 12, 12, 12, 40, 77]})";
  expectError(
      [&] {
        loadScanNetGroundTruth(tiny("_vh_clean_2.ply"), tiny(".aggregation.json"),
                               dir.path("short.segs.json"), table);
      },
      {"short.segs.json", "10 segIndices", "scene0000_00_vh_clean_2.ply", "11 vertices"});
}

TEST(ScanNetGroundTruth, BadAggregationNamesTheFile) {
  PANMAP_REQUIRE_DATA("scannet-meta");
  const ScanNetLabelTable table = ScanNetLabelTable::load(test::dataDir(kTable));
  test::TempDir dir;
  const std::string segs = tiny("_vh_clean_2.0.010000.segs.json");
  std::ofstream(dir.path("no_id.json"))
      << R"({"segGroups": [{"label": "chair", "segments": [5]}]})";
  expectError(
      [&] { loadScanNetGroundTruth(tiny("_vh_clean_2.ply"), dir.path("no_id.json"), segs, table); },
      {"no_id.json", "segGroup 0", "objectId"});
  std::ofstream(dir.path("twice.json"))
      << R"({"segGroups": [{"objectId": 0, "label": "chair", "segments": [5]},
                           {"objectId": 0, "label": "table", "segments": [9]}]})";
  expectError(
      [&] { loadScanNetGroundTruth(tiny("_vh_clean_2.ply"), dir.path("twice.json"), segs, table); },
      {"twice.json", "objectId 0 appears twice"});
  std::ofstream(dir.path("cut.json")) << R"({"segGroups": [)";
  expectError(
      [&] { loadScanNetGroundTruth(tiny("_vh_clean_2.ply"), dir.path("cut.json"), segs, table); },
      {"cut.json", "malformed JSON"});
}

const char* const kSceneFiles[] = {"_vh_clean_2.ply", ".aggregation.json",
                                   "_vh_clean_2.0.010000.segs.json"};

TEST(ScanNetGroundTruth, FindsTheScanNetFilesOfAFolder) {
  // The fixture folder is not named after its scene: the only *_vh_clean_2.ply names it (the
  // labels PLY beside it does not count).
  const std::string tiny = test::fixtureDir("scannet_gt_tiny");
  const ScanNetSceneFiles files = findScanNetSceneFiles(tiny);
  EXPECT_EQ(files.scene, "scene0000_00");
  EXPECT_EQ(files.mesh_ply, tiny + "/scene0000_00_vh_clean_2.ply");
  EXPECT_EQ(files.aggregation_json, tiny + "/scene0000_00.aggregation.json");
  EXPECT_EQ(files.segs_json, tiny + "/scene0000_00_vh_clean_2.0.010000.segs.json");

  // A folder named after its scene wins even beside another scene's mesh, trailing slash or not.
  test::TempDir dir;
  fs::create_directory(dir.path("scene0707_00"));
  for (const char* f : kSceneFiles) {
    fs::create_symlink(tiny + "/scene0000_00" + f, dir.path("scene0707_00/scene0707_00") + f);
  }
  fs::create_symlink(tiny + "/scene0000_00_vh_clean_2.ply",
                     dir.path("scene0707_00/scene0001_00_vh_clean_2.ply"));
  EXPECT_EQ(findScanNetSceneFiles(dir.path("scene0707_00")).scene, "scene0707_00");
  EXPECT_EQ(findScanNetSceneFiles(dir.path("scene0707_00/")).segs_json,
            dir.path("scene0707_00/scene0707_00_vh_clean_2.0.010000.segs.json"));
}

// ScanNet's download puts the label table above scans/<scene>/: it is found there, in the
// scene folder first, or in a scannet-meta/ folder at those levels, and nowhere else.
TEST(ScanNetGroundTruth, FindsTheLabelTableAboveTheScene) {
  test::TempDir dir;
  fs::create_directories(dir.path("scans/scene0000_00"));
  const std::string scene = dir.path("scans/scene0000_00");
  EXPECT_EQ(findScanNetLabelTable(scene), "");
  std::ofstream(dir.path("scannetv2-labels.combined.tsv")) << "id\n";
  EXPECT_EQ(findScanNetLabelTable(scene), dir.path("scannetv2-labels.combined.tsv"));
  EXPECT_EQ(findScanNetLabelTable(scene + "/"), dir.path("scannetv2-labels.combined.tsv"));
  std::ofstream(scene + "/scannetv2-labels.combined.tsv") << "id\n";
  EXPECT_EQ(findScanNetLabelTable(scene), scene + "/scannetv2-labels.combined.tsv");
  // The shared data's layout: scannet-gt/<scene> beside scannet-meta/ (found from any folder;
  // panmap-eval --gt-scannet did not find it where panmap-synth's cwd-relative default did).
  fs::create_directories(dir.path("data/scannet-gt/scene0470_00"));
  fs::create_directories(dir.path("data/scannet-meta"));
  std::ofstream(dir.path("data/scannet-meta/scannetv2-labels.combined.tsv")) << "id\n";
  EXPECT_EQ(findScanNetLabelTable(dir.path("data/scannet-gt/scene0470_00")),
            dir.path("data/scannet-meta/scannetv2-labels.combined.tsv"));
  // Three levels up is too far.
  fs::create_directories(dir.path("a/b/c/d"));
  EXPECT_EQ(findScanNetLabelTable(dir.path("a/b/c/d")), "");
}

TEST(ScanNetGroundTruth, MissingScanNetFilesAreNamed) {
  test::TempDir dir;
  expectError([&] { findScanNetSceneFiles(dir.path("absent")); }, {"absent", "not a folder"});
  fs::create_directory(dir.path("empty"));
  expectError([&] { findScanNetSceneFiles(dir.path("empty")); },
              {"empty", "expected one *_vh_clean_2.ply mesh, found 0"});
  fs::create_directory(dir.path("s"));
  const std::string tiny = test::fixtureDir("scannet_gt_tiny/scene0000_00");
  fs::create_symlink(tiny + "_vh_clean_2.ply", dir.path("s/scene0000_00_vh_clean_2.ply"));
  fs::create_symlink(tiny + ".aggregation.json", dir.path("s/scene0000_00.aggregation.json"));
  expectError([&] { findScanNetSceneFiles(dir.path("s")); },
              {"scene0000_00_vh_clean_2.0.010000.segs.json", "missing"});
  fs::create_symlink(tiny + "_vh_clean_2.ply", dir.path("s/scene0001_00_vh_clean_2.ply"));
  expectError([&] { findScanNetSceneFiles(dir.path("s")); }, {"found 2"});
}

TEST(ScanNetGroundTruth, SceneFilesOfAFullDownload) {
  // A scene folder as ScanNet's download script leaves it: the high-resolution mesh's
  // annotation (*_vh_clean.aggregation.json, *_vh_clean.segs.json) and the labels mesh stand
  // beside the three files the ground truth is read from.
  test::TempDir dir;
  for (const char* name :
       {"scene0011_00_vh_clean_2.ply", "scene0011_00_vh_clean_2.labels.ply",
        "scene0011_00.aggregation.json", "scene0011_00_vh_clean.aggregation.json",
        "scene0011_00_vh_clean_2.0.010000.segs.json", "scene0011_00_vh_clean.segs.json",
        "scene0011_00_vh_clean.ply", "scene0011_00.txt"}) {
    std::ofstream(dir.path(name)) << "x";
  }
  const ScanNetSceneFiles files = findScanNetSceneFiles(dir.path());
  EXPECT_EQ(files.mesh_ply, dir.path("scene0011_00_vh_clean_2.ply"));
  EXPECT_EQ(files.aggregation_json, dir.path("scene0011_00.aggregation.json"));
  EXPECT_EQ(files.segs_json, dir.path("scene0011_00_vh_clean_2.0.010000.segs.json"));
  // Only the high-resolution annotation: named, not taken (its segments are another mesh's).
  std::filesystem::remove(dir.path("scene0011_00.aggregation.json"));
  expectError([&] { findScanNetSceneFiles(dir.path()); },
              {"scene0011_00.aggregation.json: missing", "high-resolution"});
  std::ofstream(dir.path("scene0011_00.aggregation.json")) << "x";
  std::filesystem::remove(dir.path("scene0011_00_vh_clean_2.0.010000.segs.json"));
  expectError([&] { findScanNetSceneFiles(dir.path()); },
              {"scene0011_00_vh_clean_2.0.010000.segs.json: missing"});
}

TEST(ScanNetGroundTruth, SceneFilesOfTheSharedScene) {
  PANMAP_REQUIRE_DATA("scannet-gt");
  const ScanNetSceneFiles files = findScanNetSceneFiles(test::dataDir("scannet-gt/scene0470_00"));
  EXPECT_EQ(std::filesystem::path(files.aggregation_json).filename(),
            "scene0470_00.aggregation.json");
}

}  // namespace
}  // namespace panmap
