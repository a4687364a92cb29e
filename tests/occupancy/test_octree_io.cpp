// OctoMap binary streams and .bt files: round trips, OctoMap's own readers and tools, and
// refusal of malformed input.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_map.h"
#include "panmap/occupancy/octree_io.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A floor, a box and a sphere seen from four sides with exact depth: free, occupied and
// unknown cells at several octree levels.
class SceneMap : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    LabelledMesh mesh;
    test::addQuad(&mesh, {-3, -3, 0.013f}, {3, -3, 0.013f}, {3, 3, 0.013f}, {-3, 3, 0.013f}, 1, 2,
                  60);
    test::addSphere(&mesh, {0.6f, 0.0f, 0.5f}, 0.4f, 2, 39);
    test::addBox(&mesh, {-0.9f, -0.4f, 0.0f}, {-0.3f, 0.3f, 0.7f}, 3, 3, 12);
    const MeshRenderer renderer(mesh);
    DepthNoiseConfig exact;
    exact.enabled = false;
    map_ = new OccupancyMap();
    for (int k = 0; k < 4; ++k) {
      const double a = k * M_PI / 2 + 0.3;
      const Eigen::Isometry3d T =
          test::lookAt({2.2 * std::cos(a), 2.2 * std::sin(a), 1.6}, {0, 0, 0.3});
      map_->integrate(simulateDepth(renderer.render(test::kinectCamera(), T), exact, 0), 0.001,
                      test::kinectCamera(), T);
    }
  }
  static void TearDownTestSuite() { delete map_; }

  // Every state the two trees give at the centres of a 4 m cube of cells around the scene.
  static void expectSameStates(const octomap::OcTree& a, const octomap::OcTree& b) {
    size_t known = 0;
    for (double x = -1.975; x < 2.0; x += 0.05) {
      for (double y = -1.975; y < 2.0; y += 0.05) {
        for (double z = -0.475; z < 1.5; z += 0.05) {
          const Occupancy sa = occupancyAt(a, {x, y, z});
          ASSERT_EQ(sa, occupancyAt(b, {x, y, z})) << x << " " << y << " " << z;
          known += sa != Occupancy::kUnknown;
        }
      }
    }
    EXPECT_GT(known, 10000u);
  }

  static OccupancyMap* map_;
  test::TempDir dir_;
};
OccupancyMap* SceneMap::map_ = nullptr;

TEST_F(SceneMap, BinaryDataRoundTripIsExact) {
  const std::string data = map_->toBinaryData();
  ASSERT_GT(data.size(), 1000u);
  const auto tree = treeFromBinaryData(data, 0.05);
  EXPECT_EQ(tree->getResolution(), 0.05);
  EXPECT_EQ(toBinaryData(*tree), data);  // the decoded tree writes the same bytes
  expectSameStates(*tree, *map_->toOcTree());
  // The map's own answers agree with the decoded tree's at every observed cell.
  size_t cells = 0;
  for (const auto& block : map_->grid().blocks()) {
    for (int n = 0; n < kOccupancyBlockCells; ++n) {
      if (block->cells[n].last_frame == 0) continue;
      const CellKey key = block->corner + CellKey(n % 8, (n / 8) % 8, n / 64);
      const Eigen::Vector3d c = map_->grid().centreOf(key);
      ASSERT_EQ(occupancyAt(*tree, c), map_->occupancyAt(c)) << c.transpose();
      ++cells;
    }
  }
  EXPECT_GT(cells, 10000u);
}

// toOcTree() prunes each 64-cell octant as its last block goes in (to bound its memory on
// large maps): the tree must be the one that setting every cell, in any order, and pruning once
// gives. The scene spans 6 m, so many octants.
TEST_F(SceneMap, PruningOctantByOctantGivesTheTreeOfOnePruneAtTheEnd) {
  const auto ours = map_->toOcTree();
  octomap::OcTree reference(ours->getResolution());
  reference.setClampingThresMin(ours->getClampingThresMin());
  reference.setClampingThresMax(ours->getClampingThresMax());
  reference.setOccupancyThres(ours->getOccupancyThres());
  reference.setProbHit(ours->getProbHit());
  reference.setProbMiss(ours->getProbMiss());
  size_t cells = 0, octants = 0;
  std::set<std::tuple<int, int, int>> seen_octants;
  for (const auto& block : map_->grid().blocks()) {
    for (int n = 0; n < kOccupancyBlockCells; ++n) {
      if (block->cells[n].last_frame == 0) continue;
      const CellKey key = block->corner + CellKey(n % 8, (n / 8) % 8, n / 64);
      const bool occupied = map_->occupancyAt(map_->grid().centreOf(key)) == Occupancy::kOccupied;
      reference.setNodeValue(
          octomap::OcTreeKey(key.x(), key.y(), key.z()),
          occupied ? reference.getClampingThresMaxLog() : reference.getClampingThresMinLog(), true);
      ++cells;
      octants += seen_octants.insert({key.x() >> 6, key.y() >> 6, key.z() >> 6}).second;
    }
  }
  reference.prune();
  reference.updateInnerOccupancy();
  EXPECT_GT(cells, 10000u);
  EXPECT_GE(octants, 4u);
  EXPECT_EQ(ours->size(), reference.size());
  EXPECT_EQ(toBinaryData(*ours), toBinaryData(reference));
}

