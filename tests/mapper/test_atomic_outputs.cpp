// The outputs a planner or a viewer polls (objects.json, occupancy.bt, the meshes, the
// trajectory) are replaced whole: each goes to PATH.partial and is renamed over PATH, so a
// reader never sees a file cut off mid-write, and a write that fails leaves the old file.

#include <octomap/OcTree.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/ply.h"
#include "panmap/io/tum_trajectory.h"
#include "panmap/mapper/objects.h"
#include "panmap/occupancy/octree_io.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

// Writes PATH with `write(first)`, then blocks PATH.partial with a folder and writes it with
// `write(second)`: the second write must fail naming PATH, and PATH must still hold the first
// version's bytes, with nothing left beside it but the blocking folder.
void expectOldFileKept(const std::string& path, const std::function<void(int)>& write) {
  write(1);
  const std::string first = test::fileBytes(path);
  ASSERT_FALSE(first.empty());
  EXPECT_FALSE(fs::exists(path + ".partial"));
  fs::create_directory(path + ".partial");
  test::expectError([&] { write(2); }, {"cannot write " + path});
  EXPECT_EQ(test::fileBytes(path), first);
  fs::remove(path + ".partial");
  write(2);
  EXPECT_NE(test::fileBytes(path), first);
  EXPECT_FALSE(fs::exists(path + ".partial"));
}

TEST(AtomicOutputs, WriteFileAtomicallyReplacesTheWholeFileOrNothing) {
  test::TempDir dir;
  const std::string path = dir.path("f.txt");
  expectOldFileKept(path, [&](int version) {
    writeFileAtomically(path, std::string(version * 3, static_cast<char>('a' + version)));
  });
  EXPECT_EQ(test::fileBytes(path), "cccccc");
  test::expectError([&] { writeFileAtomically(dir.path("no/such/f.txt"), "x"); },
                    {"cannot write " + dir.path("no/such/f.txt"), "No such file or directory"});
}

TEST(AtomicOutputs, MeshesObjectsTrajectoryAndOccupancyKeepTheOldFileOnFailure) {
  test::TempDir dir;
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    const std::string path = dir.path(format == PlyFormat::kAscii ? "a.ply" : "b.ply");
    expectOldFileKept(path, [&](int version) {
      LabelledMesh mesh;
      for (int i = 0; i < 3 * version; ++i) {
        mesh.vertices.emplace_back(static_cast<float>(i), 0.5f * version, 0.0f);
      }
      mesh.faces.emplace_back(0, 1, 2);
      writePly(path, mesh, format);
    });
    EXPECT_EQ(readPly(path).vertices.size(), 6u);
  }
  const std::string objects_path = dir.path("objects.json");
  expectOldFileKept(objects_path, [&](int version) {
    std::vector<MappedObject> objects(version);
    for (int i = 0; i < version; ++i) objects[i].id = i + 1;
    writeObjectsJson(objects_path, objects, 1000 * version);
  });
  int64_t utime = 0;
  EXPECT_EQ(readObjectsJson(objects_path, &utime).size(), 2u);
  EXPECT_EQ(utime, 2000);
  const std::string trajectory_path = dir.path("trajectory.txt");
  expectOldFileKept(trajectory_path, [&](int version) {
    std::vector<StampedPose> poses(version);
    for (int i = 0; i < version; ++i) poses[i].utime = 1000000 * (i + 1);
    writeTumTrajectory(trajectory_path, poses);
  });
  EXPECT_EQ(readTumTrajectory(trajectory_path).size(), 2u);
  const std::string bt_path = dir.path("occupancy.bt");
  expectOldFileKept(bt_path, [&](int version) {
    octomap::OcTree tree(0.05);
    for (int i = 0; i < version; ++i) tree.updateNode(octomap::point3d(0.1f * i, 0, 0), true);
    writeBtFile(tree, bt_path);
  });
  EXPECT_EQ(readBtFile(bt_path)->getNumLeafNodes(), 2u);
}

}  // namespace
}  // namespace panmap
