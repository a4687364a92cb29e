// Ground-truth inputs of panmap-eval: benchmark id files, class lists.
#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/ground_truth_input.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using test::expectError;

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
  // Class ids alone (the semantic benchmark's files) scored nothing and exited 0.
  expectError(
      [&] {
        applyScanNetInstanceIds({0, 5}, "ids.txt", "mesh.ply", &bare);
      },
      {"ids.txt: every id is below 1000", "class * 1000 + instance"});
  // A class beyond NYU40 (a ScanNet label id) counted its objects under no class.
  expectError(
      [&] {
        applyScanNetInstanceIds({0, 45001}, "ids.txt", "mesh.ply", &bare);
      },
      {"ids.txt: line 2: id 45001 names class 45", "NYU40"});
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
