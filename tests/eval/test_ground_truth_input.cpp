// Ground-truth inputs of panmap-eval: ScanNet scene folders, benchmark id files, class lists.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/ground_truth_input.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::expectError;

const char* const kSceneFiles[] = {"_vh_clean_2.ply", ".aggregation.json",
                                   "_vh_clean_2.0.010000.segs.json"};

TEST(GroundTruthInput, FindsTheScanNetFilesOfAFolder) {
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

TEST(GroundTruthInput, MissingScanNetFilesAreNamed) {
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

TEST(GroundTruthInput, BenchmarkIdsReplaceTheMeshLabels) {
  LabelledMesh mesh;
  mesh.vertices.assign(5, Eigen::Vector3f::Zero());
  mesh.semantic = {1, 2, 3, 4, 22};
  mesh.instance = {9, 9, 9, 9, 9};
  applyScanNetInstanceIds({0, 5001, 5001, 3002, 39017}, "ids.txt", "mesh.ply", &mesh);
  EXPECT_EQ(mesh.semantic, (std::vector<int32_t>{1, 5, 5, 3, 39}));  // id 0 keeps its class
  EXPECT_EQ(mesh.instance, (std::vector<int32_t>{0, 5001, 5001, 3002, 39017}));
  LabelledMesh bare;  // a ScanNet mesh has no labels at all
  bare.vertices.assign(2, Eigen::Vector3f::Zero());
  applyScanNetInstanceIds({0, 7003}, "ids.txt", "mesh.ply", &bare);
  EXPECT_EQ(bare.semantic, (std::vector<int32_t>{0, 7}));
  EXPECT_EQ(bare.instance, (std::vector<int32_t>{0, 7003}));
  expectError(
      [&] {
        applyScanNetInstanceIds({1, 2, 3}, "ids.txt", "mesh.ply", &bare);
      },
      {"ids.txt: 3 lines but mesh.ply has 2 vertices"});
  expectError(
      [&] {
        applyScanNetInstanceIds({0, -4}, "ids.txt", "mesh.ply", &bare);
      },
      {"ids.txt", "line 2", "-4"});
}

TEST(GroundTruthInput, ClassLists) {
  EXPECT_EQ(parseClassList("3"), (std::vector<int32_t>{3}));
  EXPECT_EQ(parseClassList(" 39, 5 ,sofa,Night-Stand"), (std::vector<int32_t>{5, 6, 32, 39}));
  expectError([] { parseClassList("3,chair,5"); }, {"classes", "'5' listed twice"});
  expectError([] { parseClassList("41"); }, {"'41'", "1..40"});
  expectError([] { parseClassList("0"); }, {"'0'"});
  expectError([] { parseClassList("3,,4"); }, {"''"});
  expectError([] { parseClassList("flux capacitor"); }, {"'flux capacitor'"});
  expectError([] { parseClassList("99999999999"); }, {"'99999999999'"});
  expectError([] { parseClassList(""); }, {"classes: empty"});
}

}  // namespace
}  // namespace panmap