TEST_F(SceneMap, BtFileRoundTripAndOctomapsOwnReader) {
  const std::string path = dir_.path("occupancy.bt");
  map_->writeBt(path);
  const std::string bytes = readFile(path);
  EXPECT_EQ(bytes, map_->toBtBytes());
  EXPECT_EQ(bytes.rfind("# Octomap OcTree binary file", 0), 0u);
  const auto ours = readBtFile(path);
  EXPECT_EQ(toBtBytes(*ours), bytes);
  // OctoMap's constructor from a file name: what octovis and OctoMap's tools use.
  octomap::OcTree theirs(path);
  EXPECT_EQ(theirs.size(), ours->size());
  EXPECT_EQ(theirs.getResolution(), 0.05);
  expectSameStates(theirs, *ours);
}

TEST_F(SceneMap, OctomapsConvertToolRewritesTheFileByteForByte) {
  const std::string tool = "/usr/bin/convert_octree";
  if (!std::filesystem::exists(tool)) {
    GTEST_SKIP() << tool << " absent (Debian package octomap-tools, installed by setup.sh)";
  }
  const std::string in = dir_.path("in.bt"), out = dir_.path("out.bt");
  map_->writeBt(in);
  const test::CommandResult run = test::runCommand(tool + " " + in + " " + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // convert_octree reads the file, makes it maximum-likelihood, prunes and writes it: ours is
  // already in that form, so nothing may change.
  EXPECT_EQ(readFile(out), readFile(in));
}

TEST(OctreeIo, EmptyTreeRoundTrips) {
  const OccupancyMap empty;
  EXPECT_EQ(empty.toBinaryData(), "");
  EXPECT_EQ(treeFromBinaryData("", 0.05)->size(), 0u);
  const auto tree = treeFromBtBytes(empty.toBtBytes(), "empty");
  EXPECT_EQ(tree->size(), 0u);
  EXPECT_EQ(occupancyAt(*tree, {0, 0, 0}), Occupancy::kUnknown);
}

TEST_F(SceneMap, MalformedStreamsAreRefusedWithAReason) {
  const std::string data = map_->toBinaryData();
  EXPECT_EQ(countBinaryDataNodes(data), static_cast<long>(map_->toOcTree()->size()));
  test::expectError([&] { treeFromBinaryData(data.substr(0, data.size() - 1), 0.05); },
                    {"malformed octree data"});
  test::expectError([&] { treeFromBinaryData(data + std::string(2, '\0'), 0.05); }, {"malformed"});
  test::expectError([&] { treeFromBinaryData(std::string(64, '\xff'), 0.05); }, {"malformed"});
  test::expectError([&] { treeFromBinaryData(data, 0.0); }, {"resolution"});
  // Children below the 16th level: every node claims inner children, 2 bytes each.
  EXPECT_EQ(countBinaryDataNodes(std::string(2 * 17, '\xff')), -1);

  const std::string bt = map_->toBtBytes();
  test::expectError([&] { treeFromBtBytes("not an octree\n", "x.bt"); },
                    {"x.bt", "not an OctoMap .bt file"});
  test::expectError([&] { treeFromBtBytes(bt.substr(0, bt.size() - 5), "x.bt"); },
                    {"x.bt", "malformed or truncated"});
  std::string wrong_type = bt;
  wrong_type.replace(wrong_type.find("id OcTree"), 9, "id ColorOcTree");
  test::expectError([&] { treeFromBtBytes(wrong_type, "x.bt"); }, {"x.bt", "ColorOcTree"});
  std::string wrong_size = bt;
  const size_t at = wrong_size.find("size ") + 5;
  wrong_size.insert(at, "1");
  test::expectError([&] { treeFromBtBytes(wrong_size, "x.bt"); }, {"x.bt", "header says"});
  test::expectError([&] { readBtFile(dir_.path("missing.bt")); }, {"missing.bt", "cannot open"});
  test::expectError([&] { map_->writeBt(dir_.path("no/such/dir/o.bt")); }, {"o.bt"});
}

}  // namespace
}  // namespace panmap
